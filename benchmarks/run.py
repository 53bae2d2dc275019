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
    return dict(cpu=cpu, cores=os.cpu_count(), python=platform.python_version(),
                numpy=numpy.__version__, scipy=scipy.__version__, numba=numba.__version__,
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
    lines = [f"# gripkit benchmarks", "",
             f"Machine: {m['cpu']}, {m['cores']} cores; Python {m['python']}, numpy {m['numpy']}, "
             f"scipy {m['scipy']}, numba {m['numba']}; {m['date']}.", "",
             "Times are per call (best of several runs after a warm-up call, so numba compile time is "
             "excluded). ratio = peer time / gripkit time (> 1 means gripkit is faster).", "",
             "| benchmark | task | gripkit | peer | peer time | ratio | target | notes |",
             "|---|---|---|---|---|---|---|---|"]
    for r in results["rows"]:
        ratio = f"{r['ratio']:.3g}×" if r.get("ratio") else "—"
        lines.append(f"| {r['benchmark']} | {r['task']} | {_fmt_t(r['gripkit_s'])} | {r['peer']} | "
                     f"{_fmt_t(r['peer_s'])} | {ratio} | {r.get('target', '')} | {r.get('notes', '')} |")
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
                print(f"  {r['task']}: gripkit {_fmt_t(r['gripkit_s'])}, {r['peer']} {_fmt_t(r['peer_s'])}"
                      + (f", ratio {r['ratio']:.3g}" if r.get('ratio') else ""), file=sys.stderr, flush=True)
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
