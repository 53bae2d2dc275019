"""benchmarks/compare_runs.py flags a row only when gripkit is slower both against its own past
and against the peer measured beside it (a loaded machine slows both sides)."""

import importlib.util
import json
from pathlib import Path

SCRIPT = Path(__file__).resolve().parents[2] / "benchmarks" / "compare_runs.py"
spec = importlib.util.spec_from_file_location("compare_runs", SCRIPT)
compare_runs = importlib.util.module_from_spec(spec)
spec.loader.exec_module(compare_runs)


def _run(path, rows):
    path.write_text(json.dumps({"machine": {"date": "d", "load_average": [0, 0, 0]}, "rows": [
        dict(benchmark="b", task=t, peer=p, gripkit_s=g, peer_s=s) for t, p, g, s in rows]}))
    return str(path)


def test_flags_only_rows_slower_against_their_peer(tmp_path, capsys):
    old = _run(tmp_path / "old.json", [("load", "np", 1.0, 2.0), ("regressed", "np", 1.0, 2.0),
                                       ("faster", "np", 1.0, 2.0), ("gone", "np", 1.0, 1.0)])
    new = _run(tmp_path / "new.json", [("load", "np", 1.5, 3.0),  # both 1.5× slower: the machine
                                       ("regressed", "np", 1.2, 2.0), ("faster", "np", 0.5, 2.0),
                                       ("new", "np", 1.0, 1.0)])
    rows = ({r["task"]: r for r in compare_runs.compare(compare_runs._rows(old)[1],
                                                        compare_runs._rows(new)[1], 0.05)})
    assert set(rows) == {"load", "regressed", "faster"}
    assert (rows["load"]["raw"] == 1.5 and rows["load"]["relative"] == 1.0
            and not rows["load"]["slower"])
    assert rows["regressed"]["slower"] and abs(rows["regressed"]["relative"] - 1.2) < 1e-12
    assert not rows["faster"]["slower"]
    assert compare_runs.main([old, new]) == 1
    out = capsys.readouterr().out
    assert "only in the old run: b: gone" in out and "only in the new run: b: new" in out
    assert "3 rows compared, 1 slower" in out
