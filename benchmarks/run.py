"""Run every ``benchmarks/bench_*.py`` in one process and write JSON plus a markdown table.

    python benchmarks/run.py [--out benchmarks/results] [--quick] [--only NAME ...]
"""

from __future__ import annotations

import argparse
import contextlib
import datetime as dt
import importlib.util
import json
import os
import platform
import sys
import traceback
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

#: BLAS threads for every benchmark, gripkit and peers alike, fixed before numpy is imported
#: (threadpoolctl is not in the environment): tall-skinny least squares gain nothing from BLAS
#: threads on 2 shared cores and vary 20× between processes with them (docs/performance.md).
BLAS_THREADS = os.environ.get("GRIPKIT_BENCH_BLAS_THREADS", "1")
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_var] = BLAS_THREADS


def machine() -> dict:
    import numba
    import numpy
    import scipy

    cpu = platform.processor() or ""
    with contextlib.suppress(OSError):  # no /proc/cpuinfo off Linux: keep platform.processor()
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    blas = "?"
    with contextlib.suppress(Exception):
        deps = numpy.show_config(mode="dicts")["Build Dependencies"]["blas"]
        blas = f"{deps.get('name')} {deps.get('version', '')}".strip()
    env = {k: os.environ[k] for k in ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE") if k in os.environ}
    return dict(cpu=cpu, cores=os.cpu_count(), python=platform.python_version(),
                numpy=numpy.__version__, scipy=scipy.__version__, numba=numba.__version__,
                blas=blas,
                blas_threads=BLAS_THREADS, blas_env=env, load_average=os.getloadavg(),
                platform=platform.platform(), date=dt.datetime.now().isoformat(timespec="seconds"))


def _fmt_t(s):
    if s is None:
        return "—"
    for unit, f in (("s", 1.0), ("ms", 1e3), ("µs", 1e6), ("ns", 1e9)):
        if s * f >= 1:
            return f"{s * f:.3g} {unit}"
    return f"{s * 1e9:.3g} ns"


def to_markdown(results: dict) -> str:
    m = results["machine"]
    lines = ["# gripkit benchmarks", "",
             f"Machine: {m['cpu']}, {m['cores']} cores; Python {m['python']}, numpy {m['numpy']}, "
             f"scipy {m['scipy']}, numba {m['numba']}; BLAS {m.get('blas', '?')} with "
             f"{m.get('blas_threads', '?')} thread(s) on both sides"
             + (f" ({', '.join(f'{k}={v}' for k, v in m['blas_env'].items())})"
                if m.get("blas_env") else "")
             + "; load average at start "
               f"{', '.join(f'{x:.2f}' for x in m.get('load_average', ()))}; {m['date']}.", "",
             "Both sides of every row are timed by one harness (benchmarks/common.py "
             "`measure`): the same "
             "warm-up call (numba compile time excluded on both sides) and the same number "
             "of timed runs; "
             "times are per call, median (min). ratio = peer median / gripkit median (> "
             "1 means gripkit "
             "is faster). Peers marked [pure-Python peer] run interpreted Python per "
             "sample or per row; "
             "their ratios measure that, not an expert's compiled route.", "",
             "| benchmark | task | gripkit median (min) | peer | peer median (min) | "
             "ratio | target | "
             "accuracy: gripkit / peer | notes |",
             "|---|---|---|---|---|---|---|---|---|"]

    def t(med, mn, runs):
        if med is None:
            return "—"
        return _fmt_t(med) + (f" ({_fmt_t(mn)}, {runs} runs)" if mn is not None else "")

    for r in results["rows"]:
        ratio = f"{r['ratio']:.3g}×" if r.get("ratio") else "—"
        accuracy = (" / ".join(a for a in (r.get("gripkit_accuracy", ""),
                                           r.get("peer_accuracy", "")) if a))
        lines.append(f"| {r['benchmark']} | {r['task']} | "
                     f"{t(r['gripkit_s'], r.get('gripkit_min_s'), r.get('gripkit_runs'))} "
                     f"| {r['peer']} | {t(r['peer_s'], r.get('peer_min_s'), r.get('peer_runs'))} "
                     f"| {ratio} | "
                     f"{r.get('target', '')} | {accuracy} | {r.get('notes', '')} |")
    if results.get("errors"):
        lines += ["", "## Benchmarks that failed", ""]
        lines += [f"- {k}: {v}" for k, v in results["errors"].items()]
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(HERE / "results"))
    ap.add_argument("--quick", action="store_true", help="smaller problems (smoke run)")
    ap.add_argument("--only", nargs="*", default=None)
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    results = {"machine": machine(), "quick": args.quick, "rows": [], "errors": {}}
    for path in sorted(HERE.glob("bench_*.py")):
        name = path.stem.removeprefix("bench_")
        if args.only and name not in args.only:
            continue
        print(f"[bench] {name} ...", file=sys.stderr, flush=True)
        spec = importlib.util.spec_from_file_location(path.stem, path)
        mod = importlib.util.module_from_spec(spec)
        try:
            spec.loader.exec_module(mod)
            rows = mod.run(quick=args.quick)
            results["rows"].extend(rows)
            for r in rows:
                print(f"  {r['task']}: gripkit {_fmt_t(r['gripkit_s'])}, {r['peer']} "
                      f"{_fmt_t(r['peer_s'])}"
                      + (f", ratio {r['ratio']:.3g}" if r.get('ratio') else ""), file=sys.stderr,
                      flush=True)
        except Exception as exc:  # record and continue: one broken peer must not hide the rest
            results["errors"][name] = f"{type(exc).__name__}: {exc}"
            traceback.print_exc()
        # write after every module: nothing lost if a later one crashes
        (out / "results.json").write_text(json.dumps(results, indent=2, default=str))
        (out / "results.md").write_text(to_markdown(results))
    print(f"[bench] wrote {out / 'results.md'}", file=sys.stderr)
    return 1 if results["errors"] else 0


if __name__ == "__main__":
    raise SystemExit(main())
