"""The simulation-model base class: immutable parameters, pure numba kernels, Trajectory results.

A model subclass declares its signals and implements one method, ``_simulate_batch``, which calls
a module-level numba kernel::

    class MassSpringDamper(Model):
        inputs = (Signal("F", "N", "applied force"),)
        outputs = (Signal("x", "m", "position"),)
        states = (Signal("x", "m", "position"), Signal("v", "m/s", "velocity"))
        def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
            _msd_batch(thetas, u, dt, substeps, x0, y)      # @njit(parallel=True) kernel
        def modes(self, theta):
            m, b, k = theta
            wn = (k / m) ** 0.5
            return [(wn, b / (2 * (k * m) ** 0.5))]

``simulate`` returns a :class:`Trajectory`; ``simulate_batch`` runs many parameter vectors against
one input in parallel (``prange``) and is what the grey-box engine and the batch runner use.
Before integrating, the step is checked against ``modes`` (:mod:`gripkit.sim.steps`): unstable
steps are refused and internal substeps are chosen so every mode is resolved.
"""

from __future__ import annotations

import abc
import inspect
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np

from ..arguments import check_keywords, entry_point, keyword_names
from ..consistency import Finding, warn_inconsistent
from ..errors import ArgumentError, ParameterError, SimulationError
from ..params import ParameterSet
from ..signals.trajectory import Trajectory
from .steps import check_step, substeps_for

__all__ = ["Signal", "Model", "simulate"]


@dataclass(frozen=True)
class Signal:
    """A named input, output or state with its SI unit."""

    name: str
    unit: str
    doc: str = ""


class Model(abc.ABC):
    """Base class of gripkit's simulation models. See the module docstring."""

    name: str = "model"
    description: str = ""
    inputs: tuple[Signal, ...] = ()
    outputs: tuple[Signal, ...] = ()
    states: tuple[Signal, ...] = ()
    #: integration scheme of the kernel: 'rk4', 'semi-implicit' or 'zoh' (exact discretisation)
    integrator: str = "rk4"

    def __init__(self, parameters: ParameterSet, *, check: bool = True):
        if not isinstance(parameters, ParameterSet):
            raise ParameterError(f"{type(self).__name__}: expected a ParameterSet, found "
                                 f"{type(parameters).__name__}")
        self.parameters = parameters
        if check:
            warn_inconsistent(self.consistency_checks())

    # --- to override -------------------------------------------------------------------------
    @abc.abstractmethod
    def _simulate_batch(self, thetas: np.ndarray, u: np.ndarray, dt: float, substeps: int,
                        x0: np.ndarray, y: np.ndarray) -> None:
        """Simulate every row of ``thetas`` (P, n_params) against ``u`` (N, n_inputs) from
        ``x0`` (P, n_states), ``substeps`` internal steps per sample, writing ``y`` (P, N,
        n_outputs)."""

    def modes(self, theta: np.ndarray) -> list[tuple[float, float]]:
        """Natural frequencies (rad/s) and damping ratios of the model's modes at ``theta``."""
        return []

    def initial_state(self, theta: np.ndarray) -> np.ndarray:
        return np.zeros(len(self.states))

    def consistency_checks(self) -> list[Finding]:
        return []

    # --- shared machinery ----------------------------------------------------------------------
    def with_parameters(self, check: bool = True, **values) -> "Model":
        """A copy with some parameter values replaced (``'1.37 mg'`` strings are parsed)."""
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        new.parameters = self.parameters.replace(**values)
        if check:
            warn_inconsistent(new.consistency_checks())
        return new

    def theta(self, params: ParameterSet | Mapping[str, float] | None = None) -> np.ndarray:
        """The full parameter vector (SI, in ``parameters.names`` order)."""
        if params is None:
            return self.parameters.vector()
        if isinstance(params, ParameterSet):
            return params.vector(self.parameters.names)
        return self.parameters.replace(**params).vector()

    def _check_thetas(self, thetas: np.ndarray) -> np.ndarray:
        thetas = np.ascontiguousarray(np.atleast_2d(np.asarray(thetas, dtype=np.float64)))
        n = len(self.parameters)
        if thetas.ndim != 2 or thetas.shape[1] != n:
            raise ParameterError(f"{self.name}: expected parameter vectors of length {n} "
                                 f"({', '.join(self.parameters.names)}), found "
                                 f"shape {thetas.shape}")
        if not np.isfinite(thetas).all():
            raise ParameterError(f"{self.name}: parameter vectors contain NaN or inf")
        lo, hi = self.parameters.bounds_arrays()
        bad = (thetas < lo) | (thetas > hi)
        if bad.any():
            i, j = map(int, np.argwhere(bad)[0])
            p = self.parameters[self.parameters.names[j]]
            raise ParameterError(f"{self.name}: {p.name} = {thetas[i, j]:g} {p.unit} "
                                 "is outside its "
                                 f"bounds [{lo[j]:g}, {hi[j]:g}] (parameter vector {i})")
        return thetas

    def _inputs_array(self, u, dt: float | None) -> tuple[np.ndarray, float, float]:
        names = [s.name for s in self.inputs]
        t0 = 0.0
        if isinstance(u, Trajectory):
            dt_u = u.require_uniform(why=f"simulating {self.name}")
            arr = u.as_array(*names)
            t0 = float(u.t[0])
            if dt is not None and abs(dt / dt_u - 1.0) > 1e-6:
                raise SimulationError(f"dt={dt} s given, but the input trajectory is sampled "
                                      f"every {dt_u:g} s")
            dt = dt_u
        elif isinstance(u, Mapping):
            missing = [n for n in names if n not in u]
            if missing:
                raise SimulationError(f"{self.name}: inputs "
                                      f"{missing} missing", hint=f"inputs are {names}")
            arr = np.column_stack([_float_array(u[n], f"input {n!r}") for n in names])
        else:
            arr = _float_array(u, "u")
            arr = arr.reshape(-1, 1) if arr.ndim == 1 else arr
            if arr.ndim != 2 or arr.shape[1] != len(names):
                raise SimulationError(f"{self.name}: expected inputs of shape (N, "
                                      f"{len(names)}) for {names}, "
                                      f"found {np.shape(u)}")
        if dt is None:
            raise SimulationError(f"{self.name}: give the sample time dt (or a Trajectory input)")
        if isinstance(dt, bool) or not isinstance(dt, (int, float, np.integer, np.floating)):
            raise ArgumentError(f"dt: expected a sample time in seconds (a number), found "
                                f"{type(dt).__name__} {dt!r:.40}")
        if not (np.isfinite(dt) and dt > 0):
            raise SimulationError(f"dt: expected a positive number of seconds, found {dt!r}")
        if not np.isfinite(arr).all():
            raise SimulationError(f"{self.name}: inputs contain NaN or inf")
        return np.ascontiguousarray(arr), float(dt), t0

    def substeps(self, dt: float, thetas: np.ndarray) -> int:
        """Internal steps per sample so that every mode of every parameter vector is resolved."""
        if self.integrator == "zoh":
            return 1
        n = 1
        for th in thetas:
            n = max(n, substeps_for(dt, self.modes(th), self.integrator))
        return n

    def simulate_batch(self, thetas, u, dt: float | None = None, x0: np.ndarray | None = None,
                       substeps: int | None = None, out: np.ndarray | None = None) -> np.ndarray:
        """Outputs (P, N, n_outputs) for parameter vectors ``thetas`` (P, n_params). ``out``: a
        preallocated float64 array of that shape to write into (a loop that simulates many times
        saves the allocation)."""
        thetas = self._check_thetas(thetas)
        arr, dt, _ = self._inputs_array(u, dt)
        return self._simulate_checked(thetas, arr, dt, x0, substeps, out)

    def _simulate_checked(self, thetas: np.ndarray, arr: np.ndarray, dt: float, x0, substeps,
                          out) -> np.ndarray:
        """:meth:`simulate_batch` on parameter vectors and inputs already checked."""
        if substeps is None:
            substeps = self.substeps(dt, thetas)
        elif int(substeps) != substeps or substeps < 1:
            raise SimulationError(f"substeps: expected a positive integer, found {substeps!r}")
        if self.integrator != "zoh":
            for th in thetas:
                check_step(dt / substeps, self.modes(th), self.integrator, what=self.name)
        P = thetas.shape[0]
        if x0 is None:
            x0 = (np.stack([self.initial_state(th) for th in thetas]) if len(self.states)
                  else np.zeros((P, 0)))
        x0 = (np.ascontiguousarray(np.broadcast_to(np.asarray(x0, dtype=np.float64),
                                                   (P, len(self.states)))))
        shape = (P, arr.shape[0], len(self.outputs))
        if out is None:
            y = np.empty(shape)
        elif out.shape != shape or out.dtype != np.float64 or not out.flags.c_contiguous:
            raise SimulationError("out: expected a C-contiguous float64 array of shape "
                                  f"{shape}, found "
                                  f"{out.dtype} {out.shape}")
        else:
            y = out
        self._simulate_batch(thetas, arr, dt, int(substeps), x0.copy(), y)
        # one pass without a temporary; the exact test only if the sum is not finite (overflow)
        if not np.isfinite(y.sum()) and not np.isfinite(y).all():
            raise SimulationError(f"{self.name}: the simulation diverged (non-finite outputs)",
                                  hint="check the parameters and the input amplitude")
        return y

    def simulate(self, u, *, dt: float | None = None, x0: np.ndarray | None = None,
                 params: ParameterSet | Mapping[str, float] | None = None,
                 substeps: int | None = None) -> Trajectory:
        """Simulate one parameter set; returns a Trajectory of the inputs and outputs."""
        arr, dt, t0 = self._inputs_array(u, dt)
        y = self._simulate_checked(self._check_thetas(self.theta(params)[None, :]), arr, dt,
                                   None if x0 is None else np.asarray(x0)[None, :], substeps,
                                   None)[0]
        t = np.arange(arr.shape[0], dtype=np.float64)
        t *= dt
        t += t0
        # the output channels are column views of the simulated block, which nothing else
        # references (no copy); the inputs are copied (arr may be the caller's array). Both were
        # checked finite (simulate_batch, _inputs_array).
        u_rows = np.array(arr.T)
        ch = {s.name: u_rows[i] for i, s in enumerate(self.inputs)}
        ch.update({s.name: y[:, i] for i, s in enumerate(self.outputs)})
        units = {s.name: s.unit for s in (*self.inputs, *self.outputs)}
        return Trajectory._from_checked(t, ch, units, {"dt": dt, "model": self.name})

    def __repr__(self) -> str:
        return f"{type(self).__name__}({self.parameters!r})"


def _float_array(values, name: str) -> np.ndarray:
    try:
        return np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ArgumentError(f"{name}: expected numbers (an array of float), found "
                            f"{type(values).__name__} "
                            f"{values!r:.40}") from None


@entry_point
def simulate(model: Model, u, **kwargs) -> Trajectory:
    """Simulate ``model`` for inputs ``u`` (Trajectory, mapping or array with ``dt=``); keywords as
    :meth:`Model.simulate` (``dt``, ``x0``, ``params``, ``substeps``).

    Raises :class:`~gripkit.errors.ArgumentError` for a ``model`` that cannot be simulated or an
    unknown keyword."""
    if not callable(getattr(model, "simulate", None)):
        raise ArgumentError(f"simulate(): model must be a gripkit model (gripkit.sim.Model), found "
                            f"{type(model).__name__} {model!r:.40}",
                            hint="build one, e.g. gripkit.zoo.build('tsfm-left') or "
                                 "gripkit.models.MassSpringDamper()")
    method = model.simulate
    if not any(p.kind is inspect.Parameter.VAR_KEYWORD
               for p in inspect.signature(method).parameters.values()):
        check_keywords(kwargs, keyword_names(method, exclude=("u",)), f"simulate({model.name})"
                       if hasattr(model, "name") else "simulate()")
    return method(u, **kwargs)
