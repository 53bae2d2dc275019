"""The operating-point check of the array-level estimators (checks.warn_if_operating_point).

* σ_c of the constant term is the textbook standard error sqrt(s²·[(XᵀX)⁻¹]_pp) (s² = e·e/(m−p−1)),
  so |c|/σ_c and the decision do not depend on the units of u and y.
* A constant column in the span of the regressors (an input held constant over the fitted
  samples) is no operating point: the check says nothing (it printed c = 5.6e13 before).
* Inside identify(..., detrend='none') the warning names identify's own option."""

import math
import re
import warnings

import numpy as np
import pytest
from scipy.signal import lfilter

from gripkit.cli import main
from gripkit.signals import Trajectory
from gripkit.sysid import arx, identify
from gripkit.sysid.checks import constant_term, warn_if_operating_point
from gripkit.sysid.regression import arx_regression


def _record(n=2000, seed=0):
    """The review's record: y(t) = 0.9 y(t−1) + 0.5 u(t−1), u around 3, a sensor bias of 2 on y
    and noise of σ 0.2 (the true |c|/σ_c, from inv(XᵀX), is 6.86 for ARX [2 2 1])."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n) + 3.0
    y = lfilter([0.0, 0.5], [1.0, -0.9], u) + 2.0 + 0.2 * rng.standard_normal(n)
    return u, y


def _textbook(u, y, na=2, nb=2, nk=1):
    """(c, σ_c) by the normal equations: σ_c = sqrt(s²·inv(XᵀX)[p, p])."""
    X = arx_regression(u, y, na, nb, nk)
    p, m = na + nb, X.shape[0]
    Xc = np.column_stack([X[:, :p], np.ones(m)])
    th = np.linalg.lstsq(Xc, X[:, p], rcond=None)[0]
    e = X[:, p] - Xc @ th
    return th[p], math.sqrt(e @ e / (m - p - 1) * np.linalg.inv(Xc.T @ Xc)[p, p])


def _warned(fn):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        fn()
    return [str(w.message) for w in caught if "operating point" in str(w.message)]


def test_sigma_c_is_the_textbook_standard_error():
    u, y = _record()
    X = arx_regression(u, y, 2, 2, 1)
    theta, sigma_c = constant_term(X[:, :4], X[:, 4])
    c, sigma = _textbook(u, y)
    assert theta[4] == pytest.approx(c, rel=1e-10)
    assert sigma_c == pytest.approx(sigma, rel=1e-10)
    assert abs(c) / sigma == pytest.approx(6.86, abs=0.01)


@pytest.mark.parametrize("su, sy", [(1.0, 1.0), (1e-3, 1e-3), (1e3, 1e3), (1e-3, 1.0),
                                    (1.0, 1e3), (1e3, 1e-3)])
def test_the_decision_does_not_depend_on_the_units(su, sy):
    """The same record, u and y scaled together and separately: it warns every time, with the
    same |c|/σ_c = 6.86 (before: the norm of a column of R⁻¹ mixed in the other regressors'
    units, so the record warned at scale 1 and not at 1e-2)."""
    u, y = _record()
    msgs = _warned(lambda: warn_if_operating_point(u * su, y * sy, 2, 2, 1, "arx [2 2 1]"))
    assert len(msgs) == 1
    assert re.search(r"\|c\|/σ_c = 6\.86\b", msgs[0])


def test_a_constant_in_the_span_of_the_regressors_is_not_checked():
    """u = [0, 1, 1, …]: with nb = 1, nk = 1 and na = 2 the column u(t−1) is all ones over the
    fitted samples, the constant column itself; the fit cannot tell c from b (before, on this
    record: "c = 7.114e+13 (|c|/σ_c = 8.01) and a static gain of -4.947e+14 against 5.001")."""
    rng = np.random.default_rng(1)
    u = np.ones(500)
    u[0] = 0.0
    y = lfilter([0.0, 0.5], [1.0, -0.9], u) + 0.01 * rng.standard_normal(500)
    X = arx_regression(u, y, 2, 1, 1)
    assert np.all(X[:, 2] == 1.0)
    assert constant_term(X[:, :3], X[:, 3]) is None
    assert _warned(lambda: warn_if_operating_point(u, y, 2, 1, 1, "arx [2 1 1]")) == []


def test_the_remedy_named_is_the_callers():
    """A direct arx call is told of identify; identify(detrend='none') of its own
    detrend='mean' (CLI --detrend mean); both say to validate with the record's own values."""
    u, y = _record()
    (direct,) = _warned(lambda: arx(u, y, 2, 2, 1))
    assert direct.endswith("or use gripkit.sysid.identify, which removes the means")
    assert "u_offset=, y_offset= and validate the model with the record's own values " \
           "(m.compare(u, y)" in direct
    tr = Trajectory(np.arange(u.size) * 0.1, {"u": u, "y": y})
    (inside,) = _warned(lambda: identify(tr, "arx", input="u", output="y", na=2, nb=2, nk=1,
                                         detrend="none"))
    assert inside.endswith("or fit with detrend='mean' (CLI: --detrend mean), which removes the "
                           "means")
    assert "gripkit.sysid.identify" not in inside
    assert _warned(lambda: arx(u, y, 2, 2, 1))[0] == direct  # the context does not leak


def test_the_cli_names_its_own_option(tmp_path, capsys):
    """`gripkit identify arx --detrend none` on the record: the warning line ends with the
    option that removes the means, --detrend mean (an option the command has)."""
    u, y = _record()
    path = tmp_path / "op.csv"
    np.savetxt(path, np.column_stack([np.arange(u.size) * 0.1, u, y]), delimiter=",",
               header="time,u,y", comments="")
    code = main(["identify", "arx", str(path), "--input", "u", "--output", "y",
                 "--detrend", "none"])
    err = capsys.readouterr().err
    assert code == 0
    assert "warning: DataWarning: arx [2 2 1]: the data sit around an operating point" in err
    assert "or fit with detrend='mean' (CLI: --detrend mean), which removes the means" in err
