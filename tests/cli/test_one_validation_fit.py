"""One validation fit (issue 25): ``identify ... --validate V`` reports the number that
``gripkit compare MODEL.json V`` reports for the saved model, for ARX (one and two inputs) and
state space, and both state the definition. The validation record sits at another operating
point than the estimation record, where the old ``--validate`` (the record's own means removed)
and ``compare`` (the model's offsets) disagreed."""

import json

import numpy as np
import pytest
from scipy import signal

from gripkit import Trajectory, sysid
from gripkit.cli import main
from gripkit.io import load, save
from gripkit.sysid import load_model
from gripkit.sysid.linear.linear_model import VALIDATION_FIT


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    """y1 = 0.4 q⁻¹/(1 − 0.7 q⁻¹) u1 + 0.2 q⁻¹ u2, y2 = 0.3 q⁻¹/(1 − 0.5 q⁻¹) u2 around the
    operating point u = (1, 0) → y = (1.333, 0); the validation record's inputs are offset by
    +0.3 and its outputs carry the static response to that shift plus a sensor bias."""
    d = tmp_path_factory.mktemp("val")
    out = {}
    for name, seed, shift, bias in (("est", 1, 0.0, 0.0), ("val", 2, 0.3, 0.05)):
        rng = np.random.default_rng(seed)
        n = 3000
        u1 = 1.0 + shift + rng.standard_normal(n)
        u2 = rng.standard_normal(n)
        y1 = signal.lfilter([0, 0.4], [1, -0.7], u1) + signal.lfilter([0, 0.2], [1], u2)
        y2 = signal.lfilter([0, 0.3], [1, -0.5], u2)
        y1 = y1 + bias + 0.02 * rng.standard_normal(n)
        y2 = y2 + 0.02 * rng.standard_normal(n)
        tr = Trajectory.uniform(dt=0.01, u1=u1, u2=u2, y1=y1, y2=y2,
                                units={"u1": "V", "u2": "V", "y1": "N", "y2": "N"})
        out[name] = d / f"{name}.csv"
        save(tr, out[name])
    out["dir"] = d
    return out


def _json(capsys, *args):
    code = main([*map(str, args), "--json"])
    out = capsys.readouterr()
    assert code == 0, out.err
    return json.loads(out.out)


@pytest.mark.parametrize("command", [
    ["arx", "--input", "u1", "--output", "y1", "--na", "1", "--nb", "1", "--nk", "1"],
    ["oe", "--input", "u1", "--output", "y1", "--nb", "1", "--nf", "1", "--nk", "1"],
    ["arx", "--input", "u1,u2", "--output", "y1,y2", "--na", "1", "--nb", "1", "--nk", "1"],
    ["ss", "--input", "u1,u2", "--output", "y1,y2", "--order", "2"],
])
def test_validate_reports_what_compare_reports(records, capsys, command):
    model = records["dir"] / f"{command[0]}-{len(command)}.json"
    res = _json(capsys, "identify", command[0], records["est"], *command[1:], "--validate",
                records["val"],
                "--out", model)
    cmp = _json(capsys, "compare", model, records["val"])
    vfit = res["validation"]["fit_percent"]
    vfit = vfit if isinstance(vfit, list) else [vfit]
    np.testing.assert_allclose(vfit, cmp["fit_percent"], rtol=1e-9)
    assert res["validation"]["definition"] == cmp["definition"] == VALIDATION_FIT
    # the bias of 0.05 N on y1 costs fit: the model's operating point is used, not the record's mean
    assert 50.0 < cmp["fit_percent"][0] < 99.0
    # the Python doors give that number exactly: model.compare on the record, and
    # sysid.compare / sysid.validate on its columns (the model's operating point removed inside)
    m, val = load_model(model), load(records["val"])
    assert m.compare(val).fit_percent == cmp["fit_percent"]
    u, y = val.as_array(*m.inputs), val.as_array(*m.outputs)
    assert sysid.compare(m, u, y).fit_percent == cmp["fit_percent"]
    if len(m.inputs) == len(m.outputs) == 1:
        assert sysid.validate(m, u[:, 0], y[:, 0]).fit_percent == cmp["fit_percent"][0]
        assert m.validate(val).fit_percent == cmp["fit_percent"][0]
