"""``gripkit.control.lqr`` (issue 27) equals python-control's ``control.dlqr`` (gain, Riccati
solution, closed-loop eigenvalues) on identified models: a subspace (n4sid) model and an ARX
model identified from simulated data, and with a cross weight N."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lfilter

from gripkit.control import lqr
from gripkit.errors import ModelError
from gripkit.sysid import arx, n4sid


def _identified():
    rng = np.random.default_rng(27)
    u = rng.standard_normal((1500, 2))
    y1 = (lfilter([0.0, 0.5, 0.2], [1.0, -1.5, 0.7], u[:, 0])
          + lfilter([0.0, 0.3], [1.0, -0.6], u[:, 1]))
    y2 = lfilter([0.0, 0.4], [1.0, -0.8], u[:, 1]) - 0.2 * lfilter([0.0, 1.0], [1.0, -0.5], u[:, 0])
    y = np.column_stack([y1, y2]) + 0.01 * rng.standard_normal((1500, 2))
    ss_model = n4sid(u, y, 4, dt=0.01)
    y_arx = y1 + 0.01 * rng.standard_normal(1500)
    arx_model = arx(u[:, 0], y_arx, 2, 2, 1, dt=0.01)
    return ss_model, arx_model


MODELS = _identified()


def _sorted(E):
    return E[np.lexsort((E.imag, E.real))]


@pytest.mark.parametrize("which", [0, 1], ids=["n4sid 2x2 order 4", "arx [2 2 1]"])
def test_lqr_equals_control_dlqr(which):
    import control  # a dev dependency: the cross-check fails, never skips, without it

    model = MODELS[which]
    ss = model.to_ss(model.dt)
    n, m = ss.B.shape
    Q, R = np.diag(np.arange(1.0, n + 1)), 0.5 * np.eye(m)
    K, S, E = lqr(model, Q, R)
    Kc, Sc, Ec = control.dlqr(ss.A, ss.B, Q, R)
    np.testing.assert_allclose(K, Kc, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(S, Sc, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(_sorted(E), _sorted(np.asarray(Ec)), rtol=1e-9, atol=1e-12)
    assert np.max(np.abs(E)) < 1.0
    N = 0.1 * np.ones((n, m))
    Kn, Sn, _ = lqr(model, Q, R, N)
    Knc, Snc, _ = control.dlqr(ss.A, ss.B, Q, R, N)
    np.testing.assert_allclose(Kn, Knc, rtol=1e-9, atol=1e-12)
    np.testing.assert_allclose(Sn, Snc, rtol=1e-9, atol=1e-12)


def test_the_identified_models_are_what_the_test_says():
    ss_model, arx_model = MODELS
    assert ss_model.order == 4 and len(ss_model.inputs) == 2 and len(ss_model.outputs) == 2
    assert arx_model.order == 2


def test_bad_weights_are_refused():
    model = MODELS[0]
    with pytest.raises(ModelError, match="Q must be a finite 4×4 matrix"):
        lqr(model, np.eye(3), np.eye(2))
    with pytest.raises(ModelError, match="R must be positive definite"):
        lqr(model, np.eye(4), np.zeros((2, 2)))
    with pytest.raises(ModelError, match="expected a gripkit.sysid.LinearModel"):
        lqr("model.json", np.eye(4), np.eye(2))
