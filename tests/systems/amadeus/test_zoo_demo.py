"""Zoo entry ``amadeus-hand``: parameters with units and provenance, consistency checks, CLI."""

import json
import subprocess
import sys

import pytest

from gripkit import zoo
from gripkit.consistency import check


@pytest.fixture(scope="module")
def system():
    return zoo.build("amadeus-hand", check=False)


def test_parameters_have_units_and_sources(system):
    ps = system.parameters
    assert len(ps) > 50
    for p in ps.values():
        assert p.unit and p.doc and p.source, p.name
    # the Table II coefficients are carried with their Table III standard deviations
    assert ps["force_a1"].value == -1.8732 and ps["force_a1"].std == 0.0117
    assert ps["force_b2"].value == 0.1950 and ps["force_b2"].std == 0.0221


def test_consistency_report(system):
    """Seed contradictions are reported, the rest checks out: Table I actual vs eq 18 and the ε23
    rounding flagged; 5.5 Hz (Fig. 2(c)) within 10 % of the Table II poles' 5.32 Hz; the bending
    model's
    20 mm maximum; the NMP zero noted."""
    rep = check(system)
    bad = {f.check for f in rep.inconsistent}
    assert bad == {"tableI-actual-vs-theory-e12", "tableI-actual-vs-theory-e23",
                   "tableI-actual-vs-theory-e123", "tableI-theory-e23"}
    f = rep.find("fig2c-frequency-response")
    assert f.computed == pytest.approx(5.3155, abs=1e-3)
    assert rep.find("max-deflection").consistent


def test_cli_zoo_check_exits_3_with_findings():
    code = "import sys; from gripkit.cli import main; sys.exit(main())"
    r = subprocess.run([sys.executable, "-c", code, "zoo", "check", "amadeus-hand", "--json"],
                       capture_output=True, text=True)
    assert r.returncode == 3, r.stderr
    out = json.loads(r.stdout)
    assert out["consistent"] is False
    assert any(f["check"] == "tableI-theory-e12" and f["consistent"] for f in out["findings"])
