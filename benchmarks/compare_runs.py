"""Compare two benchmark runs row by row: did gripkit get slower?

    python benchmarks/compare_runs.py OLD.json NEW.json [--tolerance 0.05]

A row's change is the new gripkit time over the old one (median of each run). On a shared
machine both runs also move with the load, so the peer measured beside gripkit in the same run
is the yardstick: the *relative* change is (new gripkit / new peer) / (old gripkit / old peer).
A row is flagged when both the raw and the relative change exceed 1 + tolerance (slower against
its own past and against its peer). Rows present in only one run are listed, not compared.
Old runs come from git: ``git show REV:benchmarks/results/results.json > old.json``.
"""

from __future__ import annotations

import argparse
import json
import sys


def _key(row: dict) -> tuple[str, str, str]:
    return row["benchmark"], row["task"], row.get("peer") or ""


def _rows(path: str) -> tuple[dict, dict]:
    with open(path) as fh:
        run = json.load(fh)
    rows = {}
    for row in run["rows"]:
        rows.setdefault(_key(row), row)  # a task measured against several peers keeps each
    return run["machine"], rows


def compare(old: dict, new: dict, tolerance: float) -> list[dict]:
    """One dict per row present in both runs with a gripkit time: raw and relative change."""
    out = []
    for key in new.keys() & old.keys():
        a, b = old[key], new[key]
        if not (a.get("gripkit_s") and b.get("gripkit_s")):
            continue
        raw = b["gripkit_s"] / a["gripkit_s"]
        rel = None
        if a.get("peer_s") and b.get("peer_s"):
            rel = raw / (b["peer_s"] / a["peer_s"])
        slower = raw > 1 + tolerance and (rel is None or rel > 1 + tolerance)
        out.append(dict(benchmark=key[0], task=key[1], peer=key[2], old_s=a["gripkit_s"],
                        new_s=b["gripkit_s"],
                        raw=raw, relative=rel, slower=slower))
    return sorted(out, key=lambda r: (r["benchmark"], r["task"], r["peer"]))


def _table(rows: list[dict], only_old: list, only_new: list, machines: tuple[dict, dict]) -> str:
    lines = [f"old run: {machines[0].get('date')} (load {machines[0].get('load_average')}); "
             f"new run: {machines[1].get('date')} (load {machines[1].get('load_average')})", "",
             "| benchmark | task | peer | old | new | new/old | against the peer | slower? |",
             "|---|---|---|---|---|---|---|---|"]
    for r in rows:
        rel = "—" if r["relative"] is None else f"{r['relative']:.2f}"
        lines.append(f"| {r['benchmark']} | {r['task']} | {r['peer'] or '—'} | "
                     f"{r['old_s']:.3g} s | "
                     f"{r['new_s']:.3g} s | {r['raw']:.2f} | {rel} | "
                     f"{'**yes**' if r['slower'] else ''} |")
    for what, keys in (("only in the old run", only_old), ("only in the new run", only_new)):
        if keys:
            lines += ["", f"{what}: " + "; ".join(f"{k[0]}: {k[1]}" for k in sorted(keys))]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--tolerance", type=float, default=0.05, help="allowed slow-down "
                                                                  "(default 0.05: 5 %%)")
    args = ap.parse_args(argv)
    m_old, old = _rows(args.old)
    m_new, new = _rows(args.new)
    rows = compare(old, new, args.tolerance)
    print(_table(rows, list(old.keys() - new.keys()), list(new.keys() - old.keys()),
                 (m_old, m_new)))
    flagged = [r for r in rows if r["slower"]]
    print(f"\n{len(rows)} rows compared, {len(flagged)} slower by more than {args.tolerance:.0%} "
          f"both raw and against their peer")
    return 1 if flagged else 0


if __name__ == "__main__":
    sys.exit(main())
