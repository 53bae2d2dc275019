"""Tables II and III of 001_0b92a7da96e7aa46.txt as gripkit holds them: every printed value, both
fingers, parsed from the verbatim extraction in tests/reference/tsfm_tables.md (and that extraction
checked against the seed file when it is on disk), with provenance in the parameter sets."""

import json
import os
import re
import warnings
from pathlib import Path

import pytest

from gripkit.cli import main
from gripkit.consistency import check
from gripkit.systems.tsfm import parameters as z

REFERENCE = Path(__file__).parents[2] / "reference" / "tsfm_tables.md"
SEED_NAME = "001_0b92a7da96e7aa46.txt"

# Table II row label (as extracted) -> gripkit name, SI factor (tests/reference/tsfm_tables.md)
ROWS = {r"$d_p$ ( $\mu\text{m}/\text{V}$ )": ("d_p", 1e-6), "$s_p$ (m/N)": ("s_p", 1.0),
        r"$\lambda$": ("lam", 1e-6), r"$\beta$": ("beta", 1.0), r"$\gamma$": ("gamma", 1.0),
        "$a$": ("a", 1.0),
        "$b$": ("b", 1.0), "$m_s$ (Kg)": ("m_s", 1.0), "$b_s$ (N·s/m)": ("b_s", 1.0),
        "$k_s$ (N/m)": ("k_s", 1.0),
        r"Sensitivity (V/ $\mu\text{N}$ )": ("sensitivity", 1e6)}

# Table II, right finger, each value as printed (seed p. 7, "Right Finger" column), SI
RIGHT_FINGER = {
    "d_p": 0.78e-6,      # row d_p (µm/V): 0.78
    "s_p": 8.5e-4,       # row s_p (m/N): 8.5 × 10⁻⁴
    "lam": 0.39e-6,      # row λ: 0.39 (read in µm/V)
    "beta": 11.1e-2,     # row β: 11.1 × 10⁻²
    "gamma": 3.5e-3,     # row γ: 3.5 × 10⁻³
    "a": 2.5e-8,         # row a: 2.5 × 10⁻⁸
    "b": 8e-5,           # row b: 8 × 10⁻⁵
    "m_s": 1.79e-6,      # row m_s (Kg): 1.79 × 10⁻⁶
    "b_s": 6.98e-4,      # row b_s (N·s/m): 6.98 × 10⁻⁴
    "k_s": 130.8,        # row k_s (N/m): 130.8
    "sensitivity": 5.1e3,  # row Sensitivity (V/µN): 5.1 × 10⁻³
}


def _block(tag: str) -> list[str]:
    text = REFERENCE.read_text(encoding="utf-8")
    m = re.search(rf"```{tag}\n(.*?)```", text, re.DOTALL)
    assert m, f"no ```{tag} block in {REFERENCE}"
    return m.group(1).splitlines()


def _number(cell: str) -> float:
    """'0.78', '$8.5 \\times 10^{-4}$', '3%' -> float (the percent sign kept as a factor 0.01)."""
    cell = cell.strip().strip("$").strip()
    m = re.fullmatch(r"([\d.]+)\s*\\times\s*10\^\{(-?\d+)\}", cell)
    if m:
        return float(m.group(1)) * 10.0 ** int(m.group(2))
    if cell.endswith("%"):
        return float(cell[:-1]) / 100.0
    return float(cell)


def _table_ii() -> dict[str, dict[str, float]]:
    out: dict[str, dict[str, float]] = {"left": {}, "right": {}}
    for line in _block("table-ii")[1:]:
        cells = line.split("\t")
        name, factor = ROWS[cells[1].strip()]
        out["left"][name] = _number(cells[2]) * factor
        out["right"][name] = _number(cells[3]) * factor
    return out


def _seed_file() -> Path | None:
    env = os.environ.get("GRIPKIT_SEEDS")
    candidates = [Path(env) / SEED_NAME] if env else []
    candidates += [p / "shared" / "seeds" / SEED_NAME for p in Path(__file__).resolve().parents]
    return next((p for p in candidates if p.is_file()), None)


def test_every_table_ii_value_of_both_fingers():
    """Table II (p. 7), all eleven rows of both columns, against TABLE_II and the printed
    parameter set of each finger (``table_ii(side)``), each with a Table II source naming the
    finger."""
    parsed = _table_ii()
    assert len(parsed["left"]) == len(parsed["right"]) == 11
    for side in ("left", "right"):
        printed = z.table_ii(side)
        for name, value in parsed[side].items():
            assert z.TABLE_II[side][name] == pytest.approx(value, rel=1e-12), (side, name)
            assert printed.value(name) == pytest.approx(value, rel=1e-12), (side, name)
            src = printed[name].source
            assert ("001_0b92a7da96e7aa46.txt" in src and "Table II" in src
                    and f"{side} finger" in src), (side, name, src)


def test_right_finger_values_cited_row_by_row():
    """The right finger's column of Table II, value by value (see RIGHT_FINGER), equals the parsed
    extraction and the zoo model ``tsfm-right``: the eight values it simulates as printed, and the
    printed m_s, b_s kept in ``finger.printed`` beside the ones derived from f0 and ζ (§IV-B)."""
    assert _table_ii()["right"] == pytest.approx(RIGHT_FINGER, rel=1e-12)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        right = z.right_finger()
    for name, value in RIGHT_FINGER.items():
        assert right.printed.value(name) == pytest.approx(value, rel=1e-12), name
        if name in ("m_s", "b_s"):
            assert "Table II prints" in right.parameters[name].source
            assert f"{value:g}" in right.parameters[name].source
        else:
            assert right.parameters.value(name) == pytest.approx(value, rel=1e-12), name
            assert ("Table II" in right.parameters[name].source
                    and "right finger" in right.parameters[name].source)


def test_right_finger_in_zoo_show(capsys):
    """`gripkit zoo show tsfm-right --json` lists the right finger's Table II values (SI) with
    their source."""
    assert main(["zoo", "show", "tsfm-right", "--json"]) == 0
    params = {p["name"]: p for p in json.loads(capsys.readouterr().out)["parameters"]}
    for name in ("d_p", "s_p", "lam", "beta", "gamma", "a", "b", "k_s"):
        assert params[name]["value"] == pytest.approx(RIGHT_FINGER[name], rel=1e-12), name
        assert ("Table II" in params[name]["source"]
                and "right finger" in params[name]["source"]), name


def test_table_iii_as_printed():
    """Table III (§V-D): measured, estimated and error of the three microparts."""
    rows = [[_number(c) for c in line.split("\t")[1:]] for line in _block("table-iii")[1:]]
    assert len(rows) == len(z.TABLE_III) == 3
    for parsed, held in zip(rows, z.TABLE_III):
        assert parsed == pytest.approx(list(held), rel=1e-12)


def test_table_iii_errors_recomputed_and_reported():
    """Table III's errors recomputed from its columns: |11.7 − 12.1|/12.1 = 3.31 %,
    |71.05 − 72.5|/72.5 = 2.00 %, |445.55 − 469|/469 = 5.00 %, each within half a percentage point
    of the printed whole percent (3, 2, 5 %); a printed error off by more is reported as a finding,
    in ``check(gripper)`` and ``gripkit zoo check tsfm-gripper``."""
    found = {f.check: f for f in z.table_iii_findings()}
    for i, expected in ((1, 0.4 / 12.1), (2, 1.45 / 72.5), (3, 23.45 / 469)):
        f = found[f"table-iii-error-{i}"]
        assert f.computed == pytest.approx(expected, rel=1e-12)
        assert f.consistent and abs(f.computed - f.stated) <= 0.005
        assert f.tolerance == pytest.approx(0.005 / f.stated)
        assert f.source.endswith(f"Table III, micropart {i}")
    # the mechanism reports a disagreement: a printed 3 % against a recomputed 3.6 % is flagged
    saved = list(z.TABLE_III)
    try:
        z.TABLE_III[0] = (12.1, 11.665, 0.03)
        bad = {f.check: f for f in z.table_iii_findings()}["table-iii-error-1"]
        assert not bad.consistent and bad.computed == pytest.approx(0.435 / 12.1)
    finally:
        z.TABLE_III[:] = saved
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = check(z.gripper())
    assert all(rep.find(f"table-iii-error-{i}").consistent for i in (1, 2, 3))


def test_zoo_check_lists_table_iii(capsys):
    main(["zoo", "check", "tsfm-gripper", "--json"])
    out = json.loads(capsys.readouterr().out)
    t3 = {f["check"]: f for f in out["findings"] if f["check"].startswith("table-iii-error-")}
    assert sorted(t3) == ["table-iii-error-1", "table-iii-error-2", "table-iii-error-3"]
    assert all(f["consistent"] for f in t3.values())
    assert t3["table-iii-error-1"]["computed"] == pytest.approx(0.0330579, rel=1e-5)


def test_reference_extraction_matches_the_seed():
    """Each line of the verbatim blocks occurs in the seed file (skipped when the seeds are not on
    disk)."""
    seed = _seed_file()
    if seed is None:
        pytest.skip("the seed document 001_0b92a7da96e7aa46.txt is not shipped with "
                    "gripkit (it is the "
                    "specification, kept outside the repository); the Table II/III copy in "
                    "tests/reference/tsfm_tables.md is still checked by the other tests; "
                    "set GRIPKIT_SEEDS "
                    "to the seeds' folder to compare the copy with the seed itself")
    lines = set(seed.read_text(encoding="utf-8").splitlines())
    for tag in ("table-ii", "table-iii"):
        for line in _block(tag):
            assert line in lines, (tag, line)
