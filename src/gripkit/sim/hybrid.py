"""Hybrid (switched) linear dynamics: free ↔ constrained motion through a gap function, with the
switching instant located inside the sample step.

A :class:`HybridSystem` is piecewise affine: in mode q,

    ẋ = A_q x + B_q u + e_q,        y = C_q x + D_q u + f_q,

with the input u held over each sample (zero-order hold). A :class:`Guard` of mode q is an affine
function g(x, u) = G·x + H·u + c; the system stays in q while g ≥ 0 and switches to the guard's
target mode where g becomes negative. A contact (``001_0b92a7da96e7aa46.txt`` Fig. 5 b→d) is the
guard "gap = x_part − y_C" of the free mode; release is the guard "penetration + pull-off/k" of
the constrained mode.

Event location inside the step. Each mode is discretised exactly (ZOH) for the full step h and
for its dyadic fractions h/2, …, h/2^K (:func:`gripkit.sim.integrators.zoh_levels`). A step
first tries the whole h in the current mode (one matrix-vector product: the common case). If a
guard is crossed at the end, the step is retried in halves, quarters, … — aligned dyadic blocks —
until the crossing is bracketed within one tick h/2^K; the state there (exact solution of the old
mode) starts the new mode, which runs the rest of the step exactly. The contact force is therefore
switched on within h/2^K of the true instant (12 ns at 20 kHz with K = 12), never a sample late:
no spurious force at the transition, no energy injected by a late stiff contact. Several events in
one step are handled the same way (at most ``MAX_EVENTS_PER_STEP``; more is reported as chattering).

:func:`HybridSystem.simulate_reference` integrates the same system with fine-step RK4 and a guard
check after every substep — the reference the exact scheme is tested against.
"""

from __future__ import annotations

from collections import namedtuple
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numba
import numpy as np

from ..errors import ModelError, SimulationError
from ..signals.trajectory import Trajectory
from .integrators import modes_of, rk4_lti_step, zoh_levels
from .steps import check_step

__all__ = ["Mode", "Guard", "HybridSystem", "DiscreteHybrid", "HybridResult", "pwa_step",
           "pwa_output",
           "DEFAULT_LEVELS", "MAX_EVENTS_PER_STEP"]

#: dyadic levels: events are located within dt / 2**DEFAULT_LEVELS
DEFAULT_LEVELS = 12
#: more switches than this inside one sample step is reported as chattering (Zeno behaviour)
MAX_EVENTS_PER_STEP = 16


def _arr(x, shape, name):
    a = np.asarray(x, dtype=np.float64)
    if a.shape != shape:
        raise ModelError(f"{name}: expected shape {shape}, found {a.shape}")
    if not np.isfinite(a).all():
        raise ModelError(f"{name} contains NaN or inf")
    return a


@dataclass(frozen=True)
class Mode:
    """One mode: ẋ = A x + B u + e, y = C x + D u + f (shapes (n,n), (n,m), (n,), (p,n), (p,m),
    (p,))."""

    name: str
    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray | None = None
    e: np.ndarray | None = None
    f: np.ndarray | None = None


@dataclass(frozen=True)
class Guard:
    """Leave mode ``source`` for ``target`` when G·x + H·u + c < 0."""

    source: str
    target: str
    G: np.ndarray
    H: np.ndarray | None = None
    c: float = 0.0
    name: str = ""


@dataclass(frozen=True)
class DiscreteHybrid:
    """Arrays for :func:`pwa_step` (inputs augmented with a trailing constant 1 for e, f, c).

    Phi (Q, K+1, n, n), Gam (Q, K+1, n, m+1): level j steps dt·2^(j−K); C (Q, p, n),
    D (Q, p, m+1); G (Q, J, n), H (Q, J, m+1); target (Q, J); n_guards (Q,).
    """

    Phi: np.ndarray
    Gam: np.ndarray
    C: np.ndarray
    D: np.ndarray
    G: np.ndarray
    H: np.ndarray
    target: np.ndarray
    n_guards: np.ndarray
    dt: float
    levels: int


@dataclass(frozen=True)
class HybridResult:
    """A hybrid simulation: ``trajectory`` (inputs, outputs and a ``mode`` channel), the state
    before each sample (N, n), the mode in force during each sample (N,), and the events as rows
    (time s, from-mode, to-mode)."""

    trajectory: Trajectory
    states: np.ndarray
    modes: np.ndarray
    events: list[tuple[float, str, str]] = field(default_factory=list)


#: the switching surfaces as the kernels take them: G (Q, J, n), H (Q, J, m+1), target (Q, J)
#: and n_guards (Q,) of :class:`DiscreteHybrid`
PWAGuards = namedtuple("PWAGuards", "G H target n_guards")
#: the scratch of :func:`pwa_step`: the trial state (n,) and the events' step fractions and
#: target modes (MAX_EVENTS_PER_STEP each); any record with these fields will do
#: (``gripkit.systems.tsfm.gripper.GripperWork``)
EventWork = namedtuple("EventWork", "xt ev_frac ev_to")
#: what :func:`_hybrid_run` writes: outputs (N, p), states (N, n), modes (N,) and event rows
HybridOut = namedtuple("HybridOut", "y xs modes ev_rows")


@numba.njit(cache=True, inline="always")
def first_crossed_guard(G, H, n_guards, mode, x, u):  # pragma: no cover - compiled
    """Index of the first guard of ``mode`` with G·x + H·u < 0 (u ends with the constant 1 that
    carries c), or −1. Inlined: indexes the stacks in place, no slices."""
    for g in range(n_guards[mode]):
        acc = 0.0
        for k in range(x.shape[0]):
            acc += G[mode, g, k] * x[k]
        for k in range(u.shape[0]):
            acc += H[mode, g, k] * u[k]
        if acc < 0.0:
            return g
    return -1


@numba.njit(cache=True, inline="always")
def pwa_step(x, mode, u, Phi, Gam, G, H, target, n_guards, K, work):  # pragma: no cover
    """Advance ``x`` (n,) in place over one sample step with the held input ``u`` (m+1,, last
    entry 1). Returns (new mode, number of events); event i happened at fraction
    ``work.ev_frac[i]`` of the step, into mode ``work.ev_to[i]`` (arrays of capacity
    MAX_EVENTS_PER_STEP; ``work`` as :data:`EventWork`). See the module docstring for the dyadic
    event location.

    Speed: the function is inlined into its callers and indexes the matrix stacks in place (a
    call or a slice per step costs reference counting); the common sizes (4 or 6 states with 2
    inputs + 1) have their matrix-vector product written with constant trip counts, which LLVM
    unrolls (the measurements: docs/performance.md)."""
    xt, ev_frac, ev_to = work.xt, work.ev_frac, work.ev_to
    n = x.shape[0]
    m = u.shape[0]
    kind = 1 if (n == 4 and m == 3) else (2 if (n == 6 and m == 3) else 0)
    total = 1 << K
    p = 0
    nev = 0
    while p < total:
        if p == 0:
            j = K
        else:
            j = 0
            q = p
            while (q & 1) == 0:
                q >>= 1
                j += 1
        while True:
            if kind == 1:
                for i in range(4):
                    acc = (Gam[mode, j, i, 0] * u[0] + Gam[mode, j, i,
                                                           1] * u[1] + Gam[mode, j, i, 2] * u[2])
                    for k in range(4):
                        acc += Phi[mode, j, i, k] * x[k]
                    xt[i] = acc
            elif kind == 2:
                for i in range(6):
                    acc = (Gam[mode, j, i, 0] * u[0] + Gam[mode, j, i,
                                                           1] * u[1] + Gam[mode, j, i, 2] * u[2])
                    for k in range(6):
                        acc += Phi[mode, j, i, k] * x[k]
                    xt[i] = acc
            else:
                for i in range(n):
                    acc = 0.0
                    for k in range(n):
                        acc += Phi[mode, j, i, k] * x[k]
                    for k in range(m):
                        acc += Gam[mode, j, i, k] * u[k]
                    xt[i] = acc
            hit = (first_crossed_guard(G, H, n_guards, mode, xt,
                                       u) if nev < MAX_EVENTS_PER_STEP else -1)
            if hit < 0:
                for i in range(n):
                    x[i] = xt[i]
                p += 1 << j
                break
            if j == 0:
                for i in range(n):
                    x[i] = xt[i]
                p += 1
                new = target[mode, hit]
                if nev < ev_frac.shape[0]:
                    ev_frac[nev] = p / total
                    ev_to[nev] = new
                nev += 1
                mode = new
                break
            j -= 1
    return mode, nev


@numba.njit(cache=True)
def pwa_output(C, D, mode, x, u, y):  # pragma: no cover - compiled
    """y = C[mode] x + D[mode] u (C (Q, p, n), D (Q, p, m+1))."""
    for i in range(C.shape[1]):
        acc = 0.0
        for j in range(x.shape[0]):
            acc += C[mode, i, j] * x[j]
        for j in range(u.shape[0]):
            acc += D[mode, i, j] * u[j]
        y[i] = acc


@numba.njit(cache=True)
def _hybrid_run(Phi, Gam, C, D, guards, K, u, x, mode, out):  # pragma: no cover - compiled
    """The dyadic simulation of :meth:`HybridSystem.simulate` (``guards``: :data:`PWAGuards`)
    into ``out`` (:data:`HybridOut`); returns (event rows, first sample of a Zeno step or −1)."""
    G, H, target, n_guards = guards
    y, xs, modes, ev_rows = out
    N = u.shape[0]
    m1 = u.shape[1] + 1
    ua = np.empty(m1)
    ua[m1 - 1] = 1.0
    xt = np.empty(x.shape[0])
    ev_frac = np.empty(MAX_EVENTS_PER_STEP)
    ev_to = np.empty(MAX_EVENTS_PER_STEP, dtype=np.int64)
    work = EventWork(xt, ev_frac, ev_to)
    nrow = 0
    zeno = -1
    for k in range(N):
        for j in range(m1 - 1):
            ua[j] = u[k, j]
        for i in range(x.shape[0]):
            xs[k, i] = x[i]
        pwa_output(C, D, mode, x, ua, y[k])
        modes[k] = mode
        old = mode
        mode, nev = pwa_step(x, mode, ua, Phi, Gam, G, H, target, n_guards, K, work)
        if nev >= MAX_EVENTS_PER_STEP and zeno < 0:
            zeno = k
        for e in range(min(nev, MAX_EVENTS_PER_STEP)):
            if nrow < ev_rows.shape[0]:
                ev_rows[nrow, 0] = k + ev_frac[e]
                ev_rows[nrow, 1] = old
                ev_rows[nrow, 2] = ev_to[e]
            old = ev_to[e]
            nrow += 1
    return nrow, zeno


@numba.njit(cache=True)
def _hybrid_rk4(A, B, C, D, guards, u, h, nsub, x, mode, y, modes):  # pragma: no cover - compiled
    """The fine-step RK4 reference of :meth:`HybridSystem.simulate_reference` (``guards``:
    :data:`PWAGuards`)."""
    G, H, target, n_guards = guards
    N = u.shape[0]
    n = x.shape[0]
    m1 = u.shape[1] + 1
    ua = np.empty(m1)
    ua[m1 - 1] = 1.0
    k1 = np.empty(n)
    k2 = np.empty(n)
    k3 = np.empty(n)
    k4 = np.empty(n)
    tmp = np.empty(n)
    for k in range(N):
        for j in range(m1 - 1):
            ua[j] = u[k, j]
        pwa_output(C, D, mode, x, ua, y[k])
        modes[k] = mode
        for _ in range(nsub):
            rk4_lti_step(A[mode], B[mode], x, ua, h, k1, k2, k3, k4, tmp)
            g = first_crossed_guard(G, H, n_guards, mode, x, ua)
            if g >= 0:
                mode = target[mode, g]


class HybridSystem:
    """A piecewise-affine hybrid system (see the module docstring).

    Parameters
    ----------
    modes
        The modes, all with the same n states, m inputs and p outputs.
    guards
        Transitions between modes (by mode name).
    inputs, outputs, states
        Signal names (optional ``{name: unit}`` in ``units``).

    Example: a unit mass on a spring hitting a stiff wall at x = 1 (a contact through a gap)::

        free = Mode("free", A=[[0, 1], [-1, 0]], B=[[0], [1]], C=[[1, 0]])
        wall = Mode("contact", A=[[0, 1], [-101, 0]], B=[[0], [1]], C=[[1, 0]], e=[0, 100])
        sys = HybridSystem([free, wall], [Guard("free", "contact", G=[-1, 0], c=1.0),
                                          Guard("contact", "free", G=[1, 0], c=-1.0)])
    """

    def __init__(self, modes: Sequence[Mode], guards: Sequence[Guard] = (), *,
                 inputs: Sequence[str] = (), outputs: Sequence[str] = (),
                 states: Sequence[str] = (),
                 units: Mapping[str, str] | None = None, name: str = "hybrid"):
        if not modes:
            raise ModelError("a hybrid system needs at least one mode")
        A0 = np.atleast_2d(np.asarray(modes[0].A, dtype=np.float64))
        n = A0.shape[0]
        B0 = np.asarray(modes[0].B, dtype=np.float64).reshape(n, -1)
        m = B0.shape[1]
        C0 = np.atleast_2d(np.asarray(modes[0].C, dtype=np.float64))
        p = C0.shape[0]
        self.names = tuple(md.name for md in modes)
        if len(set(self.names)) != len(self.names):
            raise ModelError(f"mode names must be unique, found {self.names}")
        Q = len(modes)
        self.A = np.empty((Q, n, n))
        self.B = np.empty((Q, n, m + 1))
        self.C = np.empty((Q, p, n))
        self.D = np.empty((Q, p, m + 1))
        for q, md in enumerate(modes):
            self.A[q] = _arr(md.A, (n, n), f"mode {md.name!r}: A")
            Bq = np.asarray(md.B, dtype=np.float64)
            self.B[q, :, :m] = (_arr(Bq.reshape(n, m) if Bq.size == n * m else Bq, (n, m),
                                     f"mode {md.name!r}: B"))
            self.B[q, :, m] = 0.0 if md.e is None else _arr(md.e, (n,), f"mode {md.name!r}: e")
            self.C[q] = _arr(np.atleast_2d(md.C), (p, n), f"mode {md.name!r}: C")
            self.D[q, :, :m] = (0.0 if md.D is None else _arr(np.atleast_2d(md.D), (p, m),
                                                              f"mode {md.name!r}: D"))
            self.D[q, :, m] = 0.0 if md.f is None else _arr(md.f, (p,), f"mode {md.name!r}: f")
        J = max([sum(1 for g in guards if g.source == nm) for nm in self.names] + [1])
        self.G = np.zeros((Q, J, n))
        self.H = np.zeros((Q, J, m + 1))
        self.target = np.zeros((Q, J), dtype=np.int64)
        self.n_guards = np.zeros(Q, dtype=np.int64)
        for g in guards:
            for which in (g.source, g.target):
                if which not in self.names:
                    raise ModelError(f"guard {g.name or (g.source + '->' + g.target)!r}: "
                                     f"no mode {which!r}",
                                     hint=f"modes: {', '.join(self.names)}")
            q = self.names.index(g.source)
            k = self.n_guards[q]
            self.G[q, k] = _arr(g.G, (n,), f"guard {g.source}->{g.target}: G")
            self.H[q, k, :m] = (0.0 if g.H is None else _arr(g.H, (m,),
                                                             f"guard {g.source}->{g.target}: H"))
            self.H[q, k, m] = float(g.c)
            self.target[q, k] = self.names.index(g.target)
            self.n_guards[q] += 1
        self.n_states, self.n_inputs, self.n_outputs = n, m, p
        self.inputs = tuple(inputs) or tuple(f"u{i}" for i in range(m))
        self.outputs = tuple(outputs) or tuple(f"y{i}" for i in range(p))
        self.states = tuple(states) or tuple(f"x{i}" for i in range(n))
        if (len(self.inputs), len(self.outputs), len(self.states)) != (m, p, n):
            raise ModelError(f"signal names: expected {m} inputs, {p} outputs, {n} states; found "
                             f"{len(self.inputs)}, {len(self.outputs)}, {len(self.states)}")
        self.units = dict(units or {})
        self.name = name

    def discretize(self, dt: float, levels: int = DEFAULT_LEVELS) -> DiscreteHybrid:
        """Exact ZOH matrices of every mode at the step ``dt`` and its dyadic fractions."""
        if not 0 <= int(levels) <= 30:
            raise ModelError(f"levels: expected 0..30, found {levels!r}")
        Phi, Gam = zoh_levels(self.A, self.B, dt, int(levels))
        return DiscreteHybrid(Phi, Gam, self.C, self.D, self.G, self.H, self.target, self.n_guards,
                              float(dt), int(levels))

    def _prepare(self, u, dt, x0, mode0):
        if isinstance(u, Trajectory):
            dt = u.require_uniform(why=f"simulating {self.name}")
            u = u.as_array(*self.inputs)
        u2 = np.ascontiguousarray(np.asarray(u, dtype=np.float64).reshape(len(u), -1))
        if u2.shape[1] != self.n_inputs:
            raise SimulationError(f"{self.name}: expected inputs of shape (N, {self.n_inputs}), "
                                  f"found {u2.shape}")
        if not np.isfinite(u2).all():
            raise SimulationError(f"{self.name}: inputs contain NaN or inf")
        if dt is None or not (np.isfinite(dt) and dt > 0):
            raise SimulationError(f"dt: expected a positive number of seconds, found {dt!r}")
        x = np.zeros(self.n_states) if x0 is None else np.array(x0, dtype=np.float64).reshape(-1)
        if x.shape != (self.n_states,):
            raise SimulationError(f"x0: expected {self.n_states} states, found shape {x.shape}")
        mode = self.names.index(mode0) if isinstance(mode0, str) else int(mode0)
        if not 0 <= mode < len(self.names):
            raise SimulationError(f"mode0: expected one of {self.names}, found {mode0!r}")
        return u2, float(dt), x, mode

    def _result(self, u2, dt, y, xs, modes, rows):
        t = np.arange(u2.shape[0]) * dt
        ch = {n: u2[:, i] for i, n in enumerate(self.inputs)}
        ch.update({n: y[:, i] for i, n in enumerate(self.outputs)})
        ch["mode"] = modes.astype(np.float64)
        tr = (Trajectory(t, ch, {k: v for k, v in self.units.items() if k in ch},
                         {"dt": dt, "model": self.name}))
        ev = [(float(r[0]) * dt, self.names[int(r[1])], self.names[int(r[2])]) for r in rows]
        return HybridResult(tr, xs, modes, ev)

    def simulate(self, u, dt: float | None = None, x0=None, mode0: str | int = 0,
                 levels: int = DEFAULT_LEVELS, max_events: int = 100000) -> HybridResult:
        """Exact simulation with in-step event location (inputs (N, m) held over each ``dt``)."""
        u2, dt, x, mode = self._prepare(u, dt, x0, mode0)
        d = self.discretize(dt, levels)
        N = u2.shape[0]
        y = np.empty((N, self.n_outputs))
        xs = np.empty((N, self.n_states))
        modes = np.empty(N, dtype=np.int64)
        rows = np.empty((max_events, 3))
        nrow, zeno = _hybrid_run(d.Phi, d.Gam, d.C, d.D, PWAGuards(d.G, d.H, d.target, d.n_guards),
                                 d.levels, u2, x, mode, HybridOut(y, xs, modes, rows))
        if zeno >= 0:
            raise SimulationError(f"{self.name}: more than {MAX_EVENTS_PER_STEP} mode "
                                  "switches inside the "
                                  f"step at t = {zeno * dt:.6g} s (chattering between modes)",
                                  hint="check the guards: leaving a mode must not "
                                       "immediately re-enter it")
        if not np.isfinite(y).all():
            raise SimulationError(f"{self.name}: the simulation diverged (non-finite outputs)")
        return self._result(u2, dt, y, xs, modes, rows[:min(nrow, max_events)])

    def simulate_reference(self, u, dt: float | None = None, x0=None, mode0: str | int = 0,
                           substeps: int = 1000) -> HybridResult:
        """Fine-step RK4 reference (``substeps`` per sample, guard checked after each substep).
        The substep is checked against every mode's natural frequencies (gripkit.sim.steps)."""
        u2, dt, x, mode = self._prepare(u, dt, x0, mode0)
        for q, name in enumerate(self.names):
            check_step(dt / substeps, modes_of(self.A[q]), "rk4", what=f"{self.name} mode {name!r}")
        N = u2.shape[0]
        y = np.empty((N, self.n_outputs))
        modes = np.empty(N, dtype=np.int64)
        _hybrid_rk4(self.A, self.B, self.C, self.D,
                    PWAGuards(self.G, self.H, self.target, self.n_guards), u2, dt / substeps,
                    int(substeps), x, mode, y, modes)
        ch = np.flatnonzero(np.diff(modes)) + 1
        rows = np.array([[k, modes[k - 1], modes[k]] for k in ch]).reshape(-1, 3)
        return self._result(u2, dt, y, np.full((N, self.n_states), np.nan), modes, rows)
