"""Hysteresis fits of several records (issues 25 and 26): Bouc-Wen (actuator form) and
Prandtl–Ishlinskii, each record run from its own relaxed state (h = 0, every play at its first
input), one θ, σ from all records; against independent per-record fits and against the joined
record, whose run carries the first record's hysteresis state across the seam."""

import numpy as np
import pytest
from scipy.optimize import least_squares

from gripkit import Trajectory
from gripkit.errors import ArgumentError, DataError
from gripkit.sysid import BoucWenModel, PrandtlIshlinskiiModel, hysteresis, identify

N = 750
T = np.linspace(0.0, 1.0, N)
#: the seed's piezo actuator (as in test_hysteresis.py: 001_0b92a7da96e7aa46.txt Table II, eq 3)
SEED = dict(d=0.77e-6, alpha=0.43 / 0.77, beta=0.108, gamma=7.5e-3, offset=0.0)
#: two voltage sweeps from 0 V: the first ends at the top of a loop (75 V), the second starts
#: again at 0 V, so a joined record jumps 75 V → 0 V with the first record's h carried over
U1 = 50.0 - 50.0 * np.cos(2 * np.pi * 2.5 * T) * (1 - 0.5 * T)
U2 = 50.0 - 50.0 * np.cos(2 * np.pi * 2.0 * T) * (1 - 0.6 * T)
#: the Prandtl–Ishlinskii operator of test_hysteresis.py and sweeps of the same shapes
PI_R = np.arange(8) * 0.1
PI_W = np.array([0.5, 0.3, 0.2, 0.15, 0.1, 0.08, 0.05, 0.03])
V1, V2 = (U1 - 50.0) / 62.5, (U2 - 50.0) / 62.5


@pytest.fixture(scope="module")
def bw_records():
    truth = BoucWenModel(**SEED)
    rng = np.random.default_rng(3)
    return [(u, truth.simulate(u)[:, 0] + rng.normal(0.0, 0.2e-6, N)) for u in (U1, U2)]


@pytest.fixture(scope="module")
def pi_records():
    truth = PrandtlIshlinskiiModel(PI_R, PI_W, offset=0.2)
    rng = np.random.default_rng(4)
    return [(v, truth.simulate(v)[:, 0] + rng.normal(0.0, 0.01, N)) for v in (V1, V2)]


def test_bouc_wen_two_records_equal_the_fit_with_each_records_own_start(bw_records):
    m = hysteresis(bw_records, progress=False)
    names = list(m.free)
    assert names == ["d", "alpha", "beta", "gamma", "offset"]
    scale = np.array([1e-6, 1.0, 0.1, 0.01, 1e-6])

    def resid(p):  # each record's free run by BoucWenModel.simulate, from h = 0 at its start
        mm = BoucWenModel(**dict(SEED, **dict(zip(names, p * scale))))
        return np.concatenate([y - mm.simulate(u)[:, 0] for u, y in bw_records]) / 1e-6

    ref = least_squares(resid, np.array([SEED[k] for k in names]) / scale, xtol=1e-14,
                        ftol=1e-14, gtol=1e-14).x * scale
    for k, r in zip(names, ref):  # the same least squares (within 0.001σ)
        assert abs(getattr(m, k) - r) < 1e-3 * m.std[k], k
    for k in names:  # and the truth within 3σ
        assert abs(getattr(m, k) - SEED[k]) < 3 * m.std[k], k
    assert [r["n_samples"] for r in m.records] == [N, N]
    assert all(r["fit_percent"] > 98.5 for r in m.records) and m.fit_percent > 98.5
    assert m.to_dict()["records"] == m.records


def test_bouc_wen_joined_record_is_different_and_worse_at_the_seam(bw_records):
    (u1, y1), (u2, y2) = bw_records
    m = hysteresis(bw_records, progress=False)
    joined = hysteresis((np.r_[u1, u2], np.r_[y1, y2]), progress=False)
    # the false start biases every parameter (by ≫ 3σ here: 14–26σ)
    assert min(abs(getattr(joined, k) - getattr(m, k)) / m.std[k] for k in m.free) > 5
    # the first 100 samples after the seam: > 3× the noise (0.2 µm) off in the joined run, at the
    # noise level in the records fit
    e_joined = (np.r_[y1, y2] - joined.simulate(np.r_[u1, u2])[:, 0])[N:N + 100]
    e_rec = (y2 - m.simulate(u2)[:, 0])[:100]
    assert np.sqrt(np.mean(e_joined**2)) > 0.6e-6
    assert np.sqrt(np.mean(e_rec**2)) < 0.3e-6


def test_bouc_wen_sigma_from_both_records_about_one_over_sqrt2(bw_records):
    m = hysteresis(bw_records, progress=False)
    one = hysteresis(bw_records[0], progress=False)
    for k in m.free:
        assert 0.55 < m.std[k] / one.std[k] < 0.85, k


def test_pi_two_records_equal_least_squares_over_each_records_plays(pi_records):
    m = hysteresis(pi_records, "prandtl-ishlinskii", thresholds=PI_R)

    def plays(v):  # each play's output from its own relaxed start (a model with one weight 1)
        return np.column_stack([PrandtlIshlinskiiModel(PI_R, np.eye(8)[i], offset=0.0)
                                .simulate(v)[:, 0] for i in range(8)] + [np.ones(len(v))])

    A = np.vstack([plays(v) for v, _ in pi_records])
    ref = np.linalg.lstsq(A, np.concatenate([z for _, z in pi_records]), rcond=None)[0]
    np.testing.assert_allclose(m.weights, ref[:8], rtol=0, atol=1e-9)
    assert m.offset == pytest.approx(ref[8], abs=1e-9)
    assert np.all(np.abs(m.weights - PI_W) < 3 * m.weights_std)
    one = hysteresis(pi_records[0], "prandtl-ishlinskii", thresholds=PI_R)
    ratio = m.weights_std / one.weights_std
    assert np.all((ratio > 0.55) & (ratio < 0.85)), ratio
    (v1, z1), (v2, z2) = pi_records
    joined = hysteresis((np.r_[v1, v2], np.r_[z1, z2]), "prandtl-ishlinskii", thresholds=PI_R)
    assert np.max(np.abs(joined.weights - m.weights) / m.weights_std) > 5
    e_joined = (np.r_[z1, z2] - joined.simulate(np.r_[v1, v2])[:, 0])[N:N + 100]
    e_rec = (z2 - m.simulate(v2)[:, 0])[:100]
    assert np.sqrt(np.mean(e_joined**2)) > 0.05 and np.sqrt(np.mean(e_rec**2)) < 0.015


def test_identify_with_a_list_of_trajectories(bw_records):
    trs = [Trajectory.uniform(dt=1e-3, volt=u, disp=y) for u, y in bw_records]
    m = identify(trs, "hysteresis", input="volt", output="disp", progress=False)
    ref = hysteresis(bw_records, progress=False)
    assert isinstance(m, BoucWenModel) and m.inputs == ("volt",) and m.outputs == ("disp",)
    assert m.d == pytest.approx(ref.d, rel=1e-9) and m.beta == pytest.approx(ref.beta, rel=1e-9)
    direct = hysteresis(trs, input="volt", output="disp", progress=False)
    assert direct.fit_percent == pytest.approx(m.fit_percent, abs=1e-9)


def test_a_mismatched_record_is_named(bw_records):
    (u1, y1), (u2, y2) = bw_records
    tr1 = Trajectory.uniform(dt=1e-3, volt=u1, disp=y1)
    slow = Trajectory.uniform(dt=2e-3, volt=u2, disp=y2)
    other = Trajectory.uniform(dt=1e-3, volt=u2, force=y2)
    for fit in (lambda d: identify(d, "hysteresis", input="volt", output="disp"),
                lambda d: hysteresis(d, input="volt", output="disp")):
        with pytest.raises(DataError, match=r"data\[1\] is sampled at 500 Hz, data\[0\] at 1000"):
            fit([tr1, slow])
        with pytest.raises(DataError, match=r"data\[1\].*'disp'"):
            fit([tr1, other])
    with pytest.raises(DataError, match=r"hysteresis data\[1\] not excited"):
        hysteresis([(u1, y1), (np.linspace(0, 1, N), y2)], progress=False)
    with pytest.raises(ArgumentError, match="oscillator is fitted to one record"):
        hysteresis([tr1, tr1], input="volt", output="disp", form="oscillator")


def test_cli_identify_hysteresis_of_two_files(bw_records, tmp_path, capsys):
    import json

    from gripkit.cli import main

    paths = [tmp_path / "sweep1.csv", tmp_path / "sweep2.csv"]
    for path, (u, y) in zip(paths, bw_records):
        np.savetxt(path, np.column_stack([u, y]), delimiter=",", header="volt,disp",
                   comments="", fmt="%.17g")
    code = main([*map(str, ["identify", "hysteresis", *paths, "--input", "volt", "--output",
                            "disp", "--fs", 1000, "--json"])])
    out, err = capsys.readouterr()
    assert code == 0, err
    d = json.loads(out)
    ref = hysteresis(bw_records, progress=False)
    assert d["data"] == [str(p) for p in paths] and len(d["records"]) == 2
    assert [r["data"] for r in d["records"]] == [str(p) for p in paths]
    for r, q in zip(d["records"], ref.records):
        assert r["fit_percent"] == pytest.approx(q["fit_percent"], abs=1e-6)
    values = {p["name"]: p["value"] for p in d["parameters"]}
    assert values["beta"] == pytest.approx(ref.beta, rel=1e-6)
    assert d["fit_percent"] == pytest.approx(ref.fit_percent, abs=1e-6)
