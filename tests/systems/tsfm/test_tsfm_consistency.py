"""The seed's contradictions are found and reported (001_0b92a7da96e7aa46.txt Table I, Table II,
§IV-B, eq 13), in the zoo, in ``gripkit zoo check`` and when a user builds a model."""

import json
import math
import warnings

import pytest

from gripkit.cli import main
from gripkit.consistency import check
from gripkit.errors import ConsistencyWarning
from gripkit.systems.tsfm import TSFMFinger
from gripkit.systems.tsfm import parameters as z


def _findings(side):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return check(z.finger(side))


def test_the_two_contradictions_of_the_issue():
    """Table II: √(128/1.8e-6)/2π = 1342 Hz against 8520 Hz; b_s = 7e-4 gives ζ = 0.0231 against
    0.006. gripkit says which values it simulates."""
    rep = _findings("left")
    f0 = [f for f in rep if f.check == "sensor-natural-frequency" and "printed" in f.subject][0]
    assert not f0.consistent
    assert f0.computed == pytest.approx(math.sqrt(128 / 1.8e-6) / (2 * math.pi))
    assert f0.stated == 8520.0
    assert "2π dropped" in f0.message and "m_s = k_s/(2π f0)² = 4.467e-08 kg" in f0.used
    zt = [f for f in rep if f.check == "sensor-damping-ratio" and "printed" in f.subject][0]
    assert not zt.consistent and zt.computed == pytest.approx(7e-4 / (2 * math.sqrt(128 * 1.8e-6)))
    assert "b_s = 2ζ√(k_s m_s) = 2.869e-05" in zt.used
    # what gripkit simulates is consistent with the measurement
    own = [f for f in rep if f.subject == "tsfm-left" and f.check.startswith("sensor-")]
    assert own and all(f.consistent for f in own)


def test_other_contradictions_found_in_the_seed():
    """Eq 13's a2 (unit error), the left sensor's sensitivity 6e-3 V/µN against 200 µN/V (§IV-B);
    the right sensor (5.1e-3 V/µN) and both actuator stiffnesses (Table I, 1100 N/m) agree."""
    left, right = _findings("left"), _findings("right")
    bad = {f.check for f in left.inconsistent}
    assert {"sensor-natural-frequency", "sensor-damping-ratio", "eq13-a2",
            "sensor-sensitivity"} <= bad
    assert "sensor-sensitivity" not in {f.check for f in right.inconsistent}
    assert all(f.consistent for f in [*left, *right] if f.check in ("actuator-stiffness",
                                                                    "sensor-stiffness",
                                                                    "actuation-bandwidth"))


def test_a_user_model_with_table_ii_values_warns():
    with pytest.warns(ConsistencyWarning, match="1342.11 Hz, stated 8520 Hz"):
        TSFMFinger(z.table_ii("left"), reference=z.REFERENCE)


def test_zoo_check_cli(capsys):
    assert main(["zoo", "check", "tsfm-left", "--json"]) == 3
    out = json.loads(capsys.readouterr().out)
    assert not out["consistent"]
    names = {f["check"] for f in out["findings"] if not f["consistent"]}
    assert {"sensor-natural-frequency", "sensor-damping-ratio"} <= names
    assert main(["zoo", "show", "tsfm-right", "--json"]) == 0
    params = {p["name"]: p for p in json.loads(capsys.readouterr().out)["parameters"]}
    assert params["k_s"]["value"] == 130.8 and "Table II" in params["k_s"]["source"]
    assert params["L_a"]["source"].startswith("assumed")
    assert params["lam"]["unit"] == "m/V" and params["lam"]["value"] == pytest.approx(0.39e-6)


def test_gripper_zoo_entry_checks_table_iii():
    """Table III's stated errors (3, 2, 5 %) follow from its measured and estimated stiffnesses;
    §V-C's width example 400 − (62.42 + 39.4) = 298.18 µm."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        rep = check(z.gripper())
    for i in (1, 2, 3):
        assert rep.find(f"table-iii-error-{i}").consistent
    assert rep.find("width-example").consistent
    assert {"sensor-natural-frequency", "eq13-a2"} <= {f.check for f in rep.inconsistent}
