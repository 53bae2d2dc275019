"""Bad input: every case gives one clear error (or warning) naming what is wrong — issue 2's
list."""

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from arx_cases import simulate_arx

from gripkit import DataError, Trajectory, UnidentifiableError
from gripkit.errors import StabilityWarning
from gripkit.io import load
from gripkit.sysid import PolynomialModel, armax, arx, identify, oe, rls, structure_search

U, Y = simulate_arx(400, noise=1.0, seed=40)


@pytest.mark.parametrize("bad,label", [(np.nan, "NaN"), (np.inf, "infinite")])
@pytest.mark.parametrize("fn", [lambda u, y: arx(u, y, 2, 2, 2), lambda u, y: oe(u, y, 2, 2, 2),
                                lambda u, y: armax(u, y, 2, 2, 1, 2), lambda u,
                                y: rls(u, y, 2, 2, 2)],
                         ids=["arx", "oe", "armax", "rls"])
def test_nan_and_inf(fn, bad, label):
    y = Y.copy()
    y[[17, 30]] = bad
    with pytest.raises(DataError, match=rf"output y has 2 {label} values \(first at sample 17\)"):
        fn(U, y)


def test_nan_in_a_trajectory_names_the_column_and_time():
    y = Y.copy()
    y[5] = np.nan
    with pytest.raises(DataError, match=r"column 'force' has 1 NaN values \(first at t=0.025 s\)"):
        Trajectory.uniform(dt=0.005, current=U, force=y)


@pytest.mark.parametrize("t_bad,kind", [(0.01, "repeated"), (0.0, "decreasing")])
def test_repeated_or_decreasing_time_stamps(tmp_path, t_bad, kind):
    t = np.arange(50) * 0.005
    t[3] = t_bad if kind == "decreasing" else t[2]
    p = tmp_path / "d.csv"
    np.savetxt(p, np.column_stack([t, U[:50], Y[:50]]), delimiter=",", header="t,u,y", comments="")
    with pytest.raises(DataError, match=f"{kind} time"):
        load(p)


def test_non_uniform_sampling_is_refused():
    t = np.arange(400) * 0.005
    t[200:] += 0.002
    tr = Trajectory(t, {"u": U, "y": Y})
    with pytest.raises(DataError, match="ARX identification needs uniform sampling.*t=0.995"):
        identify(tr, "arx", input="u", output="y", na=2, nb=2, nk=2)


def test_too_few_samples():
    with pytest.raises(DataError, match=r"ARX \[4 4 2\] \(8 parameters, 5 initial "
                                        r"samples\) needs at "
                                        r"least 14 samples, found 10"):
        arx(U[:10], Y[:10], 4, 4, 2)
    with pytest.raises(DataError, match="OE \\[2 2 2\\] .* needs at least 43 samples"):
        oe(U[:30], Y[:30], 2, 2, 2)


def test_constant_input_is_unidentifiable_and_returns_nothing():
    """A constant input cannot identify B: say so, return no numbers."""
    with pytest.raises(UnidentifiableError, match=r"input u is constant \(0.85 for all "
                                                  r"400 samples\): "
                                                  r"a constant input cannot identify B"):
        arx(np.full(400, 0.85), Y, 2, 2, 2)
    for fn in (lambda: oe(np.full(400, 0.85), Y, 2, 2, 2),
               lambda: rls(np.full(400, 0.85), Y, 2, 2, 2),
               lambda: structure_search(np.full(400, 0.85), Y, "1:2", "1:2", "1:2")):
        with pytest.raises(UnidentifiableError, match="constant input cannot identify B"):
            fn()


def test_poorly_exciting_input_names_the_undetermined_parameters():
    """A single sine determines at most two B coefficients (its spectrum has one line)."""
    u = np.sin(2 * np.pi * np.arange(400) / 40)
    y = simulate_arx(400, noise=0.0, seed=41, u=u)[1]
    with pytest.raises(UnidentifiableError, match="condition number .* involves .*b"):
        arx(u, y, 0, 4, 1)


def test_missing_column():
    tr = Trajectory.uniform(dt=0.005, current=U, force=Y)
    with pytest.raises(DataError, match="column 'forse' not found; available "
                                        "columns: current, force"):
        identify(tr, "arx", input="current", output="forse", na=2, nb=2, nk=2)


def test_unstable_fitted_model_in_free_run_validation():
    """An unstable ARX fit (data from an unstable system) validated in free run: StabilityWarning
    and no fit number (never −10⁴⁰ %)."""
    rng = np.random.default_rng(42)
    u = rng.standard_normal(300)
    y = (simulate_arx(300, noise=0.01, seed=42, A=np.array([1.0, -1.05]), B=np.array([0.0, 1.0]),
                      u=u)[1])
    m = arx(u, y, 1, 1, 1)
    assert not m.stable
    with pytest.warns(StabilityWarning, match="largest pole magnitude 1.05"):
        v = m.validate(u, y)
    assert v.fit_percent is None


def test_mismatched_lengths_and_shapes():
    with pytest.raises(DataError, match="same length, found 400 and 399"):
        arx(U, Y[:-1], 2, 2, 2)
    # two inputs are a MIMO ARX (issue 13); two identical input columns cannot be told apart
    with pytest.raises(UnidentifiableError, match="poorly determined combination involves B2"):
        arx(np.c_[U, U], Y, 2, 2, 2)
    with pytest.raises(DataError, match="nb: expected an integer >= 1, found 0"):
        arx(U, Y, 2, 0, 2)
    with pytest.raises(DataError, match="na: expected an integer >= 0, found 1.5"):
        arx(U, Y, 1.5, 2, 2)


def test_constant_output():
    with pytest.raises(UnidentifiableError, match="output y is constant"):
        arx(U, np.full(400, 3.0), 2, 2, 2)


def test_model_built_from_bad_validation_data():
    m = PolynomialModel.from_coefficients([1.0, -0.5], [0.0, 1.0])
    y = Y.copy()
    y[3] = np.nan
    with pytest.raises(DataError, match="NaN"):
        m.validate(U, y)


@given(values=st.lists(st.floats(allow_nan=True, allow_infinity=True, width=64), min_size=1,
                       max_size=50))
def test_finiteness_check_without_temporaries_agrees_with_isfinite(values):
    """The min/max finiteness test of the signal checks (no N-element boolean temporary) says
    exactly what ``np.isfinite(a).all()`` says, for any mix of NaN, ±inf and finite values."""
    from gripkit.sysid.checks import _all_finite

    a = np.array(values)
    assert _all_finite(a) == bool(np.isfinite(a).all())


@given(values=st.lists(st.floats(allow_nan=False, allow_infinity=False, width=64), min_size=1,
                       max_size=50))
def test_rls_scale_statistics_agree_with_numpy(values):
    """The one-pass (max |x|, ‖x‖₂) of the RLS scale check equals numpy's, scaled so that values
    near the float64 limits neither overflow nor underflow."""
    from gripkit.sysid.linear.rls import _peak_and_norm

    a = np.array(values)
    peak, norm = _peak_and_norm(a)
    ref_peak = float(np.max(np.abs(a)))
    assert peak == ref_peak
    ref_norm = ref_peak * float(np.linalg.norm(a / ref_peak)) if ref_peak > 0 else 0.0
    assert norm == pytest.approx(ref_norm, rel=1e-13)
