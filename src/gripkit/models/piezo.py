"""Piezoelectric bending actuator with voltage, force and moment inputs
(``001_0b92a7da96e7aa46.txt``
eqs 2–4).

    y_A = [ d_p U − H_s(U) − s_p F_A − (3/(2 L_a)) s_p M_A ] · D(s)
    α_A = [ (2/L_a)(d_p U − H_s(U)) − (3/(2 L_a)) s_p F_A − (3/L_a²) s_p M_A ] · D(s)      (eq 4)
    D(s) = 1 / (a s² + b s + 1)

U: voltage (V); F_A (N), M_A (N·m): force and moment applied on the tip A (a positive F_A pushes
the tip back, against its free motion); y_A (m), α_A (rad): tip deflection and bending angle;
H_s: Bouc-Wen hysteresis (eq 3, :mod:`gripkit.models.hysteresis`); s_p (m/N): tip compliance;
L_a (m): actuator length. The compliance block is the cantilever's: a tip force F bends the tip
by F L³/(3EI) = s_p F and turns it by F L²/(2EI) = (3/(2L_a)) s_p F; a tip moment M by
M L²/(2EI) = (3/(2L_a)) s_p M and M L/(EI) = (3/L_a²) s_p M; a bimorph's free bending has
constant curvature, so α = 2y/L_a. The rate-dependent hysteresis is the static Bouc-Wen operator
followed by the linear dynamics D(s) (eq 2, a Hammerstein structure).

:class:`PiezoActuator` simulates it exactly per sample: H by the exact rate-independent update,
then the two D(s) filters (states y_A, ẏ_A, α_A, α̇_A) by exact zero-order-hold matrices.
"""

from __future__ import annotations

import math

import numba
import numpy as np
from numba import prange

from ..params import Parameter, ParameterSet
from ..sim.integrators import lti_rhs, lti_step, modes_of, zoh_levels
from ..lti import StateSpace
from ..sim.model import Model, Signal
from .hysteresis import bouc_wen_advance, bouc_wen_parameters

__all__ = ["PiezoActuator", "actuator_dynamics", "actuator_state_space", "actuator_parameters",
           "bw_lti_batch", "bw_lti_row", "run_bw_lti", "lti_modes"]


def actuator_dynamics(a: float, b: float) -> StateSpace:
    """D(s) = 1/(a s² + b s + 1) (eq 4) as a state space (states q, q̇; static gain 1)."""
    return StateSpace([[0.0, 1.0], [-1.0 / a, -b / a]], [[0.0], [1.0 / a]], [[1.0, 0.0]], [[0.0]],
                      inputs=("w",), outputs=("q",), input_units=("m",), output_units=("m",))


def actuator_state_space(s_p: float, a: float, b: float, L_a: float) -> StateSpace:
    """Linear part of eq 4: inputs [W = d_p U − H (m), F_A (N), M_A (N·m)], states
    [y_A, ẏ_A, α_A, α̇_A], outputs [y_A, α_A]."""
    A = np.zeros((4, 4))
    A[0, 1] = A[2, 3] = 1.0
    A[1, 0] = A[3, 2] = -1.0 / a
    A[1, 1] = A[3, 3] = -b / a
    B = np.zeros((4, 3))
    B[1] = [1.0, -s_p, -1.5 / L_a * s_p]
    B[3] = [2.0 / L_a, -1.5 / L_a * s_p, -3.0 / L_a**2 * s_p]
    B /= a
    C = np.zeros((2, 4))
    C[0, 0] = C[1, 2] = 1.0
    return StateSpace(A, B, C, np.zeros((2, 3)), inputs=("W", "F_A", "M_A"),
                      outputs=("y_A", "alpha_A"),
                      input_units=("m", "N", "N*m"), output_units=("m", "rad"))


def actuator_parameters(d_p: float, s_p: float, lam: float, beta: float, gamma: float, a: float,
                        b: float, L_a: float, *, source: str = "",
                        name: str = "piezo-actuator") -> ParameterSet:
    """ParameterSet of eq 4 (SI units)."""
    bw = bouc_wen_parameters(d_p, lam, beta, gamma, source=source)
    return ParameterSet([
        bw["d_p"],
        Parameter("s_p", s_p, "m/N", "elastic compliance at the "
                                     "actuator tip A (eq 4)", bounds=(0.0, None),
                  source=source, display_unit="um/N"),
        bw["lam"], bw["beta"], bw["gamma"],
        Parameter("a", a, "s^2", "D(s) = 1/(a s² + b s + 1): s² "
                                 "coefficient (eq 4)", bounds=(1e-16, None),
                  source=source),
        Parameter("b", b, "s", "D(s) = 1/(a s² + b s + 1): s "
                               "coefficient (eq 4)", bounds=(0.0, None),
                  source=source),
        Parameter("L_a", L_a, "m", "actuator length (eq 4)", bounds=(1e-6, None), fixed=True,
                  source=source,
                  display_unit="mm"),
    ], name)


def lti_modes(A: np.ndarray) -> list[tuple[float, float]]:
    """(ω_n rad/s, ζ) of the eigenvalues of A (one entry per complex pair or real pole)."""
    return modes_of(A)


@numba.njit(cache=True)
def bw_lti_row(bw, Phi, Gam, C, D, u, x0, y):  # pragma: no cover - compiled
    """One parameter row of :func:`bw_lti_batch` (bw (4,), Phi (n, n), … , x0 (2 + n,), y (N,
    p))."""
    N = u.shape[0]
    n = Phi.shape[0]
    m = Gam.shape[1]
    p_out = C.shape[0]
    x = np.empty(n)
    xt = np.empty(n)
    w = np.empty(m)
    yk = np.empty(p_out)
    for i in range(n):
        x[i] = x0[2 + i]
    H = x0[0]
    Uh = x0[1]
    d_p, lam, beta, gamma = bw[0], bw[1], bw[2], bw[3]
    for k in range(N):
        U = u[k, 0]
        H = bouc_wen_advance(H, U - Uh, lam, beta, gamma)
        Uh = U
        w[0] = d_p * U - H
        for j in range(1, m):
            w[j] = u[k, j]
        lti_rhs(C, D, x, w, yk)
        for i in range(p_out):
            y[k, i] = yk[i]
        lti_step(Phi, Gam, x, w, xt)


@numba.njit(cache=True, parallel=True)
def bw_lti_batch(bw, Phi, Gam, C, D, u, x0, y):  # pragma: no cover - compiled
    """Bouc-Wen then an exactly discretised LTI system, for P parameter rows in parallel.

    bw (P, 4): d_p, λ, β, γ; Phi (P, n, n), Gam (P, n, m), C (P, p, n), D (P, p, m): the LTI
    system whose inputs are [W = d_p U − H, u[:, 1], …, u[:, m−1]]; u (N, m) with the voltage
    in column 0; x0 (P, 2 + n): H, the voltage last applied, then the LTI states; y (P, N, p).
    The row body is a plain function (the body of a prange loop optimises worse, measured).
    """
    for p in prange(bw.shape[0]):
        bw_lti_row(bw[p], Phi[p], Gam[p], C[p], D[p], u, x0[p], y[p])


def run_bw_lti(bw, Phi, Gam, C, D, u, x0, y) -> None:
    """:func:`bw_lti_batch`, or its row function directly for a single row (no parallel region)."""
    if bw.shape[0] == 1:
        bw_lti_row(bw[0], Phi[0], Gam[0], C[0], D[0], u, x0[0], y[0])
    else:
        bw_lti_batch(bw, Phi, Gam, C, D, u, x0, y)


class PiezoActuator(Model):
    """The piezoelectric actuator of eq 4 (Bouc-Wen + D(s)), simulated exactly per sample.

    Inputs ``U`` (V) and, with ``loads=True``, ``F_A`` (N) and ``M_A`` (N·m); outputs ``y_A`` (m)
    and ``alpha_A`` (rad). With ``loads=False`` (free motion) the only input is U.

    The same model describes the free motion of any point of a rigid extension at distance ℓ from
    A (y = y_A + ℓ α_A = (1 + 2ℓ/L_a) D(s)[d_p U − H]): Bouc-Wen is homogeneous in (H, λ), so
    with d_p and λ multiplied by (1 + 2ℓ/L_a) output ``y_A`` is that point's displacement. This is
    how gripkit identifies the actuator from tip-B measurements (eq 14) without knowing L_r, L_a.
    """

    name = "piezo-actuator"
    description = "Bouc-Wen hysteresis followed by D(s) = 1/(a s² + b s + 1), eq 4"
    outputs = (Signal("y_A", "m", "tip deflection"), Signal("alpha_A", "rad", "tip bending angle"))
    states = (Signal("H", "m", "hysteresis"), Signal("U", "V", "voltage last applied"),
              Signal("y_A", "m", ""), Signal("v_A", "m/s", ""), Signal("alpha_A", "rad", ""),
              Signal("w_A", "rad/s", ""))
    integrator = "zoh"

    def __init__(self, parameters: ParameterSet | None = None, *, loads: bool = True,
                 check: bool = True,
                 **values):
        if parameters is None:
            defaults = dict(d_p=0.77e-6, s_p=9.1e-4, lam=0.43e-6, beta=0.108, gamma=7.5e-3,
                            a=2.5e-8,
                            b=8e-5, L_a=15e-3)
            defaults.update(values)
            parameters = actuator_parameters(**defaults)
        self.loads = bool(loads)
        self.inputs = ((Signal("U", "V", "voltage"), Signal("F_A", "N", "force on tip A"),
                        Signal("M_A", "N*m", "moment on tip A")) if self.loads
                       else (Signal("U", "V", "voltage"),))
        super().__init__(parameters, check=check)

    def _row(self, th):
        v = dict(zip(self.parameters.names, th))
        ss = actuator_state_space(v["s_p"], v["a"], v["b"], v["L_a"])
        B = ss.B if self.loads else ss.B[:, :1]
        return ss.A, B, ss.C, np.zeros((2, B.shape[1])), [v["d_p"], v["lam"], v["beta"], v["gamma"]]

    def matrices(self, thetas: np.ndarray):
        rows = [self._row(th) for th in thetas]
        A, B, C, D, bw = (np.array([r[i] for r in rows]) for i in range(5))
        return A, B, C, D, bw

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        A, B, C, D, bw = self.matrices(thetas)
        Phi, Gam = zoh_levels(A, B, dt, 0)
        run_bw_lti(bw, Phi[:, 0], Gam[:, 0], C, D, u, x0, y)

    def modes(self, theta):
        v = dict(zip(self.parameters.names, theta))
        wn = 1.0 / math.sqrt(v["a"])
        return [(wn, v["b"] * wn / 2.0)]
