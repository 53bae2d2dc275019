"""The preprocessing of a joint log for inverse-dynamics identification
(:func:`gripkit.sysid.rigid_body.dynamics.identify_dynamics`): the columns of a
:class:`~gripkit.signals.Trajectory` through the IDIM-LS signal chain
(:func:`gripkit.sysid.rigid_body.friction.idim_samples`: one zero-phase Butterworth filter on
positions, or measured velocities, and efforts; central differences; the filter's edges cut;
decimation) and the row weights of the fit.

Row weights: a joint's rows count (1) where it moves faster than 2 % of its peak speed, outside
the guard band of its velocity reversals (where Coulomb friction switches sign and the filtered
velocity smears the switch); elsewhere 0. A joint that never moves identifies nothing and is an
:class:`~gripkit.errors.UnidentifiableError`.

This is what ``gripkit identify dynamics`` runs between reading the log and the fit.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import DataError, UnidentifiableError
from ...signals.trajectory import Trajectory
from .friction import IdimSamples, check_effort_scale, idim_samples

__all__ = ["DynamicsData", "dynamics_data", "SLOW_FRACTION"]

#: rows of a joint slower than this fraction of its peak speed carry no friction sign: weight 0
SLOW_FRACTION = 0.02


@dataclass(frozen=True)
class DynamicsData:
    """Filtered, differentiated and decimated joint states and efforts, and the row weights.

    ``samples``: the IDIM-LS chain's :class:`~gripkit.sysid.rigid_body.friction.IdimSamples`
    (cutoff, decimation, effort, notes, reversal bands); ``q``, ``qd``, ``qdd``: (M, n) joint
    positions, velocities and accelerations (from measured velocities when given); ``weights``:
    (M, n) 1/0 row weights."""

    samples: IdimSamples
    q: np.ndarray
    qd: np.ndarray
    qdd: np.ndarray
    weights: np.ndarray

    @property
    def effort(self) -> np.ndarray:
        return self.samples.effort

    @property
    def t(self) -> np.ndarray:
        """Time (s) of the decimated rows, from 0."""
        return np.arange(self.q.shape[0]) * self.samples.decimation * self.samples.dt


def dynamics_data(data: Trajectory, joints, position, effort, velocity=None, *,
                  effort_scale: float = 1.0, cutoff: float | None = None,
                  decimate: int | None = None) -> DynamicsData:
    """The joint log ``data`` ready for :func:`~.dynamics.identify_dynamics`: ``position``,
    ``effort`` and (optional) ``velocity`` are column names, one per joint of ``joints`` in its
    order; efforts are ``effort_scale`` × the columns (e.g. k_t for a current); ``cutoff`` (Hz)
    and ``decimate`` default as in :func:`~.friction.idim_samples`."""
    if not isinstance(data, Trajectory):
        raise DataError(f"data: expected a gripkit Trajectory, found {type(data).__name__}",
                        hint="use gripkit.io.load(path)")
    for what, cols in (("position", position), ("effort", effort), ("velocity", velocity)):
        if cols is not None and len(cols) != len(joints):
            raise DataError(f"{what}: {len(cols)} column(s) {list(cols)} for the {len(joints)} "
                            f"actuated joints {', '.join(joints)}",
                            hint="give one column per joint, in that order")
    check_effort_scale(effort_scale, "effort_scale")
    dt = data.require_uniform(why="inverse-dynamics identification (filtering and "
                                  "differentiation)")
    P = np.column_stack([data[c] for c in position])
    E = np.column_stack([data[c] for c in effort]) * effort_scale
    st = idim_samples(P, E, dt=dt, cutoff=cutoff, decimation=decimate)
    q, qd, qdd = st.position, st.velocity, st.acceleration
    if velocity is not None:  # measured velocities through the same filter and decimation
        sv = idim_samples(np.column_stack([data[c] for c in velocity]), E, dt=dt,
                          cutoff=st.cutoff, decimation=st.decimation)
        qd, qdd = sv.position, sv.velocity
    weights = _moving_rows(qd, st, joints, data.meta.get("source") or "the data")
    return DynamicsData(st, q, qd, qdd, weights)


def _moving_rows(qd, st: IdimSamples, joints, source: str) -> np.ndarray:
    """Row weights 1/0 (module doc); a joint that never moves is an error."""
    vmax = np.max(np.abs(qd), axis=0)
    still = [j for j, v in zip(joints, vmax) if v == 0]
    if still:
        raise UnidentifiableError(f"joint(s) {', '.join(still)} never move in {source}",
                                  hint="excite every joint (gripkit excitation fourier)")
    return ((np.abs(qd) > SLOW_FRACTION * vmax) & ~st.near_reversal).astype(np.float64)
