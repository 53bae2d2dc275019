"""Recursive least squares: λ = 1 gives the LS solution, λ < 1 tracks a change, the covariance
stays finite, symmetric and positive definite over 10⁷ samples, streaming = batch."""

import numpy as np
import pytest
from arx_cases import A222, B222, THETA222, simulate_arx
from scipy.signal import lfilter

from gripkit import DataError, IdentificationError, UnidentifiableError
from gripkit.sysid import RLS, arx, rls


def test_forgetting_one_converges_to_least_squares():
    """With λ = 1 and a vague prior (P0 = 10⁸ I) RLS minimises the same sum of squares as LS
    (eq 29): θ and σ agree with arx() on the same record."""
    u, y = simulate_arx(3000, noise=2.0, seed=21)
    m = arx(u, y, 2, 2, 2)
    r = rls(u, y, 2, 2, 2, forgetting=1.0, p0=1e8)
    np.testing.assert_allclose(r.theta_final, m.theta, rtol=1e-6, atol=1e-9)
    np.testing.assert_allclose(r.theta_std_final, m.theta_std, rtol=1e-4)
    assert r.names == ("a1", "a2", "b2", "b3")
    assert r.theta.shape == (3000, 4) and r.theta_std.shape == (3000, 4)
    np.testing.assert_array_equal(r.theta[-1], r.theta_final)
    # the final model of the RLS is a PolynomialModel in MATLAB layout
    assert r.model.B.tolist()[:2] == [0.0, 0.0] and r.model.A[0] == 1.0


def test_streaming_update_equals_batch_kernel_bit_for_bit():
    u, y = simulate_arx(2500, noise=1.0, seed=22)
    for windup in ("trace", "directional", "none"):
        s = RLS(2, 2, 2, forgetting=0.97, windup=windup)
        errs = [s.update(a, b) for a, b in zip(u, y)]
        b = RLS(2, 2, 2, forgetting=0.97, windup=windup)
        res = b.run(u[:700], y[:700])
        b.run(u[700:], y[700:])  # continues from the state
        np.testing.assert_array_equal(s.theta, b.theta)
        np.testing.assert_array_equal(s.P, b.P)
        np.testing.assert_array_equal(np.asarray(errs[:700]), res.errors)
    assert s.n_updates == 2500 - 3 and s.ready


def test_streaming_update_with_huge_covariance_equals_batch_kernel():
    """With P0 = 10³⁰⁰·I the streaming step cannot show beforehand that its update stays finite
    (its bound (max|P| + |coef|·max|q|²)·p exceeds 1e300), so it backs θ and P up and updates
    them from there; the result is still the batch kernel's, bit for bit, and a sample that
    overflows φᵀPφ is refused with the estimator unchanged."""
    u, y = simulate_arx(400, noise=1.0, seed=26)
    u, y = 1e-3 * u, 1e-3 * y
    s = RLS(2, 2, 2, forgetting=0.99, p0=1e300, windup="none")
    errs = [s.update(float(a), float(b)) for a, b in zip(u, y)]
    b = RLS(2, 2, 2, forgetting=0.99, p0=1e300, windup="none")
    res = b.run(u, y)
    np.testing.assert_array_equal(s.theta, b.theta)
    np.testing.assert_array_equal(s.P, b.P)
    np.testing.assert_array_equal(np.asarray(errs), res.errors)
    fresh = RLS(2, 2, 2, p0=1e300)
    for _ in range(3):  # fill the regressor: no update yet
        fresh.update(1e4, 1e4)
    theta, P = fresh.theta, fresh.P
    with pytest.raises(IdentificationError, match="φᵀPφ overflows"):
        fresh.update(1e4, 1e4)  # φᵀPφ = 1e300·4e8: beyond float64
    np.testing.assert_array_equal(fresh.theta, theta)
    np.testing.assert_array_equal(fresh.P, P)


def _textbook_rls(u, y, lam, p0, windup, max_trace=None):
    """The module docstring's updates written with numpy matrices, one sample at a time: gain
    K = Pφ/(λ + r), exponential forgetting P ← (P − PφφᵀP/(λ + r))/λ (bounded trace for 'trace'),
    directional P ← P + (1 − λ − r)/(r(λ + r))·PφφᵀP (plain λ = 1 step when r ≤ 1e-12·trace P)."""
    th, P = np.zeros(4), p0 * np.eye(4)
    max_trace = 4 * p0 if max_trace is None else max_trace
    for t in range(3, y.size):
        phi = np.array([-y[t - 1], -y[t - 2], u[t - 2], u[t - 3]])
        Pphi = P @ phi
        r = phi @ Pphi
        e = y[t] - phi @ th
        th = th + Pphi * e / (lam + r)
        if windup == "directional":
            if r <= 1e-12 * np.trace(P):
                P = P - np.outer(Pphi, Pphi) / (1 + r)
            else:
                P = P + (1 - lam - r) / (r * (lam + r)) * np.outer(Pphi, Pphi)
        else:
            P = (P - np.outer(Pphi, Pphi) / (lam + r)) / lam
            if windup == "trace" and np.trace(P) > max_trace:
                P = P * (max_trace / np.trace(P))
    return th, P


@pytest.mark.parametrize("windup", ["none", "trace", "directional"])
def test_kernel_equals_the_textbook_update(windup):
    """The compiled kernel (P ← (P + coef·q qᵀ)·scale on the upper triangle) gives the textbook
    matrix recursion's θ and P to rounding over 3000 samples, with forgetting 0.98 (trace bound
    active with p0 = 1e4)."""
    u, y = simulate_arx(3000, noise=0.5, seed=29)
    est = RLS(2, 2, 2, forgetting=0.98, p0=1e4, windup=windup)
    est.run(u, y, store=False)
    th, P = _textbook_rls(u, y, 0.98, 1e4, windup)
    np.testing.assert_allclose(est.theta, th, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(est.P, P, rtol=1e-7, atol=1e-12 * np.abs(P).max())


def test_forgetting_tracks_a_step_change_in_parameters():
    """Parameters jump at t = 3000 from Table II [2 2 2] (S1) to Table II [2 2 2] (S2,
    A = [1, −1.9258, 0.9432], B = [0, 0, 0.2382, −0.2687]); with λ = 0.98 (memory ≈ 50 samples)
    the estimate is back within 3σ of the new truth 1000 samples later; λ = 1 is not."""
    rng = np.random.default_rng(23)
    A2 = np.array([1.0, -1.9258, 0.9432])
    B2 = np.array([0.0, 0.0, 0.2382, -0.2687])
    n = 6000
    u = 100 * rng.standard_normal(n)
    e = rng.standard_normal(n)
    y = np.zeros(n)
    for t in range(3, n):
        A, B = (A222, B222) if t < 3000 else (A2, B2)
        y[t] = -A[1] * y[t - 1] - A[2] * y[t - 2] + B[2] * u[t - 2] + B[3] * u[t - 3] + e[t]
    new = np.r_[A2[1:], B2[2:]]
    r = rls(u, y, 2, 2, 2, forgetting=0.98)
    assert np.all(np.abs(r.theta[2990] - THETA222) < 3 * r.theta_std[2990])  # before: old truth
    assert np.all(np.abs(r.theta[4000] - new) < 3 * r.theta_std[4000])
    assert np.all(np.abs(r.theta[-1] - new) < 3 * r.theta_std[-1])
    r1 = rls(u, y, 2, 2, 2, forgetting=1.0)
    assert np.any(np.abs(r1.theta[4000] - new) > 3 * r1.theta_std[4000])


@pytest.mark.parametrize("windup", ["none", "trace", "directional"])
def test_specialised_batch_kernel_equals_the_generic_one(monkeypatch, windup):
    """A record of SPECIALISE_ABOVE samples runs through the kernel compiled for its structure
    (orders as compile-time sizes, one sample loop per windup mode); with the threshold raised
    the same record runs through the generic kernel, whose arithmetic is the textbook-checked
    one above: θ and σ histories, predictions, errors and the final P agree bit for bit, with
    λ = 0.995 (forgetting) and the trace bound reached (p0 = 1e4, max_trace = 1e3)."""
    from gripkit.sysid.linear import rls as rls_module

    n = rls_module.SPECIALISE_ABOVE
    u, y = simulate_arx(n, noise=0.5, seed=31)
    kw = dict(forgetting=0.995, p0=1e4, windup=windup, max_trace=1e3)
    fast = rls(u, y, 2, 2, 2, **kw)
    monkeypatch.setattr(rls_module, "SPECIALISE_ABOVE", n + 1)
    generic = rls(u, y, 2, 2, 2, **kw)
    for name in ("theta", "theta_std", "y_pred", "errors", "P_final"):
        np.testing.assert_array_equal(getattr(fast, name), getattr(generic, name), err_msg=name)
    assert fast.loss == generic.loss


def _first_absurd_reference(x, peak, factor):
    """The corrupt-sample rule of RLS.update, sample by sample."""
    for i, v in enumerate(x):
        if abs(v) > peak:
            if peak > 0.0 and abs(v) > factor * peak:
                return i, peak
            peak = abs(v)
    return -1, peak


def test_blockwise_corrupt_sample_scan_equals_the_sample_rule():
    """The batch scan for corrupt samples skips blocks of 256 whose peak cannot break the rule;
    on 400 random records (leading zeros, spikes of 10⁵…10¹⁵ times the signal, NaN and inf,
    several start peaks and factors) it returns the sample-by-sample rule's index and peak, and
    where it finds none numpy's min and max and whether every sample is finite (its one pass
    replaces those three)."""
    from gripkit.sysid.linear.rls import _scan_signal

    rng = np.random.default_rng(41)
    hits = 0
    for _ in range(400):
        n = int(rng.integers(1, 1500))
        x = rng.standard_normal(n) * 10.0 ** rng.uniform(-5, 5)
        if rng.random() < 0.5:
            x[:int(rng.integers(0, n))] = 0.0
        if rng.random() < 0.6:
            j = int(rng.integers(0, n))
            x[j] *= 10.0 ** rng.uniform(5, 15)
        if rng.random() < 0.1:
            x[int(rng.integers(0, n))] = rng.choice([np.nan, np.inf, -np.inf])
        peak = float(rng.choice([0.0, 1e-3, 1.0]))
        factor = float(rng.choice([1e10, 10.0]))
        ref = _first_absurd_reference(x, peak, factor)
        bad, end_peak, lo, hi, finite = _scan_signal(x, peak, factor)
        assert (bad, end_peak) == ref
        if bad < 0:
            assert finite == bool(np.isfinite(x).all())
            if finite:
                assert (lo, hi) == (x.min(), x.max())
        hits += ref[0] >= 0
    assert 50 < hits < 350  # both outcomes are exercised


@pytest.mark.parametrize("windup", ["trace", "directional"])
def test_ten_million_samples_of_periodic_excitation_stay_finite_and_pd(windup):
    """10⁷ samples of a single sine (periodic, exciting only 2 of the 6 directions of φ) with
    λ = 0.98: without protection P grows like λ⁻ᵗ; with the trace bound or directional forgetting
    it stays finite, symmetric and positive definite (checked after every 10⁶ samples)."""
    n_chunk, chunks = 1_000_000, 10
    A = np.array([1.0, -1.8732, 0.8996])
    B = np.array([0.0, 0.1950, -0.2276, 0.05])
    est = RLS(2, 4, 0, forgetting=0.98, windup=windup, p0=100.0)
    rng = np.random.default_rng(24)
    zi = np.zeros(3)
    k0 = 0
    for c in range(chunks):
        k = np.arange(k0, k0 + n_chunk)
        k0 += n_chunk
        u = np.sin(2 * np.pi * k / 40.0)
        y, zi = lfilter(B, A, u, zi=zi)
        y = y + 1e-3 * rng.standard_normal(n_chunk)
        res = est.run(u, y, store=(c == chunks - 1))
        P = est.P
        assert np.isfinite(P).all() and np.isfinite(est.theta).all()
        np.testing.assert_array_equal(P, P.T)
        assert np.linalg.eigvalsh(P).min() > 0
        assert np.trace(P) <= 6 * 100.0 * (1 + 1e-12) or windup == "directional"
    assert est.n_updates == 10**7 - 3
    assert np.isfinite(res.theta).all() and np.isfinite(res.theta_std).all()
    # the sine is still predicted: the a-priori error is at the noise level
    assert np.sqrt(np.mean(res.errors[-1000:] ** 2)) < 5e-3


def test_without_protection_the_covariance_winds_up():
    """Same periodic excitation, windup='none': trace(P) grows like 0.98⁻ᵗ — the reason the
    protection exists — and a run that overflows raises instead of returning NaN."""
    k = np.arange(40000)
    u = np.sin(2 * np.pi * k / 40.0)
    y = lfilter([0, 0.195, -0.2276, 0.05], [1, -1.8732, 0.8996], u)
    est = RLS(2, 4, 0, forgetting=0.98, windup="none", p0=100.0)
    est.run(u[:600], y[:600], store=False)
    assert np.trace(est.P) > 1e3 * 600  # 0.98^-600 ≈ 1.8e5
    with pytest.raises(IdentificationError, match="diverged.*windup"):
        est.run(u[600:], y[600:], store=False)


def test_rls_errors():
    with pytest.raises(DataError, match="forgetting factor"):
        RLS(2, 2, 2, forgetting=1.5)
    with pytest.raises(DataError, match="windup"):
        RLS(2, 2, 2, windup="bogus")
    with pytest.raises(DataError, match="theta0"):
        RLS(2, 2, 2, theta0=[1.0, 2.0])
    with pytest.raises(DataError, match="needs at least 8 samples"):
        rls(np.arange(5.0), np.arange(5.0), 2, 2, 2)
    with pytest.raises(UnidentifiableError, match="constant"):
        rls(np.ones(100), np.arange(100.0), 2, 2, 2)


def test_trajectory_export():
    u, y = simulate_arx(500, noise=1.0, seed=25)
    r = rls(u, y, 2, 2, 2, forgetting=0.99, dt=0.005)
    tr = r.to_trajectory()
    assert {"a1", "b3", "a1_std", "y_pred", "error"} <= set(tr.names)
    assert tr.dt == pytest.approx(0.005)
    np.testing.assert_allclose(tr["a1"][-1], r.theta_final[0])


def test_loss_summed_in_the_kernel_is_eq29_of_the_stored_errors():
    """The batch kernel sums e² as it goes (no second pass over e): the loss is ½·e·e/updates of
    the stored a-priori errors (eq (29)) to rounding, on a first record and on a second one run
    from the first's state (whose first samples go through the streaming step, with updates)."""
    u, y = simulate_arx(3000, noise=0.3, seed=5)
    est = RLS(2, 2, 2, forgetting=0.999)
    first = est.run(u[:2000], y[:2000])
    second = est.run(u[2000:], y[2000:])
    for res, nupd in ((first, 2000 - 3), (second, 1000)):
        e = res.errors[res.first_update:]
        assert e.size == nupd
        np.testing.assert_allclose(res.loss, 0.5 * float(e @ e) / nupd, rtol=1e-12)
        assert np.all(res.errors[:res.first_update] == 0.0)
