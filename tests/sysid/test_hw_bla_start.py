"""Hammerstein–Wiener models from a periodic record (issue 26, family 2, ``periods=P``): the
linear block starts from the weighted frequency-domain fit of the best linear approximation (the
FRF of the periods with its σ) in place of the time-domain ARX / subspace start. The FRF start
reaches the same optimum as the time-domain start and recovers a known Wiener system within 3σ;
the start itself is the true linear block times the BLA gain of the static nonlinearity
(Bussgang); bad input and the CLI."""

import importlib
import json

import numpy as np
import pytest
from scipy.signal import freqz, lfilter

from gripkit.errors import ArgumentError, DataError
from gripkit.sysid import hammerstein_wiener

HW = importlib.import_module("gripkit.sysid.nonlinear.hammerstein_wiener")

#: the Wiener system: (0.4 q⁻¹ + 0.2 q⁻²)/(1 − 0.9 q⁻¹ + 0.3 q⁻²) (poles 0.45 ± 0.312j), then
#: g(x) = x + 0.2 x² − 0.1 x³, output noise σ_e = 0.05
B, F = [0.0, 0.4, 0.2], [1.0, -0.9, 0.3]
C2, C3, NOISE = 0.2, -0.1, 0.05
#: the true parameters [b1 b2 f1 f2 out_c2 out_c3 y0] (B/F) and [a1 a2 b1 b2 …] (state space,
#: nk = 1: the same transfer function)
TRUE = {"oe": [0.4, 0.2, -0.9, 0.3, C2, C3, 0.0], "ss": [-0.9, 0.3, 0.4, 0.2, C2, C3, 0.0]}


def multisine(rng, L: int, P: int) -> np.ndarray:
    """P periods of a random-phase multisine of period L exciting every line 1 … L/2 − 1 with
    equal amplitude, rms 1."""
    k = np.arange(1, L // 2)
    x = np.cos(2 * np.pi * np.outer(np.arange(L), k) / L + rng.uniform(0, 2 * np.pi, len(k)))
    x = x.sum(axis=1)
    return np.tile(x / x.std(), P)


def wiener(rng, L: int = 512, P: int = 4):
    """The Wiener system driven by ``multisine(rng, L, P)`` from rest. Returns u, y, x."""
    u = multisine(rng, L, P)
    x = lfilter(B, F, u)
    return u, x + C2 * x**2 + C3 * x**3 + NOISE * rng.normal(size=len(u)), x


@pytest.mark.parametrize("linear", ["oe", "ss"])
def test_frf_start_reaches_the_time_domain_optimum_and_the_truth(linear):
    """Both starts end at the same minimum of the simulation error (parameters within 0.01σ, the
    accuracy of the Levenberg–Marquardt stop), every parameter within 3σ of the truth, and the
    record says how the linear block was started."""
    u, y, _ = wiener(np.random.default_rng(0))
    kw = dict(nb=2, nf=2) if linear == "oe" else dict(order=2)
    ref = hammerstein_wiener(u, y, output_nonlinearity="poly:3", nk=1, linear=linear, **kw)
    m = hammerstein_wiener(u, y, output_nonlinearity="poly:3", nk=1, linear=linear, periods=4,
                           **kw)
    assert np.all(np.isfinite(m.theta_std))
    np.testing.assert_array_less(np.abs(m.theta - ref.theta), 0.01 * ref.theta_std)
    np.testing.assert_array_less(np.abs(m.theta - TRUE[linear]), 3.0 * m.theta_std)
    assert m.fit_percent == pytest.approx(ref.fit_percent, abs=1e-6)
    assert "linear start from the best linear approximation (FRF of 4 periods" in m.criterion
    assert "best linear approximation" not in ref.criterion


def test_frf_start_with_searched_orders_reaches_the_same_model():
    """Orders not given: chosen as with the time-domain start (the same nb, nf, nk), the same
    final parameters."""
    u, y, _ = wiener(np.random.default_rng(1))
    ref = hammerstein_wiener(u, y, output_nonlinearity="poly:3")
    m = hammerstein_wiener(u, y, output_nonlinearity="poly:3", periods=4)
    assert (m.nb, m.nf, m.nk) == (ref.nb, ref.nf, ref.nk) == (2, 2, 1)
    np.testing.assert_array_less(np.abs(m.theta - ref.theta), 0.01 * ref.theta_std)


@pytest.mark.parametrize("seed", range(6))
def test_frf_start_is_the_true_block_times_the_bla_gain(seed):
    """For a Gaussian-like input the best linear approximation of the Wiener system is
    ``α B/F`` with ``α = E[g'(x)] = 1 + 2 c2 E[x] + 3 c3 E[x²]`` (Bussgang; ≈ 0.80 here): the
    start fitted to it (L = 2048, 3 periods) has the true poles within 0.04 (|p| = 0.55; the
    one-realisation BLA still carries the stochastic nonlinear distortions) and its response on
    the excited lines is α B/F with the factor within 0.05 of α."""
    u, y, x = wiener(np.random.default_rng(seed), L=2048, P=3)
    bla = HW._bla(u, y, 3)
    b, f = HW._bla_fit(bla, 2, 2, 1)
    poles = np.sort_complex(np.roots(np.r_[1.0, f]))
    np.testing.assert_allclose(poles, np.sort_complex(np.roots(F)), rtol=0, atol=0.04)
    w = -np.angle(bla[0])
    g0, gs = freqz(B, F, w)[1], freqz(np.r_[0.0, b], np.r_[1.0, f], w)[1]
    factor = np.sum((g0.conj() * gs).real) / np.sum(np.abs(g0) ** 2)
    alpha = 1 + 2 * C2 * x.mean() + 3 * C3 * np.mean(x**2)
    assert factor == pytest.approx(alpha, abs=0.05)
    a_ss = HW._bla_ss_start(bla, 2, 1)[:2]        # the state-space start: the same poles
    np.testing.assert_allclose(a_ss, f, rtol=0, atol=1e-12)


def test_bad_periods_are_named():
    u, y, _ = wiener(np.random.default_rng(2), L=128, P=4)
    for p in (1, 2, 2.5, True):
        with pytest.raises(ArgumentError, match="periods must be an integer ≥ 3"):
            hammerstein_wiener(u, y, nb=2, nf=2, nk=1, periods=p)
    with pytest.raises(DataError, match="do not split into 4 whole periods"):
        hammerstein_wiener(u[:-1], y[:-1], nb=2, nf=2, nk=1, periods=4)
    with pytest.raises(DataError, match="the input is not periodic with 4 periods of 128"):
        hammerstein_wiener(np.random.default_rng(3).normal(size=512), y, nb=2, nf=2, nk=1,
                           periods=4)
    with pytest.raises(ArgumentError, match="periods takes one record"):
        hammerstein_wiener([(u, y), (u, y)], nb=2, nf=2, nk=1, periods=4)


def _cli(capsys, *args):
    from gripkit.cli import main

    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_periods_gives_the_python_fit_and_names_bad_input(tmp_path, capsys):
    u, y, _ = wiener(np.random.default_rng(4), L=256, P=4)
    est, bad = tmp_path / "est.csv", tmp_path / "bad.csv"
    np.savetxt(est, np.column_stack([u, y]), delimiter=",", header="valve,force", comments="",
               fmt="%.17g")
    ur = np.random.default_rng(5).normal(size=len(u))
    np.savetxt(bad, np.column_stack([ur, y]), delimiter=",", header="valve,force", comments="",
               fmt="%.17g")
    base = ("identify", "hw", est, "--input", "valve", "--output", "force", "--fs", 1,
            "--output-nonlinearity", "poly:3", "--nb", 2, "--nf", 2, "--nk", 1)
    code, out, err = _cli(capsys, *base, "--periods", 4, "--json")
    assert code == 0, err
    d = json.loads(out)
    py = hammerstein_wiener(u, y, output_nonlinearity="poly:3", nb=2, nf=2, nk=1, periods=4)
    assert d["fit_percent"] == pytest.approx(py.fit_percent, abs=1e-6)
    assert "FRF of 4 periods" in d["structure"]["criterion"]
    code, out, err = _cli(capsys, *base, "--periods", 1)
    assert code != 0 and err.startswith("error: ArgumentError: hammerstein_wiener: --periods "
                                        "must be an integer ≥ 3")
    assert "Traceback" not in err
    code, out, err = _cli(capsys, *base, "--periods", 3)
    assert code != 0 and err.startswith("error: DataError: hammerstein_wiener: periods: 1024 "
                                        "samples do not split into 3 whole periods")
    code, out, err = _cli(capsys, *base[:2], bad, *base[3:], "--periods", 4)
    assert code != 0 and err.startswith("error: DataError: hammerstein_wiener: periods: the "
                                        "input is not periodic")
    code, out, err = _cli(capsys, *base[:3], est, *base[3:], "--periods", 4)
    assert code != 0 and err.startswith("error: ArgumentError: hammerstein_wiener: --periods "
                                        "takes one record")
