"""The discrete state functions of a model, for the extended and unscented Kalman filters.

``state_functions(model, dt=None) -> (f, h, x0, nx)`` gives ``x[t+1] = f(x[t], u[t])`` and
``y[t] = h(x[t], u[t])`` (``x`` (nx,), ``u`` (m,), ``y`` (p,), in the model's units, offsets
applied) and the state ``x0`` (nx,) the model's own simulation starts from. Simulating ``f``,
``h`` from ``x0`` reproduces the model's noise-free simulation; the filters add the process
noise ``w ~ N(0, Q)`` to ``f`` and the measurement noise ``v ~ N(0, R)`` to ``h``.
``state_labels(model)`` names the nx states.

What the state is, family by family:

* **Linear model** (:class:`~gripkit.sysid.LinearModel`): its discrete realisation at ``dt``
  (the model's own by default) with the input and output offsets, as
  :class:`~gripkit.estimation.KalmanFilter` uses it; ``x0`` = 0. Python functions.
* **Grey-box model** (a :class:`gripkit.sim.Model`): a ``Model`` simulates by its numba kernel
  ``_simulate_batch`` with the integrator it names in ``Model.integrator``, and exposes no
  per-sample transition; ``f``, ``h`` are the same discretisation, one sample at a time.
  :class:`~gripkit.models.MassSpringDamper` (``integrator = 'zoh'``): the exact zero-order-hold
  step of ``m ẍ + b ẋ + k x = F`` (:func:`~gripkit.models.msd_zoh`), state ``[x, v]``, output
  ``x`` at the sample (as its simulate writes it before stepping); ``dt`` required.
  :class:`~gripkit.models.BoucWen` (``'zoh'``, rate independent): the exact step
  :func:`~gripkit.models.bouc_wen_advance`, state ``[H, U]`` (H after the previous sample and
  the voltage then applied), outputs ``[d_p U − H, H]``. Another ``Model`` subclass takes part by
  defining ``state_functions(dt) -> (f, h, x0)``; without it a :class:`ModelError` says so.
  :class:`~gripkit.models.PiezoActuator` (``'zoh'``): the Bouc-Wen step, then ``D(s)``
  discretised exactly by the same ``zoh_levels`` matrices as its simulate; state ``[H, U, y_A,
  v_A, α_A, w_A]``; ``dt`` required. A model fitted by ``gripkit.sysid.fit_greybox`` is the
  model class with the fitted parameters: ``type(model)(result.parameters)``.
* **Hammerstein–Wiener** (:class:`~gripkit.sysid.HWModel`): the states of the linear
  block ``B(q)/F(q)`` in the controllable canonical realisation (as ``scipy.signal.tf2ss``), fed
  with ``w = f_in(u)``; ``h`` applies the output nonlinearity and ``y0`` to the block's output.
  ``x0`` = 0: the block at rest (``HWModel.simulate(..., initial_input=0)``). numba.
* **Bouc-Wen** (:class:`~gripkit.sysid.BoucWenModel`): state ``[h, u_prev]`` (the
  hysteresis variable after the previous sample and the input then), ``h(x, u) = d u −
  h⁺ + offset`` with ``h⁺`` the step of the model's own kernel (exact for n = 1, RK4 in the input
  otherwise) and ``f(x, u) = [h⁺, u]``; ``x0`` = [0, 0] (virgin state at zero input); its
  simulate starts at ``[0, u(0)]``, which is ``x0=[0, u[0]]`` given to the filter. numba.
* **Bouc-Wen oscillator** (:class:`~gripkit.sysid.BoucWenOscillatorModel`): state
  ``[x, ẋ, z]``, ``f`` the model's ``substeps`` RK4 steps over its ``dt`` with the input held,
  ``h = x + offset``; ``x0`` = rest. numba.
* **NARX** (:class:`~gripkit.sysid.NARXModel`): state ``[s(t−1) … s(t−ly), u(t−1) …
  u(t−lu)]``, the window of past noise-free outputs ``s`` (and of past inputs, which the
  polynomial needs); ``h(x, u) = s(t) = Σ θ_k m_k`` evaluated on that window and ``u(t)``,
  ``f`` shifts ``s(t)`` and ``u(t)`` in. This is the *output-error* reading of the NARX model:
  the measured output is ``y = s + v`` (noise enters through the measurement, R), and the
  equation error of the fit enters as process noise on ``s(t−1)`` (Q[0, 0]); the model's own
  one-step predictor instead feeds the noisy measured outputs back. ``x0`` = 0. numba.
* **Nonlinear state space** (:class:`~gripkit.sysid.NLSSModel`): its own states (the
  model's basis, scaled to unit standard deviation on the estimation record), ``f(x, u) = A x +
  B ũ + E ζ(x, ũ)`` and ``h(x, u) = y₀ + C x + D ũ + F η(x, ũ)`` with the model's normalised
  input ``ũ = (u − u_offset)/u_scale`` (u in the model's units, as its ``simulate`` takes it),
  by the monomial kernels of its own free run. ``x0`` = 0, the equilibrium of the mean input
  (``NLSSModel.simulate``'s default start). ``f`` does not stop at the model's state limit (the
  free run's divergence check). numba.
* **Prandtl–Ishlinskii** (:class:`~gripkit.sysid.PrandtlIshlinskiiModel`): state the
  m play outputs ``z_i = F_{r_i}[u − a]`` after the previous sample; ``f`` applies each play to
  the new input, ``z_i⁺ = min(u − a + r_i, max(u − a − r_i, z_i))``, and ``h = c + Σ w_i z_i⁺``.
  ``x0`` = 0: every play relaxed at the input offset ``a``; its simulate relaxes them at the
  first input, which is ``x0 = u[0] − a`` (every entry) given to the filter. numba.
  *The noise model this implies*: Q on the plays (``z⁺ = play(z, u) + w``) is a random walk of
  each play's memory *while the input stays inside its band* ``|u − a − z_i| < r_i`` (the play
  holds its output, so the noise accumulates: a drifting loop interior, as creep or unmodelled
  minor loops give); once the input drives a play (reaches the band's edge) the play is reset
  to ``u − a ∓ r_i`` and keeps only the last step's noise: the accumulated error is forgotten.
  The ``r_0 = 0`` play is always driven (``z_0⁺ = u − a``), its state is the input and its
  noise never reaches the output (give it a small Q); the output's model error is ``Σ w_i`` of
  the held plays' walks. The play is not differentiable at the band's edge: the extended
  filter's Jacobian is 1 (held), 0 (driven, its variance falls back to Q), and between them
  within the difference step of the edge; near reversals it is more confident than its error
  (average NEES 3.3 for 3 plays in the tests, 3.1 for the unscented filter).

The past-input components (Bouc-Wen ``u_prev``, NARX ``u(t−k)``) and the PI play of threshold 0
are known exactly: give them a small positive process noise (for example 1e-12 of the input's
variance) so that the unscented filter's covariance stays positive definite.
"""

from __future__ import annotations

import contextlib
import dataclasses
import weakref
from typing import NamedTuple

import numba
import numpy as np

from ..errors import ModelError

__all__ = ["StateFunctions", "state_functions", "state_labels"]


class StateFunctions(NamedTuple):
    """``f(x, u) -> (nx,)``, ``h(x, u) -> (p,)``, the initial state ``x0`` (nx,) and ``nx``."""

    f: object
    h: object
    x0: np.ndarray
    nx: int


_FAMILIES = ("a gripkit.sysid.LinearModel, a grey-box gripkit Model (MassSpringDamper, "
             "BoucWen, PiezoActuator, or one defining state_functions(dt)), HWModel, BoucWenModel, "
             "BoucWenOscillatorModel, NARXModel, NLSSModel or PrandtlIshlinskiiModel")


def state_functions(model, dt: float | None = None) -> StateFunctions:
    """The discrete state functions of ``model`` (module docstring); ``dt`` the sample time
    (needed for a continuous linear model and a grey-box Model; a rate-dependent identified
    model uses its own). Raises :class:`ModelError` naming what the model lacks.

    The same model with the same values and ``dt`` gives the same ``f``, ``h`` objects (a cache
    keyed on the model's identity and its values), so that filters made again on one model reuse
    the numba kernels compiled for the first."""
    f, h, x0, nx, _ = _build(model, dt)
    return StateFunctions(f, h, x0.copy(), nx)


def state_labels(model, dt: float | None = None) -> list[str]:
    """The names of the nx states of ``model`` in :func:`state_functions`'s order."""
    return list(_build(model, dt)[4])


#: id(model) -> (weak reference, (dt, values), built functions)
_CACHE: dict = {}


def _values(model):
    """The numbers that fix a model's state functions (for the cache): a grey-box Model's
    parameter vector, an identified model's fields."""
    if hasattr(model, "theta") and callable(model.theta):  # a gripkit Model: θ and its options
        return type(model), model.theta().tobytes(), tuple(sorted(
            (k, repr(v)) for k, v in vars(model).items() if k != "parameters"))
    if dataclasses.is_dataclass(model):
        return type(model), tuple(
            np.asarray(v).tobytes() if isinstance(v, (np.ndarray, float, int)) else repr(v)
            for v in (getattr(model, fl.name) for fl in dataclasses.fields(model)))
    return None


def _build(model, dt):
    key = (dt, _values(model))
    hit = _CACHE.get(id(model))
    if key[1] is not None and hit is not None and hit[0]() is model and hit[1] == key:
        return hit[2]
    built = _build_new(model, dt)
    if key[1] is not None:
        with contextlib.suppress(TypeError):  # no weak references to this kind: not cached
            ref = weakref.ref(model, lambda _, k=id(model): _CACHE.pop(k, None))
            _CACHE[id(model)] = (ref, key, built)
    return built


def _build_new(model, dt):
    from ..sim.model import Model
    from ..sysid.nonlinear.hammerstein_wiener import HWModel
    from ..sysid.nonlinear.hysteresis import (BoucWenModel, BoucWenOscillatorModel,
                                              PrandtlIshlinskiiModel)
    from ..sysid.nonlinear.narx import NARXModel
    from ..sysid.nonlinear.nlss import NLSSModel

    if isinstance(model, Model):
        return _greybox(model, dt)
    if isinstance(model, HWModel):
        return _hw(model)
    if isinstance(model, BoucWenOscillatorModel):
        return _bwo(model, dt)
    if isinstance(model, BoucWenModel):
        return _bw(model)
    if isinstance(model, NARXModel):
        return _narx(model)
    if isinstance(model, NLSSModel):
        return _nlss(model)
    if isinstance(model, PrandtlIshlinskiiModel):
        return _pi(model)
    if hasattr(model, "to_ss") and hasattr(model, "u_offset"):
        return _linear(model, dt)
    raise ModelError(f"state_functions: {type(model).__name__} has no state-space form gripkit "
                     f"knows; expected {_FAMILIES}")


def _need_dt(dt, what):
    if dt is None:
        raise ModelError(f"state_functions: {what} is continuous and has no sample time; give "
                         "dt= (seconds)")
    if (isinstance(dt, bool) or not isinstance(dt, (int, float, np.integer, np.floating))
            or not (np.isfinite(dt) and dt > 0)):
        raise ModelError(f"state_functions: dt must be a positive number of seconds, found "
                         f"{dt!r}")
    return float(dt)


# ------------------------------------------------------------------------------ linear


def _linear_model_fh(model, dt):
    """``f``, ``h`` (Python, numpy) of a LinearModel's discrete realisation with its offsets
    applied (u, y in SI, offsets not removed)."""
    if not hasattr(model, "to_ss"):
        raise ModelError(f"expected a gripkit.sysid.LinearModel or a callable f, found "
                            f"{type(model).__name__}")
    if not (model.dt or dt):
        raise ModelError("the model is continuous; give the sample time: dt=…")
    ss = model.to_ss(model.dt if dt is None else dt)
    A, B, C, D = (np.asarray(M, dtype=np.float64) for M in (ss.A, ss.B, ss.C, ss.D))
    u0 = np.asarray(model.u_offset, dtype=np.float64)
    y0 = np.asarray(model.y_offset, dtype=np.float64)

    def f(x, u):
        return A @ x + B @ (u - u0)

    def h(x, u):
        return C @ x + D @ (u - u0) + y0

    return f, h



def _linear(model, dt):
    f, h = _linear_model_fh(model, dt)
    n = int(np.asarray(model.to_ss(model.dt if dt is None else dt).A).shape[0])
    return f, h, np.zeros(n), n, [f"x{i + 1}" for i in range(n)]


# ------------------------------------------------------------------------------ grey box


def _greybox(model, dt):
    from ..models.hysteresis import BoucWen, bouc_wen_advance
    from ..models.mass_spring_damper import MassSpringDamper, msd_zoh
    from ..models.piezo import PiezoActuator

    own = getattr(model, "state_functions", None)
    theta = model.theta()
    labels = [s.name for s in model.states]
    if callable(own):
        f, h, x0 = own(dt)
        x0 = np.asarray(x0, dtype=np.float64).ravel()
        return f, h, x0, x0.size, labels
    if isinstance(model, MassSpringDamper):
        mat = np.empty(6)
        msd_zoh(theta[0], theta[1], theta[2], _need_dt(dt, model.name), mat)
        a11, a12, a21, a22, b1, b2 = (float(v) for v in mat)

        @numba.njit
        def f(x, u):  # pragma: no cover - compiled
            out = np.empty(2)
            out[0] = a11 * x[0] + a12 * x[1] + b1 * u[0]
            out[1] = a21 * x[0] + a22 * x[1] + b2 * u[0]
            return out

        @numba.njit
        def h(x, u):  # pragma: no cover - compiled
            out = np.empty(1)
            out[0] = x[0]
            return out

        return f, h, model.initial_state(theta).astype(np.float64), 2, labels
    if isinstance(model, BoucWen):
        d_p, lam, beta, gamma = (float(v) for v in theta[:4])

        @numba.njit
        def f(x, u):  # pragma: no cover - compiled
            out = np.empty(2)
            out[0] = bouc_wen_advance(x[0], u[0] - x[1], lam, beta, gamma)
            out[1] = u[0]
            return out

        @numba.njit
        def h(x, u):  # pragma: no cover - compiled
            out = np.empty(2)
            H = bouc_wen_advance(x[0], u[0] - x[1], lam, beta, gamma)
            out[0] = d_p * u[0] - H
            out[1] = H
            return out

        return f, h, model.initial_state(theta).astype(np.float64), 2, labels
    if isinstance(model, PiezoActuator):
        return _piezo(model, theta, _need_dt(dt, model.name), labels)
    raise ModelError(f"state_functions: the grey-box model {model.name!r} "
                     f"({type(model).__name__}) has no per-sample state transition (it only "
                     "simulates in batch); define state_functions(dt) -> (f, h, x0) on it")


def _piezo(model, theta, dt, labels):
    """PiezoActuator: Bouc-Wen, then D(s) discretised exactly (its own ``zoh_levels`` step)."""
    from ..models.hysteresis import bouc_wen_advance
    from ..sim.integrators import zoh_levels

    A, B, C, D, bw = model.matrices(theta[None, :])
    Phi, Gam = zoh_levels(A, B, dt, 0)
    Phi, Gam = np.ascontiguousarray(Phi[0, 0]), np.ascontiguousarray(Gam[0, 0])
    C, D = np.ascontiguousarray(C[0]), np.ascontiguousarray(D[0])
    d_p, lam, beta, gamma = (float(v) for v in bw[0])
    n, m, p = Phi.shape[0], Gam.shape[1], C.shape[0]

    @numba.njit
    def drive(x, u):  # pragma: no cover - compiled
        """(H⁺, w): the hysteresis after this sample and the LTI input [d_p U − H⁺, loads]."""
        H = bouc_wen_advance(x[0], u[0] - x[1], lam, beta, gamma)
        w = np.empty(m)
        w[0] = d_p * u[0] - H
        for j in range(1, m):
            w[j] = u[j]
        return H, w

    @numba.njit
    def linear_row(M, N, x, w, i):  # pragma: no cover - compiled
        """Row i of ``M x[2:] + N w`` (the linear part's state after the hysteresis states)."""
        acc = 0.0
        for j in range(n):
            acc += M[i, j] * x[2 + j]
        for j in range(m):
            acc += N[i, j] * w[j]
        return acc

    @numba.njit
    def f(x, u):  # pragma: no cover - compiled
        H, w = drive(x, u)
        out = np.empty(2 + n)
        out[0] = H
        out[1] = u[0]
        for i in range(n):
            out[2 + i] = linear_row(Phi, Gam, x, w, i)
        return out

    @numba.njit
    def h(x, u):  # pragma: no cover - compiled
        _, w = drive(x, u)
        out = np.empty(p)
        for i in range(p):
            out[i] = linear_row(C, D, x, w, i)
        return out

    return f, h, model.initial_state(theta).astype(np.float64), 2 + n, labels


# ------------------------------------------------------------------------------ identified


def _hw(model):
    from ..sysid.nonlinear.hw_kernels import nl_eval

    num, den = np.asarray(model.B, dtype=np.float64), np.asarray(model.F, dtype=np.float64)
    L = max(len(num), len(den))
    if L < 2:
        raise ModelError(f"state_functions: the Hammerstein-Wiener model's linear block "
                         f"(nb={model.nb}, nf={model.nf}, nk={model.nk}) is static and has no "
                         "state to filter")
    # controllable canonical form of (n0 z^n + … + n_n)/(z^n + a1 z^(n−1) + … + a_n), n = L − 1
    # (scipy.signal.tf2ss's convention): A's first row −a, ones below the diagonal, B = e1,
    # C_j = n_j − n0 a_j, D = n0
    nz, a = np.r_[num, np.zeros(L - len(num))], np.r_[den, np.zeros(L - len(den))]
    n = L - 1
    A = np.zeros((n, n))
    A[0] = -a[1:]
    A[np.arange(1, n), np.arange(n - 1)] = 1.0
    Bv = np.zeros(n)
    Bv[0] = 1.0
    Cv = np.ascontiguousarray(nz[1:] - nz[0] * a[1:])
    d = float(nz[0])
    kin, kout = model.input_nl.code, model.output_nl.code
    pin = np.ascontiguousarray(model._part("in"), dtype=np.float64)
    pout = np.ascontiguousarray(model._part("out"), dtype=np.float64)
    cin = np.asarray(model.input_nl.consts or (0.0,), dtype=np.float64)
    cout = np.asarray(model.output_nl.consts or (0.0,), dtype=np.float64)
    y0 = float(model.theta[-1])
    gi, go = max(pin.size, 2), max(pout.size, 2)

    @numba.njit
    def f(x, u):  # pragma: no cover - compiled
        w, _ = nl_eval(kin, pin, cin, u[0], np.empty(gi))
        out = np.empty(n)
        for i in range(n):
            acc = Bv[i] * w
            for j in range(n):
                acc += A[i, j] * x[j]
            out[i] = acc
        return out

    @numba.njit
    def h(x, u):  # pragma: no cover - compiled
        w, _ = nl_eval(kin, pin, cin, u[0], np.empty(gi))
        v = d * w
        for j in range(n):
            v += Cv[j] * x[j]
        g, _ = nl_eval(kout, pout, cout, v, np.empty(go))
        out = np.empty(1)
        out[0] = g + y0
        return out

    return f, h, np.zeros(n), n, [f"x{i + 1}" for i in range(n)]


def _bw(model):
    from ..models.hysteresis import bouc_wen_advance
    from ..sysid.nonlinear.hysteresis_kernels import bw_advance_rk4

    d, lam, beta, gamma = float(model.d), float(model.lam), float(model.beta), float(model.gamma)
    nexp, offset, exact = float(model.n), float(model.offset), float(model.n) == 1.0

    @numba.njit
    def advance(x, u):  # pragma: no cover - compiled
        if exact:
            return bouc_wen_advance(x[0], u[0] - x[1], lam, beta, gamma)
        return bw_advance_rk4(x[0], u[0] - x[1], lam, beta, gamma, nexp)

    @numba.njit
    def f(x, u):  # pragma: no cover - compiled
        out = np.empty(2)
        out[0] = advance(x, u)
        out[1] = u[0]
        return out

    @numba.njit
    def h(x, u):  # pragma: no cover - compiled
        out = np.empty(1)
        out[0] = d * u[0] - advance(x, u) + offset
        return out

    return f, h, np.zeros(2), 2, ["h", "u_prev"]


def _bwo(model, dt):
    from ..sysid.nonlinear.hysteresis_kernels import bwo_sample

    if dt is not None and not np.isclose(dt, model.dt, rtol=1e-6):
        raise ModelError(f"state_functions: the Bouc-Wen oscillator is sampled every "
                         f"{model.dt:g} s, found dt={dt!r}; a rate-dependent model keeps its own "
                         "sample time (leave dt out)")
    m, c, ke, kh = float(model.mass), float(model.damping), float(model.k_e), float(model.k_h)
    beta, gamma, nexp, offset = (float(model.beta), float(model.gamma), float(model.n),
                                 float(model.offset))
    sub = int(model.substeps)
    hs = float(model.dt) / sub

    @numba.njit
    def f(s, u):  # pragma: no cover - compiled
        x, v, z = bwo_sample(s[0], s[1], s[2], u[0], hs, sub, (m, c, ke, kh, beta, gamma, nexp))
        out = np.empty(3)
        out[0] = x
        out[1] = v
        out[2] = z
        return out

    @numba.njit
    def h(s, u):  # pragma: no cover - compiled
        out = np.empty(1)
        out[0] = s[0] + offset
        return out

    return f, h, np.zeros(3), 3, ["x", "v", "z"]


def _narx(model):
    from ..sysid.nonlinear.narx import narx_output

    ly, lu = int(model.ylags), int(model.ulags)
    if ly < 1:
        raise ModelError(f"state_functions: the NARX model has no output lags (ylags={ly}), so "
                         "no state to filter; use its one-step prediction instead")
    kinds = np.ascontiguousarray(model.bases[:, 0], dtype=np.int64)
    lags = np.ascontiguousarray(model.bases[:, 1], dtype=np.int64)
    rows = np.ascontiguousarray(model.rows, dtype=np.int64)
    theta = np.ascontiguousarray(model.theta, dtype=np.float64)
    n = ly + lu
    # each base's place in the state: y(t−lag) at lag−1, u(t−lag) at ly+lag−1, u(t) past the end
    at = np.where(kinds == 0, lags - 1, np.where(lags == 0, n, ly + lags - 1))
    rows = np.where(rows < 0, -1, at[rows])
    if getattr(model, "basis", "polynomial") == "rational":  # y = N/D, D = 1 + Σ d_j q_j
        from ..sysid.nonlinear.narx_rational import rational_output

        den_rows = np.ascontiguousarray(model.den_rows, dtype=np.int64)
        den_rows = np.where(den_rows < 0, -1, at[den_rows])

        @numba.njit
        def output(x, u):  # pragma: no cover - compiled
            num, den = rational_output(rows, den_rows, theta, x, u[0])
            return num / den
    else:
        @numba.njit
        def output(x, u):  # pragma: no cover - compiled
            return narx_output(rows, theta, x, u[0])

    @numba.njit
    def f(x, u):  # pragma: no cover - compiled
        out = np.empty(n)
        out[0] = output(x, u)
        for i in range(1, ly):
            out[i] = x[i - 1]
        if lu > 0:
            out[ly] = u[0]
            for i in range(1, lu):
                out[ly + i] = x[ly + i - 1]
        return out

    @numba.njit
    def h(x, u):  # pragma: no cover - compiled
        out = np.empty(1)
        out[0] = output(x, u)
        return out

    labels = [f"s(t-{k})" for k in range(1, ly + 1)] + [f"u(t-{k})" for k in range(1, lu + 1)]
    return f, h, np.zeros(n), n, labels


def _nlss(model):
    from ..sysid.nonlinear.nlss_kernels import monomials as nlss_monomials
    from ..sysid.nonlinear.nlss_kernels import output_row, state_update

    f64 = lambda M: np.ascontiguousarray(M, dtype=np.float64)  # noqa: E731
    A, B, C, D, E, F = (f64(M) for M in (model.A, model.B, model.C, model.D, model.E, model.F))
    y0, u0, su = f64(model.y_offset), f64(model.u_offset), f64(model.u_scale)
    exz = np.ascontiguousarray(model.exz, dtype=np.int64)
    exe = np.ascontiguousarray(model.exe, dtype=np.int64)
    n, m, p = A.shape[0], B.shape[1], C.shape[0]
    if n < 1:
        raise ModelError("state_functions: the NLSS model has order 0, so no state to filter")

    @numba.njit
    def monomials(ex, x, u):  # pragma: no cover - compiled
        """ũ as the one row (1, m) the model's kernels index by sample, and the monomials of
        the exponent rows ``ex`` at (x, ũ)."""
        ut = np.empty((1, m))
        for j in range(m):
            ut[0, j] = (u[j] - u0[j]) / su[j]
        values = np.empty(ex.shape[0])
        nlss_monomials(ex, x, ut, 0, values)
        return ut, values

    @numba.njit
    def f(x, u):  # pragma: no cover - compiled
        ut, zeta = monomials(exz, x, u)
        out = np.empty(n)
        state_update(A, B, E, x, ut, 0, zeta, out)
        return out

    @numba.njit
    def h(x, u):  # pragma: no cover - compiled
        ut, eta = monomials(exe, x, u)
        out = np.empty(p)
        for i in range(p):
            out[i] = output_row(C, D, F, y0, x, ut, 0, eta, i)
        return out

    return f, h, np.zeros(n), n, [f"x{i + 1}" for i in range(n)]


def _pi(model):
    r = np.ascontiguousarray(model.thresholds, dtype=np.float64)
    w = np.ascontiguousarray(model.weights, dtype=np.float64)
    a, c, n = float(model.input_offset), float(model.offset), r.shape[0]
    if n < 1 or w.shape != (n,):
        raise ModelError(f"state_functions: the Prandtl-Ishlinskii model needs one weight per "
                         f"play operator, found {n} thresholds and {w.shape[0]} weights")

    @numba.njit
    def f(x, u):  # pragma: no cover - compiled
        out = np.empty(n)
        v = u[0] - a
        for i in range(n):  # the play of pi_simulate: z = min(v + r, max(v − r, z))
            z = x[i]
            if z < v - r[i]:
                z = v - r[i]
            elif z > v + r[i]:
                z = v + r[i]
            out[i] = z
        return out

    @numba.njit
    def h(x, u):  # pragma: no cover - compiled
        z = f(x, u)
        acc = c
        for i in range(n):
            acc += w[i] * z[i]
        out = np.empty(1)
        out[0] = acc
        return out

    return f, h, np.zeros(n), n, [f"play_{i}" for i in range(n)]
