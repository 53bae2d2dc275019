"""The orders of ``gripkit identify arx|armax|oe|rls`` not given are those of
``gripkit.sysid.identify`` (issue 23): one table, ``LINEAR_ORDERS`` (na = nb = 2, nk = 1, nc = 1,
OE's nf = na), so the command without orders and the Python call without orders give one model,
bit for bit, on the file read by ``gripkit.io.load``; ``--help`` says each default."""

import json

import numpy as np
import pytest
from scipy import signal

from gripkit import Trajectory
from gripkit.cli import main
from gripkit.io import load, save
from gripkit.sysid import identify
from gripkit.sysid.checks import LINEAR_ORDERS

#: the orders each method's JSON reports, and the table entry each one defaults to (OE: nf = na)
ORDERS = {"arx": {"na": "na", "nb": "nb", "nk": "nk"},
          "armax": {"na": "na", "nb": "nb", "nc": "nc", "nk": "nk"},
          "oe": {"nb": "nb", "nf": "na", "nk": "nk"},
          "rls": {"na": "na", "nb": "nb", "nk": "nk"}}


@pytest.fixture(scope="module")
def data(tmp_path_factory):
    """y = 0.4 q⁻¹/(1 − 0.7 q⁻¹) u + noise around u = 1 V."""
    rng = np.random.default_rng(1)
    u = 1.0 + rng.standard_normal(2000)
    y = signal.lfilter([0, 0.4], [1, -0.7], u) + 0.02 * rng.standard_normal(2000)
    path = tmp_path_factory.mktemp("orders") / "est.csv"
    save(Trajectory.uniform(dt=0.01, u=u, y=y, units={"u": "V", "y": "N"}), path)
    return path


def test_the_table_is_the_documented_one():
    assert LINEAR_ORDERS == {"na": 2, "nb": 2, "nk": 1, "nc": 1}


@pytest.mark.parametrize("method", ["arx", "armax", "oe", "rls"])
def test_cli_without_orders_is_the_python_call_without_orders(data, capsys, method):
    code = main(["identify", method, str(data), "--input", "u", "--output", "y", "--json"])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    res = json.loads(cap.out)
    py = identify(load(data), method, inputs="u", outputs="y")
    assert {k: res[k] for k in ORDERS[method]} == {k: LINEAR_ORDERS[v]
                                                   for k, v in ORDERS[method].items()}
    if method == "rls":
        assert res["theta_final"] == py.theta_final.tolist()  # bit for bit
        return
    assert {k: getattr(py, k) for k in ORDERS[method]} == {k: res[k] for k in ORDERS[method]}
    assert res["theta"] == py.theta.tolist()  # bit for bit


@pytest.mark.parametrize("method, option", [("arx", "--na"), ("arx", "--nk"), ("armax", "--nc"),
                                            ("oe", "--nf"), ("rls", "--nb")])
def test_help_says_the_default(capsys, method, option):
    assert main(["identify", method, "--help"]) == 0
    text = " ".join(capsys.readouterr().out.split())
    key = "na" if option == "--nf" else option[2:]
    # the option's line ends with typer's "[default: N]", N from the library's table
    after = text[text.index(option):]
    assert "gripkit.sysid.identify" in after[:200]
    assert f"[default: {LINEAR_ORDERS[key]}]" in after[:200]
