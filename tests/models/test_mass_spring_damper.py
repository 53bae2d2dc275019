"""Mass-spring-damper with exact zero-order hold (gripkit.models.mass_spring_damper): the
closed-form 2×2 matrix exponential of :func:`msd_zoh` against scipy.linalg.expm (the augmented
matrix [[A, B], [0, 0]] gives A_d and B_d, Van Loan) and scipy.signal.cont2discrete, and the
simulated response against scipy.signal.dlsim."""

import math

import numpy as np
import pytest
from scipy import signal
from scipy.linalg import expm

from gripkit.models import MassSpringDamper


def _expm_zoh(m, b, k, h):
    A = np.array([[0.0, 1.0], [-k / m, -b / m]])
    B = np.array([[0.0], [1.0 / m]])
    M = np.zeros((3, 3))
    M[:2, :2], M[:2, 2:] = A, B
    E = expm(M * h)
    return E[:2, :2], E[:2, 2:], A, B


# under-, critically and over-damped, a damped free mass (k = 0), a free mass; the stiff,
# lightly damped case is a 8.5 kHz, ζ = 0.006 mode sampled at 20 kHz
CASES = [(1.0, 0.1, 1.0, 0.05), (2.0, 2 * math.sqrt(2.0 * 8.0), 8.0, 0.01), (1.0, 10.0, 4.0, 0.1),
         (0.5, 0.3, 0.0, 0.02), (3.0, 0.0, 0.0, 0.1), (1e-6, 2 * 0.006 * math.sqrt(2.85e3 * 1e-6),
                                                       2.85e3, 5e-5)]


@pytest.mark.parametrize("m,b,k,h", CASES)
def test_zoh_matrices_equal_the_matrix_exponential(m, b, k, h):
    Ad, Bd = MassSpringDamper(m=m, b=b, k=k, check=False).discrete_matrices(h)
    Ae, Be, A, B = _expm_zoh(m, b, k, h)
    np.testing.assert_allclose(Ad, Ae, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(Bd, Be, rtol=1e-10, atol=1e-14 * h * h / m)
    Ac, Bc, *_ = signal.cont2discrete((A, B, np.eye(2), np.zeros((2, 1))), h, method="zoh")
    np.testing.assert_allclose(Ad, Ac, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(Bd, Bc, rtol=1e-10, atol=1e-14 * h * h / m)


def test_simulation_equals_scipy_dlsim_and_reports_its_mode():
    """A 300-sample chirp-like force through m = 2, b = 0.4, k = 50: positions equal dlsim's to
    1e-12 of their range; modes() gives ω_n = √(k/m) = 5 rad/s and ζ = b/(2√(km)) = 0.02."""
    m, b, k, dt = 2.0, 0.4, 50.0, 0.01
    msd = MassSpringDamper(m=m, b=b, k=k)
    t = np.arange(300) * dt
    F = np.sin(2 * np.pi * (0.5 + 2 * t) * t)
    x = msd.simulate(F, dt=dt)["x"]
    A = np.array([[0.0, 1.0], [-k / m, -b / m]])
    sysd = signal.cont2discrete((A, np.array([[0.0], [1 / m]]), np.array([[1.0, 0.0]]),
                                  np.zeros((1, 1))), dt, method="zoh")
    ref = signal.dlsim(sysd[:4] + (dt,), F)[1][:, 0]
    np.testing.assert_allclose(x, ref, atol=1e-12 * np.ptp(ref))
    (wn, zeta), = msd.modes(msd.theta())
    assert (wn, zeta) == pytest.approx((5.0, 0.02), rel=1e-12)
    assert msd.natural_frequency_hz() == pytest.approx(5.0 / (2 * np.pi), rel=1e-12)
    assert msd.damping_ratio() == pytest.approx(0.02, rel=1e-12)
