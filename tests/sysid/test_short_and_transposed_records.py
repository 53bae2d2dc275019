"""Messages that named the wrong cause (API audit): a short record given to ``frf`` blamed
``nperseg`` (never passed), a short one given to ``hysteresis`` blamed ``burn_in = 0``, and a
(1, N) array passed for an (N,) record read as one sample of N channels ('needs more than 2
samples, found 1', 'input u1 is constant'). Each now names the record and what it needs."""

import numpy as np
import pytest

from gripkit import DataError, UnidentifiableError
from gripkit.sysid import arx, frf, hysteresis, n4sid, nlss, oe
from gripkit.sysid.linear.frf import _h1_min_samples

RNG = np.random.default_rng(0)
U = RNG.standard_normal(300)
Y = np.convolve(U, [0.0, 0.5, 0.3])[:300]


@pytest.mark.parametrize("n", [1, 12, 23])
def test_frf_on_a_short_record_says_how_many_samples_it_needs(n):
    """Default segments of 16 samples (N // 8 below 128), half overlapping: more than one
    segment needs 16 + 8 = 24 samples; two inputs need 16 + 2·8 = 32."""
    with pytest.raises(DataError, match=rf"a record of {n} sample\(s\) is too short for an H1 FRF "
                                        r"with 1 input\(s\): it needs at least 24"):
        frf(U[:n], Y[:n])
    assert frf(U[:24], Y[:24]).H.shape[1:] == (1, 1)
    assert [_h1_min_samples(m) for m in (1, 2, 3)] == [24, 32, 40]
    with pytest.raises(DataError, match=r"nperseg: expected 8 … 100 samples per segment, found "
                                        r"200"):
        frf(U[:100], Y[:100], nperseg=200)  # a user's own nperseg is still the one named


def test_spa_on_a_short_record_says_how_many_samples_it_needs():
    """The default lag window N/10 needs 2 lags: 20 samples (it blamed lag_window, never
    passed)."""
    with pytest.raises(DataError, match=r"a record of 19 sample\(s\) is too short for an SPA "
                                        r"FRF: it needs at least 20"):
        frf(U[:19], Y[:19], method="spa")
    assert frf(U[:20], Y[:20], method="spa").H.shape[1:] == (1, 1)


def test_a_row_given_to_a_single_channel_estimator_is_called_transposed():
    with pytest.raises(DataError, match=r"input u: expected a 1-D array of samples, found shape "
                                        r"\(1, 300\) \(one row: it looks transposed\); pass "
                                        r"x.ravel\(\)"):
        oe(U[None, :], Y[None, :], 2, 2, 1)


def test_hysteresis_on_a_short_record_asks_for_more_data_not_a_lower_burn_in():
    with pytest.raises(DataError, match=r"hysteresis: 5 samples; a loop needs at least 10; more "
                                        r"data are needed"):
        hysteresis((U[:5], Y[:5]), dt=1.0)


@pytest.mark.parametrize("fit", [lambda u, y: arx(u, y, 2, 2, 1), lambda u, y: n4sid(u, y, 2),
                                 lambda u, y: frf(u, y),
                                 lambda u, y: nlss((u, y), order=2, progress=False)],
                         ids=["arx", "n4sid", "frf", "nlss"])
def test_a_row_record_is_called_transposed(fit):
    with pytest.raises(DataError, match=r"u: shape \(1, 300\) is 1 sample\(s\) of 300 channels: "
                                        r"it looks transposed; samples go in rows: pass x.T"):
        fit(U[None, :], Y[None, :])


def test_a_short_wide_but_plausible_record_is_not_called_transposed():
    """4 samples of 3 inputs is short, not transposed: the count of equations is named."""
    with pytest.raises(UnidentifiableError, match="2 equations cannot determine 8") as exc:
        arx(RNG.standard_normal((4, 3)), RNG.standard_normal(4), 2, 2, 1)
    assert "transposed" not in str(exc.value)
