"""Continuous-time transfer function of several records at once (issue 25): every record's output
error from its own initial state (least squares inside the residual), σ from all records. Truth:
G(s) = 4/(s² + 0.8 s + 4) (the tfest example: ω_n = 2 rad/s, ζ = 0.2), sampled every 0.05 s with
a zero-order hold."""

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.lti import TransferFunction
from gripkit.sysid import identify, tfest
from gripkit.sysid.linear.tfest import tfest_records

G = TransferFunction([4.0], [1.0, 0.8, 4.0])
GD = G.c2d(0.05)
THETA = np.array([0.8, 4.0, 4.0])  # den[1], den[2], num[2]


def window(seed, start, n=2500, u0=0.0, noise=0.05):
    """Samples start … start + n − 1 of a run driven by white noise: the record begins in motion
    (its initial state is whatever the run reached), around the equilibrium (u0, u0)."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(start + n)
    y = GD.simulate(u)[:, 0]
    return u[start:] + u0, y[start:] + noise * rng.standard_normal(n)[-n:] + u0


def theta_of(m):
    return np.r_[m.system.denominator()[1:], m.system.numerator()[-1:]]


def std_of(m):
    return np.r_[m.info["den_std"][1:], m.info["num_std"][-1:]]


def test_records_cut_from_running_operation_within_3_sigma():
    """Two windows cut from running operation (each starts in motion): the fit of both, each from
    its own estimated initial state, lies within 3σ of the truth; its σ is below either record's
    alone, and each record's free-run fit is within 1 point of the noise limit
    100 (1 − 0.05/σ_y)."""
    recs = [window(1, 700), window(2, 1300)]
    m = tfest_records(recs, 2, 0, dt=0.05)
    assert np.all(np.abs(theta_of(m) - THETA) < 3 * std_of(m)), (theta_of(m), std_of(m))
    for u, y in recs:
        one = tfest(u, y, 2, 0, dt=0.05)
        assert np.all(std_of(m) < std_of(one))
    for r, (_, y) in zip(m.info["records"], recs):
        assert r["fit_percent"][0] > 100 * (1 - 0.05 / np.std(y)) - 1.0
    assert m.info["n_records"] == 2 and m.n_samples == 5000


def test_joined_records_biased_records_not():
    """Windows at two operating points (u0 = 0 and 3, data as they are): joined, the jump at the
    seam is simulated as a step response that is not in the data; the fit is pulled by many σ.
    Each record from its own initial state: within 3σ."""
    recs = [window(3, 600), window(4, 900, u0=3.0)]
    m = tfest_records(recs, 2, 0, dt=0.05)
    joined = tfest(np.concatenate([r[0] for r in recs]), np.concatenate([r[1] for r in recs]), 2, 0,
                   dt=0.05)
    assert np.all(np.abs(theta_of(m) - THETA) < 3 * std_of(m))
    assert np.max(np.abs(theta_of(joined) - THETA) / std_of(joined)) > 10.0


def test_identify_list_tf():
    recs = [window(5, 500, u0=1.0), window(6, 800, u0=1.0)]
    trs = [Trajectory.uniform(dt=0.05, u=u, y=y) for u, y in recs]
    m = identify(trs, "tf", input="u", output="y", poles=2, zeros=0)
    u0 = np.concatenate([r[0] for r in recs]).mean()
    assert m.u_offset[0] == pytest.approx(u0, rel=1e-12)
    assert np.all(np.abs(theta_of(m) - THETA) < 3 * std_of(m))


def test_cli_tf_several_files(tmp_path, capsys):
    import json

    from gripkit.cli import main
    from gripkit.io import load, save

    paths = []
    for k, (seed, start) in enumerate(((7, 400), (8, 900))):
        u, y = window(seed, start, n=2000)
        paths.append(tmp_path / f"run{k}.csv")
        save(Trajectory.uniform(dt=0.05, u=u, y=y), paths[-1])
    code = main(["identify", "tf", *map(str, paths), "--input", "u", "--output", "y", "--poles",
                 "2", "--zeros", "0", "--json"])
    out, err = capsys.readouterr()
    assert code == 0, err
    res = json.loads(out)
    m = identify([load(p) for p in paths], "tf", input="u", output="y", poles=2, zeros=0)
    np.testing.assert_allclose(res["den"], m.system.denominator(), rtol=1e-9)
    assert [r["data"] for r in res["records"]] == [str(p) for p in paths]
    np.testing.assert_allclose(res["den"], [1.0, 0.8, 4.0], atol=3 * max(res["den_std"]))
