"""One linear-system hierarchy: :class:`LinearSystem` with its two views, :class:`StateSpace`
and :class:`TransferFunction`, continuous (``dt=None``) or discrete (``dt > 0`` s), MIMO, with
signal names and units and an optional parameter covariance.

Continuous:  ẋ = A x + B u,  y = C x + D u,        G(s) = C (sI − A)⁻¹ B + D.
Discrete:    x[k+1] = A x[k] + B u[k],  y[k] = C x[k] + D u[k],   G(z) = C (zI − A)⁻¹ B + D.

Frequencies are angular (rad/s) everywhere; a discrete system is evaluated at z = e^{jω dt}.
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import AccuracyWarning, DataError, ModelError, emit_warning
from . import _connect, _discretize, _realize
from ._checks import as_dt, as_input_array, as_matrix, as_names, as_units, require_discrete, same_dt
from ._frequency import Bode, default_grid
from ._pycontrol import control_module
from ._uncertainty import Uncertainty, complex_covariance, push

__all__ = (["Damping", "LinearSystem", "StateSpace", "TransferFunction", "c2d", "d2c", "series",
            "parallel", "feedback"])

_EPS = np.finfo(float).eps


def _fmt_dt(dt):
    return "continuous" if dt is None else f"dt={dt:g} s"


def _initial_state(x0, n: int) -> np.ndarray:
    """``x0`` as a fresh float64 vector of ``n`` finite states (zeros when None)."""
    if x0 is None:
        return np.zeros(n)
    x = np.array(x0, dtype=np.float64).reshape(-1)
    if x.shape != (n,):
        raise DataError(f"x0: expected {n} initial states, found shape {np.shape(x0)}")
    if not np.isfinite(x).all():
        raise DataError("x0 has non-finite values")
    return x


def _simulate_arrays(A, B, C, D, u, x0):
    n = A.shape[0]
    x = _initial_state(x0, n)
    from ._kernels import simulate_ss  # numba, imported on first simulation

    y = np.empty((u.shape[0], C.shape[0]))
    simulate_ss(np.ascontiguousarray(A), np.ascontiguousarray(B), np.ascontiguousarray(C),
                np.ascontiguousarray(D), u, x, np.empty(n), y)
    return y


def _polyval(c, s):
    """Σ_k c[..., k] s^(L−1−k) (descending powers) at each s by Horner's rule, shape
    (len(s),) + c.shape[:-1]."""
    sb = s.reshape((s.size,) + (1,) * (c.ndim - 1))
    out = np.zeros((s.size,) + c.shape[:-1], dtype=np.result_type(s, c))
    for k in range(c.shape[-1]):
        out *= sb
        out += c[..., k]
    return out


def _vector_as(x, shape):
    """A 1-D sequence reshaped (a column of B, a row of C); anything else unchanged."""
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        return x
    return a.reshape(shape) if a.ndim == 1 else x


def _ss_frequency(A, B, C, D, s):
    """G(s_k) = C (s_k I − A)⁻¹ B + D, and X = (sI − A)⁻¹ B, Y = C (sI − A)⁻¹, for each s_k."""
    n = A.shape[0]
    if n == 0:
        H = np.broadcast_to(D, (s.size,) + D.shape).astype(complex)
        return H, np.zeros((s.size, 0, D.shape[1])), np.zeros((s.size, D.shape[0], 0))
    M = s[:, None, None] * np.eye(n) - A
    sv = np.linalg.svd(M, compute_uv=False)
    bad = sv[:, -1] <= n * _EPS * np.maximum(sv[:, 0], 1.0)
    if np.any(bad):
        raise ModelError(f"frequency response: s = {s[bad][0]:.6g} is a pole of the system (sI "
                         "− A is singular)",
                         hint="evaluate away from the poles on the imaginary axis (or "
                              "the unit circle)")
    X = np.linalg.solve(M, np.broadcast_to(B.astype(complex), (s.size,) + B.shape))
    Ct = np.broadcast_to(C.T.astype(complex), (s.size,) + C.T.shape)
    Y = np.swapaxes(np.linalg.solve(np.swapaxes(M, 1, 2), Ct), 1, 2)
    return C @ X + D, X, Y


@dataclass(frozen=True, eq=False)
class Damping:
    """Poles with their natural frequencies ``wn`` (rad/s) and damping ratios ``zeta``, and the
    one-sigma ``wn_std``/``zeta_std`` (None without covariance). See :meth:`LinearSystem.damping`.

    Examples
    --------
    >>> from gripkit.lti import StateSpace
    >>> float(StateSpace([[-3.0]], [[1.0]], [[1.0]]).damping().zeta[0])
    1.0
    """

    poles: np.ndarray
    wn: np.ndarray
    zeta: np.ndarray
    wn_std: np.ndarray | None = None
    zeta_std: np.ndarray | None = None

    @property
    def f_hz(self) -> np.ndarray:
        """Natural frequencies in Hz, ω_n/2π."""
        return self.wn / (2 * np.pi)


class LinearSystem:
    """A linear time-invariant system (the common interface of :class:`StateSpace` and
    :class:`TransferFunction`).

    Every system has ``dt`` (None: continuous; > 0: sample time in s), ``inputs``/``outputs``
    (names), ``input_units``/``output_units`` (SI strings, ``''`` when not declared), ``meta``
    (free-form provenance) and ``uncertainty`` (an :class:`Uncertainty` or None).

    Examples
    --------
    >>> from gripkit.lti import LinearSystem, StateSpace, TransferFunction
    >>> all(isinstance(g, LinearSystem) for g in (StateSpace([[-1.0]], [[1.0]], [[1.0]]),
    ...                                           TransferFunction([1.0], [1.0, 1.0])))
    True
    """

    # ------------------------------------------------------------------ shape and time base
    @property
    def n_inputs(self) -> int:
        return len(self.inputs)

    @property
    def n_outputs(self) -> int:
        return len(self.outputs)

    @property
    def is_discrete(self) -> bool:
        return self.dt is not None

    @property
    def is_siso(self) -> bool:
        return self.n_inputs == 1 and self.n_outputs == 1

    def replace(self, **changes):
        """A copy with some fields changed (validated again).

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([1.0], [1.0, 1.0]).replace(inputs="V").inputs
        ('V',)
        """
        return dataclasses.replace(self, **changes)

    def _signals(self, **over) -> dict:
        d = dict(dt=self.dt, inputs=self.inputs, outputs=self.outputs, input_units=self.input_units,
                 output_units=self.output_units, meta=dict(self.meta))
        d.update(over)
        return d

    def _s(self, w) -> np.ndarray:
        w = np.atleast_1d(np.asarray(w, dtype=np.float64)).ravel()
        if not np.isfinite(w).all():
            raise DataError("w: frequencies must be finite (rad/s)")
        return np.exp(1j * w * self.dt) if self.is_discrete else 1j * w

    # ------------------------------------------------------------------ analysis
    @property
    def stable(self) -> bool:
        """Asymptotic stability: every pole with Re p < 0 (continuous) or |p| < 1 (discrete).

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([1.0], [1.0, -0.5], dt=0.1).stable
        True
        """
        p = self.poles()
        return bool(np.all(np.abs(p) < 1.0)) if self.is_discrete else bool(np.all(p.real < 0.0))

    @property
    def minimum_phase(self) -> bool:
        """Every (transmission) zero with Re z < 0 (continuous) or |z| < 1 (discrete).

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> g = TransferFunction.from_polynomials([1, -1.8732, 0.8996], [0, 0, 0.1950, -0.2276],
        ...                                       dt=0.005)
        >>> g.minimum_phase     # zero at z = 1.167 (000_8f66dcc7ab06470c.txt §V-F)
        False
        """
        z = self.zeros()
        return bool(np.all(np.abs(z) < 1.0)) if self.is_discrete else bool(np.all(z.real < 0.0))

    def damping(self) -> Damping:
        """Natural frequency ω_n (rad/s) and damping ratio ζ of each pole, with their one-sigma
        when the system carries a covariance.

        Continuous pole s: ``ω_n = |s|``, ``ζ = −Re s / |s|``. Discrete pole z: the same of
        ``s = ln(z)/dt`` (the continuous pole that ZOH maps to z). σ by linearisation of the pole
        covariance: ∂ω_n/∂(x, y) = (x, y)/ω_n and ∂ζ/∂(x, y) = (−y², x y)/ω_n³ for s = x + j y,
        and ds/dz = 1/(z dt).

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> d = TransferFunction([100.0], [1.0, 4.0, 100.0]).damping()
        >>> d.wn.round(9).tolist(), d.zeta.round(9).tolist()
        ([10.0, 10.0], [0.2, 0.2])
        """
        if self.uncertainty is not None:
            p, cov = self.pole_covariance()
        else:
            p, cov = self.poles(), None
        if self.is_discrete:
            # a pole at z = 0 (a delay) is s = ln 0 = −∞: ω_n = ∞, ζ = 1 (as MATLAB's damp)
            at0 = p == 0
            pz = np.where(at0, 1.0, p).astype(complex)
            s = np.where(at0, -np.inf, np.log(pz) / self.dt)
            c = np.where(at0, 0.0, 1.0 / (pz * self.dt))
        else:
            s, c = p.astype(complex), np.ones(p.size, dtype=complex)
        wn = np.abs(s)
        with np.errstate(invalid="ignore"):
            zeta = (np.where(np.isinf(wn), 1.0,
                             np.where(wn > 0, -s.real / np.where(wn > 0, wn, 1.0), -1.0)))
        if cov is None:
            return Damping(p, wn, zeta, None, None)
        # ∂(Re s, Im s)/∂(Re p, Im p): multiplication by the complex number c = ds/dp
        Jz = np.stack([np.stack([c.real, -c.imag], -1), np.stack([c.imag, c.real], -1)], -2)
        cs = Jz @ cov @ np.swapaxes(Jz, -1, -2)
        x, y = np.where(np.isinf(wn), 0.0, s.real), np.where(np.isinf(wn), 0.0, s.imag)
        w = np.where((wn > 0) & np.isfinite(wn), wn, np.inf)
        gw = np.stack([x / w, y / w], -1)
        gz = np.stack([-y ** 2 / w ** 3, x * y / w ** 3], -1)
        var = lambda g: np.einsum("ka,kab,kb->k", g, cs, g)  # noqa: E731
        return (Damping(p, wn, zeta, np.sqrt(np.clip(var(gw), 0, None)),
                        np.sqrt(np.clip(var(gz), 0, None))))

    def pole_covariance(self) -> tuple[np.ndarray, np.ndarray]:
        """Poles and the covariance of (Re p, Im p) of each, shape (n, 2, 2), to first order:
        for a simple eigenvalue λ with right and left eigenvectors v, w,
        ``∂λ/∂θ_i = wᴴ (∂A/∂θ_i) v / (wᴴ v)``.

        Examples
        --------
        >>> from gripkit.lti import StateSpace
        >>> s = StateSpace([[-2.0]], [[1.0]], [[1.0]]).with_covariance([[0.01]], ["A[0,0]"])
        >>> p, cov = s.pole_covariance()
        >>> float(p[0].real), float(cov[0, 0, 0])
        (-2.0, 0.01)
        """
        ss = self.to_ss(minimal=False)
        if ss.uncertainty is None:
            raise ModelError("pole_covariance: the system carries no covariance",
                             hint="build it with with_covariance(...) or from an identified model")
        from scipy import linalg  # on first use: scipy.linalg is ~0.2 s of a CLI start-up

        A = ss.A
        lam, vl, vr = linalg.eig(A, left=True, right=True)
        dA = ss.uncertainty.tangents[0]
        den = np.einsum("ij,ij->j", vl.conj(), vr)
        J = np.einsum("ij,kil,lj->kj", vl.conj(), dA, vr) / den
        cond = np.linalg.norm(vl, axis=0) * np.linalg.norm(vr, axis=0) / np.abs(den)
        bad = cond > 1.0 / np.sqrt(_EPS)
        cov = complex_covariance(J, ss.uncertainty.covariance)
        if np.any(bad):
            emit_warning(f"pole_covariance: {int(bad.sum())} pole(s) are (nearly) repeated; their "
                         "first-order σ is undefined and set to inf", AccuracyWarning)
            cov[bad] = np.inf
        return lam, cov

    def frequency_response(self, w) -> np.ndarray:
        """G at angular frequencies ``w`` (rad/s), shape (len(w), p, m), at s = jω, or
        z = e^{jω dt} when discrete: ``C (sI − A)⁻¹ B + D`` for a :class:`StateSpace`,
        num(s)/den(s) for a :class:`TransferFunction` (ModelError when s is a pole).

        Parameters
        ----------
        w
            Angular frequencies (rad/s), shape (N,).

        Returns
        -------
        ndarray of complex, shape (N, p, m)

        Examples
        --------
        >>> from gripkit.lti import StateSpace, TransferFunction
        >>> StateSpace([[-1.0]], [[1.0]], [[1.0]]).frequency_response([1.0])[0, 0, 0]
        np.complex128(0.5-0.5j)
        >>> TransferFunction([1.0], [1.0, 1.0]).frequency_response([1.0])[0, 0, 0]
        np.complex128(0.5-0.5j)
        """
        return self._response(self._s(w))

    def frequency_response_covariance(self, w) -> np.ndarray:
        """Covariance of (Re G, Im G) at each ω (rad/s), shape (len(w), p, m, 2, 2), to first
        order in the parameters (see :class:`Uncertainty`).

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> g = TransferFunction([2.0], [1.0, 1.0]).with_covariance([[0.04]], ["num[1]"])
        >>> float(g.frequency_response_covariance([0.0])[0, 0, 0, 0, 0])  # σ(DC gain)² = 0.2²
        0.04
        """
        if self.uncertainty is None:
            raise ModelError("frequency_response_covariance: the system carries no covariance",
                             hint="build it with with_covariance(...) or from an identified model")
        return complex_covariance(self._frequency_jacobian(self._s(w)), self.uncertainty.covariance)

    def bode(self, w=None, n: int = 512) -> Bode:
        """Bode data at ``w`` (rad/s); by default ``n`` points (discrete: 0 … Nyquist, excluded;
        continuous: two decades beyond the poles and zeros). Carries σ when the system does.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> b = TransferFunction([10.0], [1.0, 10.0]).bode([0.0, 10.0])
        >>> [round(float(x), 2) for x in b.magnitude_db[:, 0, 0]]
        [0.0, -3.01]
        """
        if w is None:
            w = (default_grid(self.dt, self.poles(), self.zeros() if self.is_siso else np.zeros(0),
                              int(n)))
        w = np.atleast_1d(np.asarray(w, dtype=np.float64))
        H = self.frequency_response(w)
        cov = None if self.uncertainty is None else self.frequency_response_covariance(w)
        return Bode(w, H, cov)

    # ------------------------------------------------------------------ time responses
    def simulate(self, u, x0=None) -> np.ndarray:
        """Outputs y (N, p) of a discrete system for inputs ``u`` (N, m) (or (N,) with one
        input) from state ``x0`` (default rest). A :class:`StateSpace` runs the recursion
        x[k+1] = A x[k] + B u[k], y[k] = C x[k] + D u[k] (a numba kernel,
        :func:`gripkit.lti.simulate_ss`); a :class:`TransferFunction` runs its observable
        canonical realisation (:meth:`TransferFunction.to_ss` with ``minimal=False``), a SISO
        one by ``scipy.signal.lfilter``, whose state (transposed direct form II) is that
        realisation's: O(n) per sample.

        Parameters
        ----------
        u
            Inputs, shape (N, m) in the units of ``input_units``.
        x0
            Initial state: a StateSpace's, shape (n,); a TransferFunction's observable
            realisation's (its size is the sum of the entries' degrees; see
            :meth:`TransferFunction.initial_state`). Default zero.

        Returns
        -------
        ndarray, shape (N, p)

        Examples
        --------
        >>> from gripkit.lti import StateSpace, TransferFunction
        >>> StateSpace([[0.5]], [[1.0]], [[1.0]], dt=1.0).simulate([1.0, 0.0, 0.0])[:, 0].tolist()
        [0.0, 1.0, 0.5]
        >>> TransferFunction.from_polynomials([1, -0.5], [0, 1.0],
        ...                                   dt=1.0).simulate([1.0, 0, 0])[:, 0].tolist()
        [0.0, 1.0, 0.5]
        """
        if not self.is_discrete:
            raise ModelError("simulate: the system is continuous; it needs a sample time",
                             hint="discretise it first: sys.c2d(dt)")
        return self._simulate(as_input_array(u, self.n_inputs), x0)

    def _time_grid(self, t) -> tuple[int, float]:
        if self.is_discrete:
            if np.ndim(t) == 0:
                n = int(t)
                if n != t or n < 1:
                    raise DataError(f"t: expected a positive number of samples, found {t!r}")
                return n, self.dt
            t = np.asarray(t, dtype=np.float64)
            if t.size > 1 and not np.allclose(np.diff(t), self.dt, rtol=1e-9, atol=0):
                raise DataError(f"t: expected samples spaced by dt = {self.dt:g} s")
            return t.size, self.dt
        t = np.asarray(t, dtype=np.float64)
        if t.ndim != 1 or t.size < 2:
            raise DataError("t: a continuous system needs times in s (uniform, from 0, at "
                            "least 2 samples)")
        h = float(t[1] - t[0])
        if not (h > 0 and abs(t[0]) <= 1e-12 * h and np.allclose(np.diff(t), h, rtol=1e-9, atol=0)):
            raise DataError("t: expected uniform, increasing times starting at 0")
        return t.size, h

    def _sampled(self, h):
        ss = self.to_ss(minimal=False)
        if self.is_discrete:
            return ss.A, ss.B, ss.C, ss.D
        return _discretize.c2d_matrices(ss.A, ss.B, ss.C, ss.D, h, "zoh")

    def step(self, t) -> np.ndarray:
        """Unit-step responses from rest, shape (N, p, m): column j is the response to a step on
        input j. Continuous systems are sampled with ZOH at the grid's step, which is exact for a
        step input: y[k] = Σ_{i<k} C A_d^{k−1−i} B_d + D.

        Parameters
        ----------
        t
            Discrete: a number of samples N, or times spaced by ``dt``. Continuous: uniform times
            from 0 (s), shape (N,).

        Returns
        -------
        ndarray, shape (N, p, m)
            ``[k, i, j]``: output i at sample k after the step on input j.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> y = TransferFunction([0.5], [1.0, -0.5], dt=1.0).step(4)
        >>> y[:, 0, 0].tolist()
        [0.0, 0.5, 0.75, 0.875]
        """
        return self._input_responses(t, lambda A, B, C, D, N, j: _simulate_arrays(
            A, B[:, j:j + 1], C, D[:, j:j + 1], np.ones((N, 1)), None))

    def impulse(self, t) -> np.ndarray:
        """Impulse responses from rest, shape (N, p, m). Discrete: the response to a unit pulse
        u[0] = 1 (``scipy.signal.dimpulse``). Continuous: ``y(t) = C e^{At} B`` (the D δ(t) term
        is left out, as in ``scipy.signal.impulse``).

        Parameters
        ----------
        t
            As for :meth:`step`.

        Returns
        -------
        ndarray
            As for :meth:`step`, the impulse in place of the step.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([0.5], [1.0, -0.5], dt=1.0).impulse(3)[:, 0, 0].tolist()
        [0.0, 0.5, 0.25]
        """
        return self._input_responses(t, self._impulse_column)

    def _impulse_column(self, A, B, C, D, N, j):
        """The response (N, p) to an impulse on input j (see :meth:`impulse`)."""
        if self.is_discrete:
            u = np.zeros((N, 1))
            u[0] = 1.0
            return _simulate_arrays(A, B[:, j:j + 1], C, D[:, j:j + 1], u, None)
        return _simulate_arrays(A, np.zeros((A.shape[0], 1)), C, np.zeros((C.shape[0], 1)),
                                np.zeros((N, 1)), self.to_ss(minimal=False).B[:, j])

    def _input_responses(self, t, column):
        """(N, p, m) on the time grid ``t``: ``[:, :, j] = column(A, B, C, D, N, j)``, with
        (A, B, C, D) the realisation sampled at the grid's step (:meth:`_sampled`)."""
        N, h = self._time_grid(t)
        A, B, C, D = self._sampled(h)
        out = np.empty((N, C.shape[0], B.shape[1]))
        for j in range(B.shape[1]):
            out[:, :, j] = column(A, B, C, D, N, j)
        return out

    # ------------------------------------------------------------------ discretisation
    def c2d(self, dt: float, method: str = "zoh", prewarp: float | None = None):
        """The discrete equivalent at sample time ``dt`` (s), of the same view.

        Methods (see :mod:`gripkit.lti._discretize` for the equations): ``'zoh'`` (exact for
        piecewise-constant inputs: Φ = e^{A dt}, Γ = ∫₀^dt e^{As} ds B), ``'foh'`` (triangle
        hold), ``'tustin'`` (s = (2/T)(z−1)/(z+1); ``prewarp`` ω_p in rad/s matches G at ω_p).

        Parameters
        ----------
        dt
            Sample time (s), > 0.
        method
            ``'zoh'``, ``'foh'`` or ``'tustin'`` (alias ``'bilinear'``).
        prewarp
            Tustin only: the frequency ω_p (rad/s, below π/dt) where the response is kept exact.

        Returns
        -------
        LinearSystem
            The same view (StateSpace or TransferFunction), names, units and covariance carried.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> g = TransferFunction([1.0], [1.0, 1.0]).c2d(0.1)
        >>> [round(float(c), 6) for c in g.den_zinv()]
        [1.0, -0.904837]
        """
        if self.is_discrete:
            raise ModelError(f"c2d: the system is already discrete ({_fmt_dt(self.dt)})",
                             hint="use d2c() first to resample, or keep it as it is")
        dt = require_discrete(dt, "c2d")
        m = _discretize.check_method(method, prewarp)
        return self._map_ss(lambda A, B, C, D: _discretize.c2d_matrices(A, B, C, D, dt, m, prewarp),
                            dt=dt,
                            meta={**self.meta, "c2d": m})

    def d2c(self, method: str = "zoh", prewarp: float | None = None):
        """The continuous system whose ``c2d(dt, method)`` is this one (inverse of :meth:`c2d`).

        ZOH and FOH need log Φ: a real pole on the closed negative real axis (z ≤ 0: at or
        beyond the Nyquist frequency, or a pure delay) has no continuous preimage and raises
        ModelError; Tustin needs no pole at z = −1.

        Parameters
        ----------
        method, prewarp
            As for :meth:`c2d`.

        Returns
        -------
        LinearSystem
            Continuous, same view, names, units and covariance carried.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> g = TransferFunction([1.0], [1.0, 1.0])
        >>> back = g.c2d(0.1).d2c()
        >>> [round(float(c), 9) for c in back.denominator()]
        [1.0, 1.0]
        """
        if not self.is_discrete:
            raise ModelError("d2c: the system is already continuous")
        dt = self.dt
        m = _discretize.check_method(method, prewarp)
        return self._map_ss(lambda A, B, C, D: _discretize.d2c_matrices(A, B, C, D, dt, m, prewarp),
                            dt=None,
                            meta={**self.meta, "d2c": m})

    # ------------------------------------------------------------------ interconnection
    def series(self, other):
        """``other ∘ self``: u → self → other → y (G = G_other · G_self). See :func:`series`.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> g = TransferFunction([1.0], [1.0, 1.0])
        >>> g.series(TransferFunction([3.0], [1.0, 3.0])).denominator().tolist()
        [1.0, 4.0, 3.0]
        """
        return series(self, other)

    def parallel(self, other):
        """``self + other`` on shared inputs, outputs summed. See :func:`parallel`.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([1.0], [1.0, 1.0]).parallel(2.0).dc_gain().tolist()  # a static gain
        [[3.0]]
        """
        return parallel(self, other)

    def feedback(self, other=1.0, sign: float = -1.0):
        """Closed loop ``(I − sign·G K)⁻¹ G``. See :func:`feedback`.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([3.0], [1.0, 1.0]).feedback().dc_gain().tolist()
        [[0.75]]
        """
        return feedback(self, other, sign)

    def __mul__(self, other):
        if isinstance(other, LinearSystem):
            return series(other, self)
        return self._scaled(other)

    def __rmul__(self, other):
        return self._scaled(other)

    def __add__(self, other):
        return parallel(self, other)

    def __radd__(self, other):
        return parallel(self, other)

    def __neg__(self):
        return self._scaled(-1.0)

    def __sub__(self, other):
        return parallel(self, -other)

    def _scaled(self, k):
        try:
            k = float(k)
        except (TypeError, ValueError):
            return NotImplemented
        if not math.isfinite(k):
            raise ModelError(f"gain: expected a finite number, found {k!r}")
        return self._map_self(lambda *arrs: self._scale_arrays(arrs, k))

    # ------------------------------------------------------------------ uncertainty
    # ------------------------------------------------------------------ files
    def to_dict(self) -> dict:
        """A JSON-ready description: ``type`` (``'StateSpace'``/``'TransferFunction'``), the
        arrays as nested lists (stored form), ``dt``, names, units, ``meta`` and ``uncertainty``
        (``names``, ``covariance``, ``tangents``) or None. :meth:`from_dict` reads it back
        exactly (floats survive JSON's shortest repr).

        Examples
        --------
        >>> import json
        >>> from gripkit.lti import LinearSystem, TransferFunction
        >>> g = TransferFunction([1.0], [1.0, 0.5], dt=0.1, inputs="V")
        >>> back = LinearSystem.from_dict(json.loads(json.dumps(g.to_dict())))
        >>> back.inputs, back.denominator().tolist()
        (('V',), [1.0, 0.5])
        """
        keys = ("A", "B", "C", "D") if isinstance(self, StateSpace) else ("num", "den")
        d = {"type": type(self).__name__}
        d.update({k: a.tolist() for k, a in zip(keys, self._arrays())})
        d.update(dt=self.dt, inputs=list(self.inputs), outputs=list(self.outputs),
                 input_units=list(self.input_units), output_units=list(self.output_units),
                 meta=dict(self.meta))
        if isinstance(self, StateSpace):
            d.update(states=list(self.states), state_units=list(self.state_units))
        u = self.uncertainty
        d["uncertainty"] = None if u is None else {"names": list(u.names),
                                                   "covariance": u.covariance.tolist(),
                                                   "tangents": [t.tolist() for t in u.tangents]}
        return d

    @staticmethod
    def from_dict(d: dict) -> LinearSystem:
        """The system :meth:`to_dict` described (validated as any new system).

        Examples
        --------
        >>> from gripkit.lti import LinearSystem
        >>> LinearSystem.from_dict({"type": "StateSpace", "A": [[-1.0]], "B": [[1.0]],
        ...                         "C": [[2.0]]}).dc_gain().tolist()
        [[2.0]]
        """
        if not isinstance(d, dict) or d.get("type") not in ("StateSpace", "TransferFunction"):
            found = d.get("type") if isinstance(d, dict) else type(d).__name__
            raise ModelError("from_dict: expected a dict with type 'StateSpace' or "
                             f"'TransferFunction', found {found!r}")
        kw = ({k: d[k] for k in ("dt", "inputs", "outputs", "input_units", "output_units",
                                 "meta") if d.get(k) is not None})
        u = d.get("uncertainty")
        if u is not None:
            try:
                kw["uncertainty"] = Uncertainty(tuple(u["names"]), u["covariance"],
                                                tuple(np.asarray(t, dtype=np.float64)
                                                      for t in u["tangents"]))
            except (KeyError, TypeError) as e:
                raise ModelError("from_dict: uncertainty needs names, covariance "
                                 f"and tangents ({e})") from None
        try:
            if d["type"] == "StateSpace":
                kw.update({k: d[k] for k in ("states", "state_units") if d.get(k) is not None})
                return (StateSpace(np.asarray(d["A"], dtype=np.float64), d["B"], d["C"], d.get("D"),
                                   **kw))
            return (TransferFunction(np.asarray(d["num"], dtype=np.float64),
                                     np.asarray(d["den"], dtype=np.float64), **kw))
        except KeyError as e:
            raise ModelError(f"from_dict: the {d['type']} description lacks {e}") from None

    def sample(self, n: int, seed=None) -> list:
        """``n`` systems drawn from the linearised parameter distribution, θ ~ N(θ̂, Σ):
        each array becomes ``X + Σ_i δθ_i ∂X/∂θ_i`` (for Monte Carlo studies).

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> g = TransferFunction([1.0], [1.0, 2.0]).with_covariance([[1e-4]], ["den[1]"])
        >>> len(g.sample(5, seed=0))
        5
        """
        if self.uncertainty is None:
            raise ModelError("sample: the system carries no covariance")
        rng = np.random.default_rng(seed)
        arrays = self._arrays()
        out = []
        for d in self.uncertainty.draws(n, rng):
            arrs = (tuple(a + np.tensordot(d, t, axes=1)
                          for a, t in zip(arrays, self.uncertainty.tangents)))
            out.append(self._rebuild(arrs, None))
        return out

    def _map_self(self, fn, **signals):
        arrs, unc = push(fn, [self._arrays()], [self.uncertainty])
        return self._rebuild(arrs, unc, **signals)

    def _map_ss(self, fn, **signals):
        """Apply an array map to the state-space arrays and return the same view."""
        ss = self.to_ss(minimal=False)
        arrs, unc = push(fn, [ss._arrays()], [ss.uncertainty])
        out = ss._rebuild(arrs, unc, **signals)
        return out if isinstance(self, StateSpace) else out.to_tf(minimal=True)

    # ------------------------------------------------------------------ interop
    def to_scipy(self):
        """``scipy.signal`` equivalent: a ``TransferFunction`` for SISO transfer functions, a
        ``StateSpace`` otherwise (with ``dt`` when discrete). Names, units and covariance are not
        carried (scipy has no place for them).

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([1.0], [1.0, 1.0], dt=0.1).to_scipy().dt
        0.1
        """
        kw = {"dt": self.dt} if self.is_discrete else {}
        if isinstance(self, TransferFunction) and self.is_siso:
            from scipy import signal
            return signal.TransferFunction(self.numerator(), self.denominator(), **kw)
        ss = self.to_ss()
        from scipy import signal
        return signal.StateSpace(ss.A, ss.B, ss.C, ss.D, **kw)


# ====================================================================== state space
@dataclass(frozen=True, eq=False)
class StateSpace(LinearSystem):
    """A state-space system ``(A, B, C, D)``, continuous (``dt=None`` or 0) or discrete
    (``dt`` > 0 s)::

        ẋ = A x + B u  (or x[k+1] = A x[k] + B u[k]),   y = C x + D u.

    Parameters
    ----------
    A, B, C, D
        Shapes (n, n), (n, m), (p, n), (p, m). A 1-D ``B`` is one column, a 1-D ``C`` one row;
        ``D=None`` is zero. Matrices are copied, checked finite and made read-only.
    dt
        None or 0 for continuous time, else the sample time (s).
    inputs, outputs, states
        Distinct names (defaults ``u``/``y``/``x`` or ``u0, u1, …``).
    input_units, output_units, state_units
        SI unit strings (``''``: not declared).
    meta
        Provenance (free-form).
    uncertainty
        Parameter covariance and tangents ``(dA, dB, dC, dD)``; see :meth:`with_covariance`.

    Examples
    --------
    >>> from gripkit.lti import StateSpace
    >>> s = StateSpace([[0.0, 1.0], [-4.0, -0.4]], [[0.0], [4.0]], [[1.0, 0.0]],
    ...                inputs="F", outputs="x", input_units="N", output_units="m")
    >>> s.poles().round(3).tolist(), float(s.dc_gain()[0, 0])
    ([(-0.2+1.99j), (-0.2-1.99j)], 1.0)
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray | None = None
    dt: float | None = None
    inputs: tuple[str, ...] | None = None
    outputs: tuple[str, ...] | None = None
    input_units: tuple[str, ...] | None = None
    output_units: tuple[str, ...] | None = None
    meta: dict = field(default_factory=dict)
    states: tuple[str, ...] | None = None
    state_units: tuple[str, ...] | None = None
    uncertainty: Uncertainty | None = None

    def __post_init__(self):
        set_ = object.__setattr__
        A = as_matrix(self.A, "A")
        n = A.shape[0]
        if A.shape != (n, n):
            raise ModelError(f"A: expected a square matrix, found shape {A.shape}")
        B = as_matrix(_vector_as(self.B, (-1, 1)), "B")
        if B.shape[0] != n:
            raise ModelError(f"B: expected shape ({n}, m) (one row per state), found {B.shape}")
        C = as_matrix(_vector_as(self.C, (1, -1)), "C")
        if C.shape[1] != n:
            raise ModelError(f"C: expected shape (p, {n}) (one column per state), found {C.shape}")
        p, m = C.shape[0], B.shape[1]
        D = np.zeros((p, m)) if self.D is None else self.D
        D = as_matrix(D, "D", (p, m))
        for k, v in (("A", A), ("B", B), ("C", C), ("D", D)):
            set_(self, k, v)
        set_(self, "dt", as_dt(self.dt))
        set_(self, "inputs", as_names(self.inputs, m, "inputs", "u"))
        set_(self, "outputs", as_names(self.outputs, p, "outputs", "y"))
        set_(self, "states", as_names(self.states, n, "states", "x"))
        set_(self, "input_units", as_units(self.input_units, m, "input_units"))
        set_(self, "output_units", as_units(self.output_units, p, "output_units"))
        set_(self, "state_units", as_units(self.state_units, n, "state_units"))
        set_(self, "meta", dict(self.meta or {}))
        if self.uncertainty is not None:
            if not isinstance(self.uncertainty, Uncertainty):
                raise ModelError("uncertainty: expected an Uncertainty, found "
                                 f"{type(self.uncertainty).__name__}")
            self.uncertainty._check_shapes(self._arrays())

    # ------------------------------------------------------------------ plumbing
    def _arrays(self):
        return (self.A, self.B, self.C, self.D)

    def _rebuild(self, arrays, uncertainty, **signals):
        """A system of this class (a subclass keeps its class) with new arrays; the state names
        stay when the state count does."""
        keep = arrays[0].shape == self.A.shape
        return type(self)(*arrays, **self._signals(**signals), states=self.states if keep else None,
                          state_units=self.state_units if keep else None, uncertainty=uncertainty)

    @staticmethod
    def _scale_arrays(arrs, k):
        A, B, C, D = arrs
        return A, B, C * k, D * k

    @property
    def n_states(self) -> int:
        return self.A.shape[0]

    def with_covariance(self, covariance, parameters=None) -> StateSpace:
        """A copy carrying the covariance of some of its matrix entries.

        Parameters
        ----------
        covariance
            Σ, shape (k, k).
        parameters
            k entry names ``'A[i,j]'``, ``'B[i,j]'``, ``'C[i,j]'``, ``'D[i,j]'``; default all
            entries, in the order vec(A), vec(B), vec(C), vec(D) (row-major).

        Examples
        --------
        >>> from gripkit.lti import StateSpace
        >>> s = StateSpace([[-1.0]], [[1.0]], [[1.0]]).with_covariance([[0.04]], ["B[0,0]"])
        >>> s.uncertainty.names, float(s.uncertainty.std[0])
        (('B[0,0]',), 0.2)
        """
        arrays = dict(zip("ABCD", self._arrays()))
        if parameters is None:
            parameters = [f"{k}[{i},{j}]" for k, a in arrays.items()
                          for i in range(a.shape[0]) for j in range(a.shape[1])]
        parameters = list(parameters)
        tangents = [np.zeros((len(parameters),) + a.shape) for a in arrays.values()]
        for q, name in enumerate(parameters):
            mt = re.fullmatch(r"\s*([ABCD])\[\s*(\d+)\s*,\s*(\d+)\s*\]\s*", str(name))
            if not mt:
                raise ModelError(f"parameters: expected names like 'A[0,1]', found {name!r}")
            k, i, j = mt.group(1), int(mt.group(2)), int(mt.group(3))
            if i >= arrays[k].shape[0] or j >= arrays[k].shape[1]:
                raise ModelError(f"parameters: {name!r} lies outside {k}, whose shape is "
                                 f"{arrays[k].shape}")
            tangents["ABCD".index(k)][q, i, j] = 1.0
        return self.replace(uncertainty=Uncertainty(tuple(parameters), covariance, tuple(tangents)))

    # ------------------------------------------------------------------ analysis
    def poles(self) -> np.ndarray:
        """Eigenvalues of A.

        Examples
        --------
        >>> from gripkit.lti import StateSpace
        >>> StateSpace([[-1.0, 0.0], [0.0, -3.0]], [[1.0], [1.0]],
        ...            [[1.0, 1.0]]).poles().real.tolist()
        [-1.0, -3.0]
        """
        return (np.linalg.eigvals(self.A).astype(complex) if self.n_states
                else np.zeros(0, dtype=complex))

    def zeros(self) -> np.ndarray:
        """Transmission zeros: where the system matrix [[A − zI, B], [C, D]] of a minimal
        realisation loses rank (see :func:`gripkit.lti._realize.ss_zeros`).

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([1.0, 2.0], [1.0, 3.0, 5.0]).to_ss().zeros().real.round(9).tolist()
        [-2.0]
        """
        return _realize.ss_zeros(self.A, self.B, self.C, self.D)

    def dc_gain(self) -> np.ndarray:
        """Static gain (p, m): ``D − C A⁻¹ B`` (continuous) or ``D + C (I − A)⁻¹ B`` (discrete).

        Raises ModelError when a pole sits at s = 0 (z = 1): the gain is infinite.

        Examples
        --------
        >>> from gripkit.lti import StateSpace
        >>> StateSpace([[-2.0]], [[1.0]], [[4.0]]).dc_gain().tolist()
        [[2.0]]
        """
        n = self.n_states
        M = (np.eye(n) - self.A) if self.is_discrete else -self.A
        if n:
            s = np.linalg.svd(M, compute_uv=False)
            if s[-1] <= n * _EPS * max(s[0], np.abs(self.A).max(), 1.0):
                raise ModelError("dc_gain: the system has a pole at "
                                 + ("z = 1" if self.is_discrete else "s = 0")
                                 + ": its DC gain is infinite")
            return self.C @ np.linalg.solve(M, self.B) + self.D
        return self.D.copy()

    def _response(self, s):
        """``C (sI − A)⁻¹ B + D`` at each s."""
        return _ss_frequency(self.A, self.B, self.C, self.D, s)[0]

    def _frequency_jacobian(self, s):
        _, X, Y = _ss_frequency(self.A, self.B, self.C, self.D, s)
        dA, dB, dC, dD = self.uncertainty.tangents
        return (np.einsum("fpn,knl,flm->kfpm", Y, dA, X) + np.einsum("fpn,knm->kfpm", Y, dB)
                + np.einsum("kpn,fnm->kfpm", dC, X) + dD[:, None])

    # ------------------------------------------------------------------ simulation
    def _simulate(self, u, x0):
        """The recursion of the class docstring (a numba kernel,
        :func:`gripkit.lti.simulate_ss`)."""
        return _simulate_arrays(self.A, self.B, self.C, self.D, u, x0)

    # ------------------------------------------------------------------ conversions
    def to_ss(self, minimal: bool = False) -> StateSpace:
        """This system, or a minimal realisation of it (``minimal=True``; the covariance is
        dropped with an AccuracyWarning when states are removed from an uncertain system).

        Examples
        --------
        >>> from gripkit.lti import StateSpace
        >>> s = StateSpace([[-1.0, 0.0], [0.0, -2.0]], [[1.0], [0.0]], [[1.0, 1.0]])
        >>> s.to_ss(minimal=True).n_states
        1
        """
        if not minimal:
            return self
        A, B, C, D = _realize.minreal(*self._arrays())
        if A.shape == self.A.shape:
            return self
        if self.uncertainty is not None:
            emit_warning("to_ss(minimal=True): removing states drops the covariance (the cancelled "
                         "modes carry part of it)", AccuracyWarning)
        return StateSpace(A, B, C, D, **self._signals())

    def to_tf(self, minimal: bool = True) -> TransferFunction:
        """The matrix of SISO transfer functions G_ij = num_ij/den_ij (descending powers,
        monic denominators). With ``minimal`` each entry's uncontrollable and unobservable modes
        cancel; a system with covariance keeps full-degree entries (their coefficients, not the
        cancelled ones, carry the linearised σ exactly).

        Examples
        --------
        >>> from gripkit.lti import StateSpace
        >>> g = StateSpace([[-2.0]], [[1.0]], [[3.0]]).to_tf()
        >>> g.numerator().tolist(), g.denominator().tolist()
        ([3.0], [1.0, 2.0])
        """
        minimal = minimal and self.uncertainty is None
        arrs, unc = (push(lambda A, B, C, D: _realize.ss2tf(A, B, C, D, minimal), [self._arrays()],
                          [self.uncertainty]))
        return TransferFunction(arrs[0], arrs[1], **self._signals(), uncertainty=unc)

    def to_control(self):
        """``control.StateSpace`` with input, output and state names (python-control, optional).

        Examples
        --------
        >>> from gripkit.lti import StateSpace
        >>> StateSpace([[-1.0]], [[1.0]], [[1.0]], inputs="V",
        ...            outputs="x").to_control().input_labels
        ['V']
        """
        ct = control_module()
        return ct.ss(self.A, self.B, self.C, self.D, 0 if self.dt is None else self.dt,
                     inputs=list(self.inputs), outputs=list(self.outputs), states=list(self.states))

    def __repr__(self) -> str:
        return (f"StateSpace(n={self.n_states}, inputs={list(self.inputs)}, "
                f"outputs={list(self.outputs)}, "
                f"{_fmt_dt(self.dt)}{', with covariance' if self.uncertainty is not None else ''})")


# ====================================================================== transfer function
def _parse_polys(x, name):
    """(p, m) nested list of 1-D coefficient arrays from a 1-D sequence (SISO), a p × m nested
    list of 1-D sequences (MIMO) or an array of shape (p, m, L)."""
    def poly(c, where):
        try:
            a = np.atleast_1d(np.asarray(c, dtype=np.float64))
        except (TypeError, ValueError):
            a = None
        if a is None or a.ndim != 1 or a.size == 0:
            raise ModelError(f"{name}{where}: expected a 1-D sequence of coefficients, found {c!r}")
        return a

    if isinstance(x, np.ndarray) and x.ndim == 3:
        return [[poly(x[i, j], f"[{i},{j}]") for j in range(x.shape[1])] for i in range(x.shape[0])]
    nested = isinstance(x, (list, tuple)) and len(x) > 0 and all(isinstance(r, (list, tuple))
                                                                 for r in x) \
        and all(isinstance(c, (list, tuple, np.ndarray)) for r in x for c in r)
    if not nested:
        return [[poly(x, "")]]
    rows = [[poly(c, f"[{i},{j}]") for j, c in enumerate(r)] for i, r in enumerate(x)]
    if any(len(r) != len(rows[0]) for r in rows) or not rows[0]:
        raise ModelError(f"{name}: expected a rectangular p × m list of lists of "
                         "polynomials, found rows of "
                         f"lengths {[len(r) for r in rows]}")
    return rows


@dataclass(frozen=True, eq=False)
class TransferFunction(LinearSystem):
    """A (p × m) matrix of SISO transfer functions G_ij(s) = num_ij(s)/den_ij(s), or of z for a
    discrete system, coefficients in descending powers::

        G_ij = (b_0 s^d + … + b_d) / (s^d + a_1 s^{d−1} + … + a_d)

    Denominators are stored monic (the leading coefficient divided out) and all entries padded
    with leading zeros to one length L. A discrete system also reads in powers of z⁻¹, the layout
    of ARX/RST code (:meth:`from_polynomials`, :meth:`num_zinv`, :meth:`den_zinv`).

    Parameters
    ----------
    num, den
        1-D coefficient arrays (SISO), or p × m nested lists of them, or arrays of shape
        (p, m, L). Every entry must be proper: deg num ≤ deg den.
    dt, inputs, outputs, input_units, output_units, meta
        As for :class:`StateSpace`.
    uncertainty
        Covariance with tangents ``(dnum, dden)`` of shape (k, p, m, L); the arrays must then
        already be in stored form (monic, padded). See :meth:`with_covariance`.

    Examples
    --------
    >>> from gripkit.lti import TransferFunction
    >>> g = TransferFunction([2.0, 4.0], [2.0, 6.0, 10.0])   # (s + 2)/(s² + 3 s + 5)
    >>> g.numerator().tolist(), g.denominator().tolist(), float(g.dc_gain()[0, 0])
    ([1.0, 2.0], [1.0, 3.0, 5.0], 0.4)
    """

    num: np.ndarray
    den: np.ndarray
    dt: float | None = None
    inputs: tuple[str, ...] | None = None
    outputs: tuple[str, ...] | None = None
    input_units: tuple[str, ...] | None = None
    output_units: tuple[str, ...] | None = None
    meta: dict = field(default_factory=dict)
    uncertainty: Uncertainty | None = None

    def __post_init__(self):
        set_ = object.__setattr__
        nums, dens = _parse_polys(self.num, "num"), _parse_polys(self.den, "den")
        p, m = len(nums), len(nums[0])
        if (len(dens), len(dens[0])) != (p, m):
            raise ModelError(f"den: expected {p} × {m} denominators (as num), found {len(dens)} "
                             f"× {len(dens[0])}")
        stored = self.uncertainty is not None
        L = max(max(c.size for r in nums for c in r), max(c.size for r in dens for c in r))
        num = np.zeros((p, m, L))
        den = np.zeros((p, m, L))
        for i in range(p):
            for j in range(m):
                nu, de = nums[i][j], dens[i][j]
                where = f"[{i},{j}]" if (p, m) != (1, 1) else ""
                if not (np.isfinite(nu).all() and np.isfinite(de).all()):
                    raise ModelError(f"num{where}/den{where}: coefficients must be finite")
                if not np.any(de):
                    raise ModelError(f"den{where}: the denominator is zero")
                k = np.flatnonzero(de)[0]
                deg_den = de.size - 1 - k
                nz = np.flatnonzero(nu)
                deg_num = nu.size - 1 - nz[0] if nz.size else 0
                if deg_num > deg_den:
                    raise ModelError(f"num{where}: an improper transfer function (numerator "
                                     f"degree {deg_num} > "
                                     f"denominator degree {deg_den}) has no "
                                     "state-space realisation",
                                     hint="add poles (a filter) to make it proper")
                lead = de[k]
                if stored and lead != 1.0:
                    raise ModelError("den: with an uncertainty, denominators must be given "
                                     "monic (stored form)",
                                     hint="build the system first, then call with_covariance(...)")
                num[i, j, L - nu.size:] = nu / lead
                den[i, j, L - de.size:] = de / lead
        if not stored:  # drop columns of leading zeros shared by every entry
            nz = np.flatnonzero(np.any(num != 0, axis=(0, 1)) | np.any(den != 0, axis=(0, 1)))
            num, den = num[:, :, nz[0]:], den[:, :, nz[0]:]
        num.flags.writeable = False
        den.flags.writeable = False
        set_(self, "num", num)
        set_(self, "den", den)
        set_(self, "dt", as_dt(self.dt))
        set_(self, "inputs", as_names(self.inputs, m, "inputs", "u"))
        set_(self, "outputs", as_names(self.outputs, p, "outputs", "y"))
        set_(self, "input_units", as_units(self.input_units, m, "input_units"))
        set_(self, "output_units", as_units(self.output_units, p, "output_units"))
        set_(self, "meta", dict(self.meta or {}))
        if stored:
            if not isinstance(self.uncertainty, Uncertainty):
                raise ModelError("uncertainty: expected an Uncertainty, found "
                                 f"{type(self.uncertainty).__name__}")
            self.uncertainty._check_shapes(self._arrays())

    # ------------------------------------------------------------------ construction
    @classmethod
    def from_polynomials(cls, A, B, *, C=None, F=None, dt: float, covariance=None,
                         **signals) -> TransferFunction:
        """The discrete SISO system ``y = B(q)/(A(q) F(q)) u``, coefficients in increasing powers
        of q⁻¹ (MATLAB ``idpoly`` layout, as in :class:`gripkit.sysid.PolynomialModel`)::

            A(q) = 1 + a_1 q⁻¹ + … + a_na q⁻ⁿᵃ,   B(q) = b_nk q⁻ⁿᵏ + … ,   F(q) = 1 + f_1 q⁻¹ + …

        ``C`` (a noise polynomial, not part of B/(A F)) only names its parameters so that
        ``covariance`` can be the identified model's whole covariance over
        ``a1…a_na, b_nk…, c1…c_nc, f1…f_nf`` (in that order; the c's get zero tangents). Trailing
        zeros are padding, and a non-monic A (without covariance) is divided out.

        Parameters
        ----------
        A, B, C, F
            Coefficient arrays in increasing powers of q⁻¹.
        dt
            Sample time (s), > 0.
        covariance
            Covariance of the free coefficients in the order above (names ``a1 … f_nf``).
        **signals
            ``inputs``, ``outputs``, ``input_units``, ``output_units``, ``meta``.

        Returns
        -------
        TransferFunction

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> g = TransferFunction.from_polynomials([1, -1.8732, 0.8996], [0, 0, 0.1950, -0.2276],
        ...                                       dt=0.005)
        >>> g.relative_degree(), round(float(g.dc_gain()[0, 0]), 4)
        (2, -1.2348)
        """
        dt = require_discrete(dt, "from_polynomials")
        a = np.atleast_1d(np.asarray(A, dtype=np.float64))
        b = np.atleast_1d(np.asarray(B, dtype=np.float64))
        f = np.ones(1) if F is None else np.atleast_1d(np.asarray(F, dtype=np.float64))
        c = np.ones(1) if C is None else np.atleast_1d(np.asarray(C, dtype=np.float64))
        for name, v in (("A", a), ("B", b), ("C", c), ("F", f)):
            if v.ndim != 1 or not np.isfinite(v).all() or v.size == 0:
                raise ModelError(f"{name}: expected finite coefficients in powers of q⁻¹, "
                                 f"found {v.tolist()}")
        if a[0] == 0 or f[0] == 0:
            raise ModelError("A and F must start with a nonzero coefficient (q⁰ term)")
        if not np.any(b):
            raise ModelError("B is all zeros: the system has no input path")
        den = np.convolve(a, f)
        L = max(den.size, b.size)
        num_s, den_s = np.pad(b, (0, L - b.size)), np.pad(den, (0, L - den.size))
        if covariance is None:
            return cls(num_s, den_s, dt=dt, **signals)
        if a[0] != 1.0 or f[0] != 1.0 or (C is not None and c[0] != 1.0):
            raise ModelError("from_polynomials with covariance: A, C and F must be "
                             "monic (start with 1)")
        nk = int(np.flatnonzero(b)[0])
        names = ([f"a{i}" for i in range(1, a.size)] + [f"b{j}" for j in range(nk, b.size)]
                 + [f"c{i}" for i in range(1, c.size)] + [f"f{i}" for i in range(1, f.size)])
        k = len(names)
        dnum = np.zeros((k, 1, 1, L))
        dden = np.zeros((k, 1, 1, L))
        q = 0
        for i in range(1, a.size):
            e = np.zeros(a.size)
            e[i] = 1.0
            dden[q, 0, 0, :den.size] = np.convolve(e, f)
            q += 1
        for j in range(nk, b.size):
            dnum[q, 0, 0, j] = 1.0
            q += 1
        q += c.size - 1
        for i in range(1, f.size):
            e = np.zeros(f.size)
            e[i] = 1.0
            dden[q, 0, 0, :den.size] = np.convolve(a, e)
            q += 1
        unc = Uncertainty(tuple(names), covariance, (dnum, dden))
        return (cls(num_s.reshape(1, 1, L), den_s.reshape(1, 1, L), dt=dt, uncertainty=unc,
                    **signals))

    def with_covariance(self, covariance, parameters=None) -> TransferFunction:
        """A copy carrying the covariance of some coefficients.

        ``parameters`` are names ``'num[k]'``/``'den[k]'`` (SISO) or ``'num[i,j][k]'`` (MIMO),
        k indexing entry ij's coefficients in descending powers within its denominator degree d
        (k = 0 … d; ``den[0]`` is the fixed leading 1). Default: every ``num`` coefficient and
        ``den[1]…den[d]`` of each entry.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> import numpy as np
        >>> g = TransferFunction([1.0], [1.0, 2.0]).with_covariance(np.diag([0.0, 0.01, 0.04]))
        >>> g.uncertainty.names
        ('num[0]', 'num[1]', 'den[1]')
        """
        p, m, L = self.num.shape
        deg = [[L - 1 - int(np.flatnonzero(self.den[i, j])[0]) for j in range(m)] for i in range(p)]
        tag = (lambda i, j: "") if (p, m) == (1, 1) else (lambda i, j: f"[{i},{j}]")
        if parameters is None:
            parameters = [f"{w}{tag(i, j)}[{k}]" for i in range(p) for j in range(m)
                          for w, ks in (("num", range(deg[i][j] + 1)),
                                        ("den", range(1, deg[i][j] + 1))) for k in ks]
        parameters = list(parameters)
        tangents = (np.zeros((len(parameters), p, m, L)), np.zeros((len(parameters), p, m, L)))
        pat = r"\s*(num|den)\[\s*(\d+)\s*\]\s*" if (p, m) == (1, 1) else \
            r"\s*(num|den)\[\s*(\d+)\s*,\s*(\d+)\s*\]\[\s*(\d+)\s*\]\s*"
        for q, name in enumerate(parameters):
            mt = re.fullmatch(pat, str(name))
            if not mt:
                raise ModelError("parameters: expected names like "
                                 f"{'num[0]' if (p, m) == (1, 1) else 'num[0,1][2]'}, "
                                 f"found {name!r}")
            g = mt.groups()
            w, i, j, k = (g[0], 0, 0, int(g[1])) if len(g) == 2 else (g[0], int(g[1]), int(g[2]),
                                                                      int(g[3]))
            if i >= p or j >= m or k > deg[i][j] or (w == "den" and k == 0):
                raise ModelError(f"parameters: {name!r} is not a free coefficient (entry degree "
                                 f"{deg[i][j] if i < p and j < m else '?'}; den[0] is the "
                                 "fixed leading 1)")
            tangents[0 if w == "num" else 1][q, i, j, L - 1 - deg[i][j] + k] = 1.0
        return self.replace(uncertainty=Uncertainty(tuple(parameters), covariance, tangents))

    # ------------------------------------------------------------------ plumbing
    def _arrays(self):
        return (self.num, self.den)

    def _rebuild(self, arrays, uncertainty, **signals):
        return (TransferFunction(arrays[0], arrays[1], **self._signals(**signals),
                                 uncertainty=uncertainty))

    @staticmethod
    def _scale_arrays(arrs, k):
        return arrs[0] * k, arrs[1]

    def _entry(self, i, j):
        if not (0 <= i < self.n_outputs and 0 <= j < self.n_inputs):
            raise ModelError(f"entry ({i}, {j}) lies outside the {self.n_outputs} × "
                             f"{self.n_inputs} system")
        d = self.den[i, j]
        k = np.flatnonzero(d)[0]
        return self.num[i, j, k:], d[k:]

    def numerator(self, i: int = 0, j: int = 0) -> np.ndarray:
        """Entry ij's numerator, descending powers, leading zeros removed.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([0.0, 3.0], [1.0, 1.0]).numerator().tolist()
        [3.0]
        """
        nu = self._entry(i, j)[0]
        nz = np.flatnonzero(nu)
        return nu[nz[0]:].copy() if nz.size else np.zeros(1)

    def denominator(self, i: int = 0, j: int = 0) -> np.ndarray:
        """Entry ij's monic denominator, descending powers.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([1.0], [2.0, 1.0]).denominator().tolist()
        [1.0, 0.5]
        """
        return self._entry(i, j)[1].copy()

    def relative_degree(self, i: int = 0, j: int = 0) -> int:
        """deg den − deg num of entry ij: for a discrete system, the input delay in samples
        (the ``nk`` of q⁻¹ layouts).

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction.from_polynomials([1, -0.5], [0, 0, 1], dt=1.0).relative_degree()
        2
        """
        return self._entry(i, j)[1].size - self.numerator(i, j).size

    def _zinv_check(self):
        if not self.is_discrete:
            raise ModelError("num_zinv/den_zinv: powers of z⁻¹ need a "
                             "discrete system", hint="use numerator()")

    def num_zinv(self, i: int = 0, j: int = 0) -> np.ndarray:
        """Entry ij's numerator in increasing powers of z⁻¹ (delay as leading zeros, trailing
        zeros dropped): the ``B`` of ``y = B(q)/A(q) u``.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([1.0], [1.0, -0.5, 0.0], dt=1.0).num_zinv().tolist()
        [0.0, 0.0, 1.0]
        """
        self._zinv_check()
        nu = self._entry(i, j)[0]
        nz = np.flatnonzero(nu)
        return nu[:nz[-1] + 1].copy() if nz.size else np.zeros(1)

    def den_zinv(self, i: int = 0, j: int = 0) -> np.ndarray:
        """Entry ij's denominator in increasing powers of z⁻¹ (``[1, a_1, …]``, trailing zeros
        dropped): the ``A`` of ``y = B(q)/A(q) u``.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([1.0], [1.0, -0.5, 0.0], dt=1.0).den_zinv().tolist()
        [1.0, -0.5]
        """
        self._zinv_check()
        d = self._entry(i, j)[1]
        return d[:np.flatnonzero(d)[-1] + 1].copy()

    # ------------------------------------------------------------------ analysis
    def pole_covariance(self) -> tuple[np.ndarray, np.ndarray]:
        """Poles and the covariance of (Re p, Im p) of each, shape (n, 2, 2), to first order.

        SISO: root sensitivity of the monic denominator D, ``∂r/∂θ_i = −(∂D/∂θ_i)(r) / D'(r)``;
        roots at z = 0 that no parameter moves (a delay's trailing zeros of D) have σ = 0.
        MIMO: as :meth:`LinearSystem.pole_covariance`, on the realisation.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> g = TransferFunction.from_polynomials([1, -0.5], [0, 0, 0, 1.0], dt=1.0,
        ...                                       covariance=[[1e-4, 0], [0, 0]])
        >>> p, cov = g.pole_covariance()
        >>> p.real.tolist(), cov[:, 0, 0].round(12).tolist()
        ([0.5, 0.0, 0.0], [0.0001, 0.0, 0.0])
        """
        if not self.is_siso:
            return super().pole_covariance()
        if self.uncertainty is None:
            raise ModelError("pole_covariance: the system carries no covariance",
                             hint="build it with with_covariance(...) or from an identified model")
        den = self.denominator()
        d = den.size - 1
        dden = self.uncertainty.tangents[1][:, 0, 0, self.den.shape[2] - 1 - d:]
        t = 0
        while t < d and den[d - t] == 0.0 and not np.any(dden[:, d - t]):
            t += 1
        core, dcore = den[:d + 1 - t], dden[:, :d + 1 - t]
        r = np.roots(core).astype(complex) if core.size > 1 else np.zeros(0, dtype=complex)
        slope = np.polyval(np.polyder(core), r) if r.size else r
        J = -np.array([np.polyval(row, r) for row in dcore]).reshape(-1, r.size) / slope
        cov = complex_covariance(J, self.uncertainty.covariance)
        # a repeated root has D'(r) ≈ 0 (within the rounding of D' at r): its first-order σ is
        # undefined
        bad = (np.abs(slope) <= 100 * core.size * _EPS * np.polyval(np.abs(np.polyder(core)),
                                                                    np.abs(r)))
        if np.any(bad):
            emit_warning(f"pole_covariance: {int(bad.sum())} pole(s) are (nearly) repeated; their "
                         "first-order σ is undefined and set to inf", AccuracyWarning)
            cov[bad] = np.inf
        return np.r_[r, np.zeros(t, dtype=complex)], np.concatenate([cov, np.zeros((t, 2, 2))])

    def poles(self) -> np.ndarray:
        """SISO: the roots of the denominator. MIMO: the eigenvalues of a minimal realisation.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([1.0], [1.0, 3.0, 2.0]).poles().real.tolist()
        [-2.0, -1.0]
        """
        if self.is_siso:
            return np.roots(self.denominator()).astype(complex)
        A = _realize.minreal(*_realize.tf2ss(self.num, self.den))[0]
        return np.linalg.eigvals(A).astype(complex) if A.size else np.zeros(0, dtype=complex)

    def zeros(self) -> np.ndarray:
        """SISO: the roots of the numerator. MIMO: the transmission zeros (see
        :meth:`StateSpace.zeros`).

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([1.0, -1.167], [1.0, 0.2, 0.1]).zeros().real.tolist()
        [1.167]
        """
        if self.is_siso:
            b = self.numerator()
            return np.roots(b).astype(complex) if b.size > 1 else np.zeros(0, dtype=complex)
        return _realize.ss_zeros(*_realize.tf2ss(self.num, self.den))

    def _eval(self, s):
        """num and den of every entry at each s, shapes (len(s), p, m), and the rounding bound
        L ε Σ|a_k| |s|^k of each den(s) (below it, den(s) is zero within rounding)."""
        bound = self.num.shape[2] * _EPS * _polyval(np.abs(self.den), np.abs(s))
        return _polyval(self.num, s), _polyval(self.den, s), bound

    def _response(self, s):
        """num(s)/den(s) of every entry at each s; ModelError at a pole."""
        nu, de, bound = self._eval(s)
        bad = np.abs(de) <= bound  # a pole on the evaluation contour
        if np.any(bad):
            f = np.argwhere(bad)[0, 0]
            var = "z" if self.is_discrete else "s"
            raise ModelError(f"frequency response: {var} = {s[f]:.6g} is a pole of the system",
                             hint="evaluate away from the poles on the imaginary axis (or "
                                  "the unit circle)")
        return nu / de

    def _frequency_jacobian(self, s):
        nu, de, _ = self._eval(s)
        dnum, dden = self.uncertainty.tangents
        dn = np.moveaxis(_polyval(dnum, s), 0, 1)
        dd = np.moveaxis(_polyval(dden, s), 0, 1)
        return (dn * de - nu * dd) / de ** 2

    def dc_gain(self) -> np.ndarray:
        """Static gain (p, m): num/den at s = 0 (continuous) or z = 1 (discrete).

        Raises ModelError when a denominator vanishes there (a pole at s = 0 or z = 1).

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([0.1950, -0.2276], [1.0, -1.8732, 0.8996],
        ...                  dt=0.005).dc_gain().round(4).tolist()
        [[-1.2348]]
        """
        s0 = np.array([1.0 if self.is_discrete else 0.0])
        nu, de, bound = self._eval(s0)
        if np.any(np.abs(de) <= bound):
            raise ModelError("dc_gain: the system has a pole at "
                             + ("z = 1" if self.is_discrete else "s = 0")
                             + ": its DC gain is infinite")
        return (nu / de)[0].real

    # ------------------------------------------------------------------ simulation
    def initial_state(self, u_past, y_past) -> np.ndarray:
        """The state x0 of :meth:`simulate` that continues a SISO discrete system from past
        samples (time order, most recent last; missing ones count 0), as
        ``scipy.signal.lfiltic`` does for ``lfilter``.

        Examples
        --------
        >>> import numpy as np
        >>> from gripkit.lti import TransferFunction
        >>> g = TransferFunction.from_polynomials([1, -0.5], [0, 1.0], dt=1.0)
        >>> g.simulate(np.zeros(2), g.initial_state([0.0], [2.0]))[:, 0].tolist()
        [1.0, 0.5]
        """
        self._zinv_check()
        if not self.is_siso:
            raise ModelError("initial_state: defined for SISO systems; use a StateSpace for MIMO")
        nu, de = self._entry(0, 0)
        yp = np.atleast_1d(np.asarray(y_past, dtype=np.float64)).ravel()
        up = np.atleast_1d(np.asarray(u_past, dtype=np.float64)).ravel()
        if not (np.isfinite(yp).all() and np.isfinite(up).all()):
            raise DataError("u_past/y_past have non-finite values")
        if de.size == 1:
            return np.zeros(0)
        from scipy import signal
        return signal.lfiltic(nu, de, yp[::-1][:de.size - 1], up[::-1][:de.size - 1])

    def _simulate(self, u, x0):
        """Through the observable canonical realisation (:meth:`to_ss` with ``minimal=False``);
        a SISO system runs ``scipy.signal.lfilter``, whose state (transposed direct form II) is
        that realisation's: O(n) per sample."""
        if self.is_siso:
            nu, de = self._entry(0, 0)
            if de.size == 1:
                _initial_state(x0, 0)
                return nu[0] * u
            from scipy import signal  # imported on first use (import cost: docs/performance.md)

            return (signal.lfilter(nu, de, u[:, 0],
                                   zi=_initial_state(x0, de.size - 1))[0].reshape(-1, 1))
        A, B, C, D = _realize.tf2ss(self.num, self.den)
        return _simulate_arrays(A, B, C, D, u, x0)

    # ------------------------------------------------------------------ conversions
    def to_tf(self, minimal: bool = True) -> TransferFunction:
        """This system (already a transfer function).

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> g = TransferFunction([1.0], [1.0, 1.0])
        >>> g.to_tf() is g
        True
        """
        return self

    def to_ss(self, minimal: bool = True, form: str = "observable") -> StateSpace:
        """A state-space realisation: each entry in canonical form, in parallel.

        ``form='observable'``: ``A = [[-a1, 1, 0, …], [-a2, 0, 1, …], …]``, ``C = e₁ᵀ``: the state
        of ``lfilter`` (:meth:`initial_state`). ``form='controllable'``: its transpose, exactly
        ``scipy.signal.tf2ss``'s realisation. With ``minimal`` (and no covariance) states are
        removed when some cancel (the canonical form is then lost); a SISO entry with coprime
        num/den is minimal already and keeps its form.

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> s = TransferFunction([1.0, 2.0], [1.0, 3.0, 2.0]).to_ss()   # (s+2)/((s+1)(s+2))
        >>> s.n_states, s.poles().real.round(9).tolist()
        (1, [-1.0])
        >>> TransferFunction([1.0], [1.0, 3.0, 2.0]).to_ss(form="controllable").A.tolist()
        [[-3.0, -2.0], [1.0, 0.0]]
        """
        if form not in _realize.FORMS:
            raise ModelError(f"form: expected one of {', '.join(_realize.FORMS)}, found {form!r}")
        arrs, unc = (push(lambda n, d: _realize.tf2ss(n, d, form), [self._arrays()],
                          [self.uncertainty]))
        if minimal and self.uncertainty is None:
            reduced = _realize.minreal(*arrs)
            if reduced[0].shape[0] < arrs[0].shape[0]:
                arrs = reduced
        return StateSpace(*arrs, **self._signals(), uncertainty=unc)

    def to_control(self):
        """``control.TransferFunction`` with input and output names (python-control, optional).

        Examples
        --------
        >>> from gripkit.lti import TransferFunction
        >>> TransferFunction([1.0], [1.0, 1.0], outputs="F").to_control().output_labels
        ['F']
        """
        ct = control_module()
        p, m = self.n_outputs, self.n_inputs
        num = [[self.numerator(i, j) for j in range(m)] for i in range(p)]
        den = [[self.denominator(i, j) for j in range(m)] for i in range(p)]
        return (ct.tf(num, den, 0 if self.dt is None else self.dt, inputs=list(self.inputs),
                      outputs=list(self.outputs)))

    def __repr__(self) -> str:
        if self.is_siso:
            body = f"num={self.numerator().tolist()}, den={self.denominator().tolist()}"
        else:
            body = f"{self.n_outputs}×{self.n_inputs}"
        return (f"TransferFunction({body}, inputs={list(self.inputs)}, "
                f"outputs={list(self.outputs)}, "
                f"{_fmt_dt(self.dt)}{', with covariance' if self.uncertainty is not None else ''})")


# ====================================================================== operations
def c2d(sys: LinearSystem, dt: float, method: str = "zoh",
        prewarp: float | None = None) -> LinearSystem:
    """Discretise ``sys`` at ``dt`` (s); see :meth:`LinearSystem.c2d`.

    Examples
    --------
    >>> from gripkit.lti import StateSpace, c2d
    >>> round(float(c2d(StateSpace([[-1.0]], [[1.0]], [[1.0]]), 0.1).A[0, 0]), 6)   # e^{-0.1}
    0.904837
    """
    return sys.c2d(dt, method, prewarp)


def d2c(sys: LinearSystem, method: str = "zoh", prewarp: float | None = None) -> LinearSystem:
    """The continuous system that discretises to ``sys``; see :meth:`LinearSystem.d2c`.

    Examples
    --------
    >>> import math
    >>> from gripkit.lti import StateSpace, d2c
    >>> round(float(d2c(StateSpace([[math.exp(-0.1)]], [[1.0]], [[1.0]], dt=0.1)).A[0, 0]), 9)
    -1.0
    """
    return sys.d2c(method, prewarp)


def _check_units(a, b, what):
    for x, y in zip(a, b):
        if x and y and x != "1" and y != "1" and x != y:
            raise ModelError(f"{what}: units differ ({x!r} feeds {y!r})",
                             hint="scale one system (k * sys) and replace its units to match")


def _both_siso_tf(g1, g2):
    return (isinstance(g1, TransferFunction) and isinstance(g2, TransferFunction) and g1.is_siso
            and g2.is_siso)


def _as_system(x, like: LinearSystem, n_in: int, n_out: int):
    if isinstance(x, LinearSystem):
        return x
    try:
        K = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ModelError("expected a LinearSystem or a static gain, found "
                         f"{type(x).__name__}") from None
    if K.ndim == 0:
        K = K * np.eye(n_out) if n_out == n_in else np.full((n_out, n_in), float(K))
    if K.shape == (1, 1) and like.is_siso and isinstance(like, TransferFunction):
        return TransferFunction([K[0, 0]], [1.0], dt=like.dt)
    return (StateSpace(np.zeros((0, 0)), np.zeros((0, K.shape[1])), np.zeros((K.shape[0], 0)), K,
                       dt=like.dt))


def _operand(x, like: LinearSystem, n_out: int, n_in: int, what: str, role: str, why: str):
    """``x`` (a system, or a static gain made one) checked to share ``like``'s time base and to
    have ``n_out`` outputs and ``n_in`` inputs: (system, dt)."""
    g = _as_system(x, like, n_in, n_out)
    dt = same_dt(like.dt, g.dt, what)
    if (g.n_outputs, g.n_inputs) != (n_out, n_in):
        raise ModelError(f"{what}: {role} must be {n_out}×{n_in} ({why}), found "
                         f"{g.n_outputs}×{g.n_inputs}")
    return g, dt


def series(*systems: LinearSystem) -> LinearSystem:
    """u → G₁ → G₂ → … → y: ``G = G_k ⋯ G₂ G₁`` (the first system acts first).

    Inputs (names, units) come from the first system, outputs from the last; each output count
    must equal the next input count, and declared units must agree (``''`` and ``'1'`` match
    anything). Two SISO transfer functions give a transfer function (num₁num₂)/(den₁den₂);
    otherwise a state space with state [x₁; x₂]: ``A = [[A₁, 0], [B₂C₁, A₂]]``,
    ``B = [B₁; B₂D₁]``, ``C = [D₂C₁, C₂]``, ``D = D₂D₁``. Parameters of different systems are
    taken as independent.

    Parameters
    ----------
    *systems
        Two or more systems on one time base, in signal-flow order.

    Returns
    -------
    LinearSystem
        Inputs named and united as the first system's, outputs as the last's.

    Examples
    --------
    >>> from gripkit.lti import TransferFunction, series
    >>> g = series(TransferFunction([1.0], [1.0, 1.0]), TransferFunction([2.0], [1.0, 2.0]))
    >>> g.denominator().tolist(), float(g.dc_gain()[0, 0])
    ([1.0, 3.0, 2.0], 1.0)
    """
    if len(systems) < 2:
        raise ModelError(f"series: expected at least two systems, found {len(systems)}")
    out = systems[0]
    for nxt in systems[1:]:
        out = _series2(out, nxt)
    return out


def _series2(g1, g2):
    dt = same_dt(g1.dt, g2.dt, "series")
    if g1.n_outputs != g2.n_inputs:
        raise ModelError(f"series: the first system has {g1.n_outputs} outputs but the second "
                         f"{g2.n_inputs} inputs")
    _check_units(g1.output_units, g2.input_units, "series")
    return _connected(g1, g2, dict(dt=dt, inputs=g1.inputs, outputs=g2.outputs,
                                   input_units=g1.input_units, output_units=g2.output_units,
                                   meta={}), _connect.tf_series, _connect.ss_series)


def _connected(g1, g2, sig, tf_op, ss_op):
    """The interconnection of ``g1`` and ``g2`` with signals ``sig``: a SISO transfer function
    by ``tf_op`` on their (num, den) when both are SISO transfer functions, else a state space
    by ``ss_op`` on their realisations' arrays (state [x₁; x₂]); the covariance pushed
    through either map."""
    if _both_siso_tf(g1, g2):
        return _siso_tf_op(tf_op, g1, g2, sig)
    s1, s2 = g1.to_ss(minimal=False), g2.to_ss(minimal=False)
    arrs, unc = push(ss_op, [s1._arrays(), s2._arrays()], [s1.uncertainty, s2.uncertainty])
    return StateSpace(*arrs, **sig, states=_joined(s1.states, s2.states), uncertainty=unc)


def _joined(a, b):
    names = tuple(a) + tuple(b)
    return names if len(set(names)) == len(names) else None


def _siso_tf_op(op, g1, g2, sig):
    """A SISO transfer function from a polynomial operation on two (num, den) pairs, stored
    form (padded, monic); the covariance goes through the whole map, normalisation included."""
    def fn(n1, d1, n2, d2):
        n, d = op(n1[0, 0], d1[0, 0], n2[0, 0], d2[0, 0])
        L = max(n.size, d.size)
        n, d = np.pad(n, (L - n.size, 0)), np.pad(d, (L - d.size, 0))
        lead = d[np.flatnonzero(d)[0]]
        return (n / lead).reshape(1, 1, L), (d / lead).reshape(1, 1, L)

    arrs, unc = push(fn, [g1._arrays(), g2._arrays()], [g1.uncertainty, g2.uncertainty])
    return TransferFunction(arrs[0], arrs[1], **sig, uncertainty=unc)


def parallel(g1: LinearSystem, g2: LinearSystem) -> LinearSystem:
    """``G₁ + G₂``: both driven by the same inputs, outputs added (names from G₁).

    Two SISO transfer functions give (n₁d₂ + n₂d₁)/(d₁d₂); otherwise a state space with
    ``A = diag(A₁, A₂)``, ``B = [B₁; B₂]``, ``C = [C₁, C₂]``, ``D = D₁ + D₂``.

    Parameters
    ----------
    g1, g2
        Systems of the same shape and time base; ``g2`` may be a static gain.

    Returns
    -------
    LinearSystem
        Inputs and outputs named and united as ``g1``'s.

    Examples
    --------
    >>> from gripkit.lti import TransferFunction, parallel
    >>> g = parallel(TransferFunction([1.0], [1.0, 1.0]), TransferFunction([1.0], [1.0, 2.0]))
    >>> g.numerator().tolist(), g.denominator().tolist()
    ([2.0, 3.0], [1.0, 3.0, 2.0])
    """
    g2, dt = _operand(g2, g1, g1.n_outputs, g1.n_inputs, "parallel", "g2", "the shape of g1")
    _check_units(g1.input_units, g2.input_units, "parallel inputs")
    _check_units(g2.output_units, g1.output_units, "parallel outputs")
    return _connected(g1, g2, g1._signals(dt=dt, meta={}), _connect.tf_parallel,
                      _connect.ss_parallel)


def feedback(plant: LinearSystem, controller=1.0, sign: float = -1.0) -> LinearSystem:
    """Closed loop y = G e, e = r + sign·K y (``sign=-1``: negative feedback):
    ``T = (I − sign·G K)⁻¹ G``, inputs r and outputs y named as the plant's.

    Two SISO transfer functions give ``n_G d_K / (d_G d_K − sign n_G n_K)``; otherwise a state
    space (:func:`gripkit.lti._connect.ss_feedback`). ``controller`` may be a static gain.
    An algebraic loop with I − sign·D_G D_K singular raises ModelError.

    Parameters
    ----------
    plant
        G, p outputs and m inputs.
    controller
        K (m outputs, p inputs) in the feedback path, or a static gain (scalar or matrix).
    sign
        −1 for negative feedback, +1 for positive.

    Returns
    -------
    LinearSystem
        Inputs r and outputs y, named and united as the plant's.

    Examples
    --------
    >>> from gripkit.lti import TransferFunction, feedback
    >>> t = feedback(TransferFunction([4.0], [1.0, 1.0, 0.0]))    # 4/(s² + s + 4)
    >>> t.denominator().tolist(), float(t.dc_gain()[0, 0])
    ([1.0, 1.0, 4.0], 1.0)
    """
    if sign not in (1, -1, 1.0, -1.0):
        raise ModelError(f"sign: expected -1 (negative feedback) or +1, found {sign!r}")
    K, dt = _operand(controller, plant, plant.n_inputs, plant.n_outputs, "feedback",
                     "the controller", "plant outputs → plant inputs")
    _check_units(plant.output_units, K.input_units, "feedback")
    return _connected(plant, K, plant._signals(dt=dt, meta={}),
                      lambda n, d, nk, dk: _connect.tf_feedback(n, d, nk, dk, sign),
                      lambda *a: _connect.ss_feedback(*a, sign=sign))
