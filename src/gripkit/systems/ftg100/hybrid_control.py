"""Hybrid force/position control of an electrostatic microgripper arm (the future work of seed
``003_abd62b560633beaf.txt`` §IV): position control of the actuated arm before contact, force
control after it, a bumpless switch at contact detection, anti-windup at the actuator limits.

Controller (sampled at T_s = 50 µs, 20 kHz as in the seed), in actuator-force units — the
comb-drive force F_x = c_e V² is commanded and inverted to V = √(F_x/c_e) ∈ [0, V_max], which
linearises the quadratic actuator (eq 5) exactly:

* **approach (position mode)**: the tip reference ramps at ``approach_speed`` towards
  ``x_limit``; a PID on the tip position x_a (derivative on the error, so the ramp's velocity is fed
  forward) plus the static suspension force at the reference,
      u = PID_x(x_ref, x̂_a) + K_sa ξ + K₃ ξ³,   ξ = x_ref / D_a;
* **contact detection**: the measured force exceeds ``contact_threshold`` on ``confirm``
  consecutive samples;
* **grasp (force mode)**: a PI(D) on the measured force, the suspension force at the measured
  position, the lever-amplified force reference and damping injection on the tip velocity
  estimate v̂ (filtered difference of the position measurement) relative to the velocity the
  reference asks for,
      u = PID_F(F_ref, F̂) + K_sa ξ̂ + K₃ ξ̂³ + D_a F_ref − k_v (v̂ − Ḟ_ref/k_c),   ξ̂ = x̂_a / D_a,
  with F_ref starting from the force measured at the switch and moving to the command at a
  limited rate (a full-scale change in ``force_ramp``) through a first-order stage
  (``force_tau``): the held voltage then changes in small, even steps, which keeps the 35-60 kHz
  object mode (ball between the two tips, above the loop's bandwidth) quiet. k_c is the
  contact stiffness seen at the tip (≈ k2, the sensing arm, whatever k0 is);
* **bumpless switch**: at detection the force PID's integrator is set (:func:`pid_transfer`) so
  that its first output equals the last command;
* **anti-windup**: both PIDs saturate at [c_e V_min², c_e V_max²] (0-200 V) with
  back-calculation.

Kernels: :func:`hybrid_step` (one sample, scalar numba, parameters ``cp`` and state ``cs`` as
float arrays) and the closed-loop grasp simulation on
:class:`gripkit.systems.ftg100.model.FTG100Plant`
(:func:`simulate_hybrid_grasp`, :func:`grasp_batch`): the controller sees the force sensor reading
k2·x_b plus white noise of σ = 50 nN (the seed's resolution) and the tip position plus white noise
(σ = 1 nm, an interferometer as in the seed's experiments, assumed). Metrics per grasp: contact
and detection times, peak true contact force (checked after every RK4 substep, so impact spikes
between samples count), overshoot over the command, 2 % settling time measured from the first
contact, final error, largest voltage, and whether the damage threshold was crossed.
"""

from __future__ import annotations

import math
from collections import namedtuple
from dataclasses import asdict, dataclass, replace

import numba
import numpy as np

from ...control.pid import PID, PID_NPARAM, pid_step, pid_transfer
from ...errors import ConfigError, SimulationError
from ...params import ParameterSet
from ...progress import track
from ...signals.trajectory import Trajectory
from ...sim.noise import normal_draw
from .model import PO, FTG100Plant, advance_plant, plant_outputs, plant_parameters as _pp

__all__ = ["HybridForcePosition", "HybridController", "hybrid_step", "simulate_hybrid_grasp",
           "grasp_batch",
           "HybridGraspResult", "GraspBatch", "METRICS", "impact_speed_limit"]

# controller parameter layout
_TS, _PX, _PF = 0, 1, 1 + PID_NPARAM
_KV = 1 + 2 * PID_NPARAM
(_TFV, _VAPP, _XLIM, _FTH, _NCONF, _TAUF, _LEVER, _K1, _K3, _CE, _VMAX, _VMIN, _RAMP,
 _KC, _BUMP) = range(_KV + 1, _KV + 16)
_NCP = _BUMP + 1
# controller state layout
_MODE, _SX, _SF = 0, 1, 5
_VF, _XPREV, _STARTED, _XREF, _FREF, _COUNT, _UPREV, _KSW, _K, _FREF1 = range(9, 19)
_NCS = 19

#: names of the columns of :attr:`GraspBatch.metrics`
METRICS = ("t_contact", "t_switch", "peak_force", "overshoot_percent", "settling_time",
           "final_error",
           "max_voltage", "damage", "detected", "sat_fraction")
#: index of each metric in a row of ``met`` (``met[MX.peak_force]``), generated from METRICS
MX = namedtuple("MetricIndex", METRICS)(*range(len(METRICS)))


@numba.njit(cache=True)
def hybrid_step(cp, cs, x_meas, f_meas, f_cmd):  # pragma: no cover - compiled
    """One controller sample: returns the voltage for measured tip position ``x_meas`` (m), measured
    force ``f_meas`` (N) and commanded force ``f_cmd`` (N); updates ``cs`` (module docstring)."""
    ts = cp[_TS]
    px = cp[_PX:_PX + PID_NPARAM]
    pf = cp[_PF:_PF + PID_NPARAM]
    sx = cs[_SX:_SX + 4]
    sf = cs[_SF:_SF + 4]
    if cs[_STARTED] == 0.0:
        cs[_STARTED] = 1.0
        cs[_XPREV] = x_meas
        cs[_XREF] = x_meas
        cs[_VF] = 0.0
        cs[_KSW] = -1.0
    # tip velocity estimate: filtered backward difference
    a = cp[_TFV] / (cp[_TFV] + ts)
    cs[_VF] = a * cs[_VF] + (1.0 - a) * (x_meas - cs[_XPREV]) / ts
    cs[_XPREV] = x_meas
    lever = cp[_LEVER]
    if cs[_MODE] == 0.0:
        if f_meas > cp[_FTH]:
            cs[_COUNT] += 1.0
        else:
            cs[_COUNT] = 0.0
        if cs[_COUNT] >= cp[_NCONF]:
            cs[_MODE] = 1.0
            cs[_KSW] = cs[_K]
            cs[_FREF] = f_meas
            cs[_FREF1] = f_meas
            xi = x_meas / lever
            ff = cp[_K1] * xi + cp[_K3] * xi * xi * xi + lever * cs[_FREF] - cp[_KV] * cs[_VF]
            if cp[_BUMP] > 0.0:
                pid_transfer(pf, sf, cs[_FREF], f_meas, ff, cs[_UPREV])
            else:  # plain switch (for comparison): the force PID starts from rest
                for i in range(4):
                    sf[i] = 0.0
    if cs[_MODE] == 0.0:
        xr = cs[_XREF] + cp[_VAPP] * ts
        if xr > cp[_XLIM]:
            xr = cp[_XLIM]
        cs[_XREF] = xr
        xi = xr / lever
        u = pid_step(px, sx, xr, x_meas, cp[_K1] * xi + cp[_K3] * xi * xi * xi)
    else:
        # reference: rate-limited ramp to the command (a full-scale change in force_ramp s), then
        # a first-order smoothing stage (force_tau): small, even steps of the held voltage. It
        # does not move on while the actuator is saturated in its direction (no reference windup)
        # nor on the switching sample (which returns the last command exactly).
        dref = 0.0
        if cs[_KSW] != cs[_K]:
            d = f_cmd - cs[_FREF1]
            if cp[_RAMP] > 0.0:
                lim = max(abs(f_cmd), abs(cs[_FREF1])) / cp[_RAMP] * ts
                if d > lim:
                    d = lim
                elif d < -lim:
                    d = -lim
            if (d > 0.0 and cs[_UPREV] >= pf[8]) or (d < 0.0 and cs[_UPREV] <= pf[7]):
                d = 0.0
            cs[_FREF1] += d
            b = ts / (cp[_TAUF] + ts)
            dref = b * (cs[_FREF1] - cs[_FREF])
            cs[_FREF] += dref
        # damping injection relative to the tip velocity the reference asks for (Ḟ_ref / k_c)
        vref = dref / ts / cp[_KC]
        xi = x_meas / lever
        ff = cp[_K1] * xi + cp[_K3] * xi * xi * xi + lever * cs[_FREF] - cp[_KV] * (cs[_VF] - vref)
        u = pid_step(pf, sf, cs[_FREF], f_meas, ff)
    cs[_UPREV] = u
    cs[_K] += 1.0
    v = math.sqrt(u / cp[_CE]) if u > 0.0 else 0.0
    if v < cp[_VMIN]:
        v = cp[_VMIN]
    elif v > cp[_VMAX]:
        v = cp[_VMAX]
    return v


@dataclass(frozen=True)
class HybridForcePosition:
    """Gains and settings of the hybrid force/position controller (module docstring).

    SI units: ``kp_x, ki_x, kd_x`` actuator force (N) per m, m·s, m/s of tip error; ``kp_f, ki_f,
    kd_f`` N per N; ``kv`` N·s/m (actuator force per tip velocity); ``tf_x``, ``tf_v`` derivative
    and velocity filter time constants (s); ``approach_speed`` (m/s) up to ``x_limit`` (m);
    ``contact_threshold`` (N) on ``confirm`` samples; ``force_ramp``, ``force_tau`` (s) shape the
    force reference; ``k_contact`` (N/m) contact stiffness at the tip; ``lever`` (D_a), ``k1``
    (N/m), ``k3`` (N/m³), ``c_e`` (N/V²) the actuator model; ``v_min``, ``v_max`` (V) the limits;
    ``anti_windup`` and ``bumpless`` switch those features off for comparisons. Defaults are tuned
    for the FT-G100 at 20 kHz (:meth:`for_plant` fills in the actuator model)."""

    dt: float = 5e-5
    kp_x: float = 3.0
    ki_x: float = 3000.0
    kd_x: float = 6e-4
    tf_x: float = 5e-5
    kp_f: float = 1.0
    ki_f: float = 8000.0
    kd_f: float = 0.0
    kv: float = 6e-3
    tf_v: float = 5e-5
    approach_speed: float = 5e-4
    x_limit: float = 100e-6
    contact_threshold: float = 0.5e-6
    confirm: int = 2
    force_ramp: float = 2e-3
    force_tau: float = 2e-4
    k_contact: float = 6.43
    anti_windup: bool = True
    bumpless: bool = True
    lever: float = 4.7
    k1: float = 25.4
    k3: float = 0.0
    c_e: float = 4.79375e-08
    v_max: float = 200.0
    v_min: float = 0.0

    def __post_init__(self):
        for k, v in asdict(self).items():
            if not isinstance(v, (int, float)) or not math.isfinite(v):
                raise ConfigError(f"hybrid controller {k}: expected a finite number, found {v!r}")
        for k in ("dt", "approach_speed", "x_limit", "contact_threshold", "lever", "c_e", "v_max",
                  "tf_v",
                  "k_contact"):
            if getattr(self, k) <= 0:
                raise ConfigError(f"hybrid controller {k}: expected a positive value, found "
                                  f"{getattr(self, k)!r}")
        if not 0 <= self.v_min < self.v_max:
            raise ConfigError("hybrid controller voltage range: expected 0 <= v_min "
                              "< v_max, found "
                              f"[{self.v_min:g}, {self.v_max:g}] V")
        if self.confirm < 1 or int(self.confirm) != self.confirm:
            raise ConfigError("hybrid controller confirm: expected a positive integer, found "
                              f"{self.confirm!r}")

    @classmethod
    def for_plant(cls, plant_parameters: ParameterSet | None = None,
                  **overrides) -> "HybridForcePosition":
        """Tuned defaults with the actuator model (D_a, K_sa, K₃, c_e, V_max) taken from an
        :class:`~gripkit.systems.ftg100.model.FTG100Plant` parameter set (the nominal one by
        default)."""
        ps = plant_parameters if plant_parameters is not None else _pp()
        base = dict(lever=ps.value("D_a"), k1=ps.value("K_sa"), k3=ps.value("K3_a"),
                    c_e=ps.value("c_e"),
                    v_max=ps.value("V_max"), k_contact=ps.value("K_sb") / ps.value("D_b") ** 2)
        base.update(overrides)
        return cls(**base)

    def with_(self, **changes) -> "HybridForcePosition":
        return replace(self, **changes)

    @property
    def force_limit(self) -> tuple[float, float]:
        """Actuator-force range [c_e V_min², c_e V_max²] (N)."""
        return self.c_e * self.v_min ** 2, self.c_e * self.v_max ** 2

    def params(self) -> np.ndarray:
        """The parameter array of :func:`hybrid_step`."""
        lo, hi = self.force_limit
        tt = None if self.anti_windup else math.inf
        px = (PID(self.kp_x, self.ki_x, self.kd_x, dt=self.dt, tf=self.tf_x, b=1.0, c=1.0, tt=tt,
                  u_min=lo, u_max=hi))
        pf = (PID(self.kp_f, self.ki_f, self.kd_f, dt=self.dt, b=1.0, c=0.0, tt=tt, u_min=lo,
                  u_max=hi))
        cp = np.empty(_NCP)
        cp[_TS] = self.dt
        cp[_PX:_PX + PID_NPARAM] = px.params
        cp[_PF:_PF + PID_NPARAM] = pf.params
        cp[_KV] = self.kv
        cp[_TFV] = self.tf_v
        cp[_VAPP] = self.approach_speed
        cp[_XLIM] = self.x_limit
        cp[_FTH] = self.contact_threshold
        cp[_NCONF] = self.confirm
        cp[_TAUF] = self.force_tau
        cp[_LEVER] = self.lever
        cp[_K1] = self.k1
        cp[_K3] = self.k3
        cp[_CE] = self.c_e
        cp[_VMAX] = self.v_max
        cp[_VMIN] = self.v_min
        cp[_RAMP] = self.force_ramp
        cp[_KC] = self.k_contact
        cp[_BUMP] = 1.0 if self.bumpless else 0.0
        return cp

    def controller(self) -> "HybridController":
        """A stateful controller for use sample by sample (e.g. on hardware)."""
        return HybridController(self)


class HybridController:
    """Sample-by-sample use of :class:`HybridForcePosition`: ``V = c.step(x_meas, f_meas,
    f_cmd)``."""

    def __init__(self, design: HybridForcePosition):
        self.design = design
        self._cp = design.params()
        self._cs = np.zeros(_NCS)

    def reset(self) -> None:
        self._cs[:] = 0.0

    @property
    def mode(self) -> str:
        return "force" if self._cs[_MODE] == 1.0 else "position"

    @property
    def command(self) -> float:
        """The last actuator-force command (N)."""
        return float(self._cs[_UPREV])

    def step(self, x_meas: float, f_meas: float, f_cmd: float) -> float:
        vals = (float(x_meas), float(f_meas), float(f_cmd))
        if not all(math.isfinite(v) for v in vals):
            raise SimulationError(f"hybrid controller: non-finite measurement or command {vals}")
        return float(hybrid_step(self._cp, self._cs, *vals))


# ------------------------------------------------------------------------------------------------
# closed loop on the FT-G100 plant
# ------------------------------------------------------------------------------------------------

#: the settings shared by the grasps of a batch: controller sample time dt, plant substeps per
#: sample, the settling band (fraction of the command), the number of samples and whether the
#: trajectories are recorded
GraspRun = namedtuple("GraspRun", "dt substeps band n_steps rec")


@numba.njit(cache=True)
def _grasp_one(th, cp, fprof, sig_f, sig_x, seed, damage, run, traj,
               met):  # pragma: no cover - compiled
    """One closed-loop grasp from rest (``run``: :data:`GraspRun`); writes the trajectory (if
    ``run.rec``) and the metrics. ``fprof`` holds the commanded force, one value (constant) or one
    per sample; the metrics refer to its last value."""
    dt, substeps, band, n_steps, rec = run
    fcmd = fprof[fprof.shape[0] - 1]
    varying = fprof.shape[0] > 1
    s = np.zeros(4)
    o = np.empty(4)
    cs = np.zeros(_NCS)
    rng = np.empty(1, dtype=np.uint64)
    rng[0] = np.uint64(seed) * np.uint64(0x2545F4914F6CDD1D) + np.uint64(1)
    h = dt / substeps
    mode = 0
    lo_u = cp[_CE] * cp[_VMIN] * cp[_VMIN]
    hi_u = cp[_CE] * cp[_VMAX] * cp[_VMAX]
    t_contact = -1.0
    t_switch = -1.0
    peak = 0.0
    last_out = -1
    vmax = 0.0
    nsat = 0
    err = 0.0
    nerr = 0
    f = 0.0
    tail = n_steps - max(1, n_steps // 10)
    for n in range(n_steps):
        plant_outputs(th, s, mode, o)
        fm = o[PO.F_s] + sig_f * normal_draw(rng)
        xm = o[PO.x_a] + sig_x * normal_draw(rng)
        V = hybrid_step(cp, cs, xm, fm, fprof[n] if varying else fcmd)
        if rec:
            traj[n, 0] = n * dt
            traj[n, 1] = o[PO.x_a]
            traj[n, 2] = o[PO.x_b]
            traj[n, 3] = o[PO.F_c]
            traj[n, 4] = fm
            traj[n, 5] = V
            traj[n, 6] = cs[_MODE]
        if t_switch < 0.0 and cs[_MODE] == 1.0:
            t_switch = n * dt
        if V > vmax:
            vmax = V
        if cs[_UPREV] >= hi_u or cs[_UPREV] <= lo_u:
            nsat += 1
        for j in range(substeps):
            mode = advance_plant(th, s, mode, V, h, 1)
            plant_outputs(th, s, mode, o)
            f = o[PO.F_c]
            if f > 0.0 and t_contact < 0.0:
                t_contact = n * dt + (j + 1) * h
            if f > peak:
                peak = f
        if t_contact >= 0.0 and abs(f - fcmd) > band * fcmd:
            last_out = n
        if n >= tail:
            err += f - fcmd
            nerr += 1
    met[MX.t_contact] = t_contact if t_contact >= 0.0 else np.nan
    met[MX.t_switch] = t_switch if t_switch >= 0.0 else np.nan
    met[MX.peak_force] = peak
    met[MX.overshoot_percent] = max(0.0, (peak - fcmd) / fcmd * 100.0)
    if t_contact < 0.0 or last_out == n_steps - 1:
        met[MX.settling_time] = np.inf
    else:
        met[MX.settling_time] = max(0.0, (last_out + 1) * dt - t_contact)
    met[MX.final_error] = err / nerr / fcmd
    met[MX.max_voltage] = vmax
    met[MX.damage] = 1.0 if peak > damage else 0.0
    met[MX.detected] = 1.0 if t_switch >= 0.0 else 0.0
    met[MX.sat_fraction] = nsat / n_steps


@numba.njit(cache=True, parallel=True)
def _grasp_batch(thetas, cps, fprofs, sig_f, sig_x, seeds, damages, run, traj,
                 met):  # pragma: no cover - compiled
    dt, substeps, band, n_steps, rec = run
    for p in numba.prange(thetas.shape[0]):
        _grasp_one(thetas[p], cps[p], fprofs[p], sig_f[p], sig_x[p], seeds[p], damages[p],
                   GraspRun(dt, substeps, band, n_steps, rec), traj[p], met[p])


@dataclass(frozen=True)
class HybridGraspResult:
    """One closed-loop grasp: ``trajectory`` (t, x_a, x_b, F_c true, F_meas, V, mode) and
    ``metrics`` (see :data:`METRICS`; times in s from the start, settling from first contact)."""

    trajectory: Trajectory
    metrics: dict
    force: float
    damage_threshold: float
    k0: float
    gap: float

    def passed(self, overshoot_percent: float = 10.0, settling_time: float = 5e-3) -> bool:
        m = self.metrics
        return bool(m["detected"] and not m["damage"] and m["overshoot_percent"] < overshoot_percent
                    and m["settling_time"] < settling_time)


@dataclass(frozen=True)
class GraspBatch:
    """Many grasps: ``metrics`` (P, len(METRICS)) and the scenario arrays (force, k0, gap, seed);
    ``trajectories`` (P, N, 7) when recorded."""

    metrics: np.ndarray
    force: np.ndarray
    k0: np.ndarray
    gap: np.ndarray
    seed: np.ndarray
    damage_threshold: np.ndarray
    dt: float
    trajectories: np.ndarray | None = None

    def __getitem__(self, name: str) -> np.ndarray:
        if name not in METRICS:
            raise KeyError(f"no metric {name!r}; metrics: {', '.join(METRICS)}")
        return self.metrics[:, METRICS.index(name)]

    def __len__(self) -> int:
        return self.metrics.shape[0]

    def rows(self) -> list[dict]:
        out = []
        for i in range(len(self)):
            d = (dict(force=float(self.force[i]), k0=float(self.k0[i]), gap=float(self.gap[i]),
                      seed=int(self.seed[i])))
            d.update({k: float(v) for k, v in zip(METRICS, self.metrics[i])})
            d["damage"] = bool(d["damage"])
            d["detected"] = bool(d["detected"])
            out.append(d)
        return out


def _prepare(controller, plant, force, k0, gap, seed, noise_force, noise_position, damage_threshold,
             duration):
    plant = plant if plant is not None else FTG100Plant(check=False)
    if not isinstance(plant, FTG100Plant):
        raise ConfigError(f"plant: expected an FTG100Plant, found {type(plant).__name__}")
    if controller is None:
        controller = HybridForcePosition.for_plant(plant.parameters)
    ctrls = list(controller) if isinstance(controller, (list, tuple)) else [controller]
    for c in ctrls:
        if not isinstance(c, HybridForcePosition):
            raise ConfigError("controller: expected a HybridForcePosition, found "
                              f"{type(c).__name__}")
    base = plant.theta()
    names = plant.parameters.names
    arrs = np.broadcast_arrays(
        np.asarray(force, float), np.asarray(base[names.index("k0")] if k0 is None else k0, float),
        np.asarray(base[names.index("gap")] if gap is None else gap, float), np.asarray(seed),
        np.asarray(noise_force, float), np.asarray(noise_position, float),
        np.arange(len(ctrls)) if len(ctrls) > 1 else np.asarray(0))
    F, K0, G, S, NF, NX, CI = (np.ascontiguousarray(np.atleast_1d(a)).ravel() for a in arrs)
    if not (np.isfinite(F).all() and (F > 0).all()):
        raise ConfigError("force: expected positive commanded forces (N), e.g. 20e-6")
    if not (np.isfinite(K0).all() and (K0 >= 0).all()):
        raise ConfigError("k0: expected object stiffnesses >= 0 N/m")
    if not (np.isfinite(G).all() and (G >= 0).all()):
        raise ConfigError("gap: expected free gaps >= 0 m")
    if (NF < 0).any() or (NX < 0).any() or not (np.isfinite(NF).all() and np.isfinite(NX).all()):
        raise ConfigError("noise: expected standard deviations >= 0")
    if not np.issubdtype(S.dtype, np.integer) or (S < 0).any():
        raise ConfigError("seed: expected non-negative integers")
    dmg = (np.broadcast_to(1.5 * F if damage_threshold is None else np.asarray(damage_threshold,
                                                                               float), F.shape))
    dmg = np.ascontiguousarray(dmg, dtype=float)
    P = F.size
    thetas = np.repeat(base[None, :], P, axis=0)
    thetas[:, names.index("k0")] = K0
    thetas[:, names.index("gap")] = G
    thetas = plant._check_thetas(thetas)
    cps = np.stack([ctrls[i].params() for i in CI])
    dt = ctrls[0].dt
    if any(abs(c.dt - dt) > 1e-15 for c in ctrls):
        raise ConfigError("controllers in one batch must share the sample time dt")
    if not (math.isfinite(duration) and duration > dt):
        raise ConfigError(f"duration: expected more than one sample ({dt:g} s), found {duration!r}")
    n_steps = int(round(duration / dt))
    substeps = plant.substeps(dt, np.unique(thetas, axis=0))
    return plant, thetas, cps, F, K0, G, S.astype(np.int64), NF, NX, dmg, dt, n_steps, substeps


def grasp_batch(controller: HybridForcePosition | list | None = None, plant=None, *, force=20e-6,
                k0=None,
                gap=None, seed=0, duration: float = 0.1, noise_force=50e-9, noise_position=1e-9,
                damage_threshold=None, band: float = 0.02, record: bool = False,
                progress: bool = True) -> GraspBatch:
    """Closed-loop approach-and-grasp simulations from rest, in parallel, for every combination
    broadcast from ``force`` (commanded force, N), ``k0`` (object stiffness, N/m; default the
    plant's), ``gap`` (free gap, m; default the plant's), ``seed`` (noise stream) and the noise
    standard deviations ``noise_force`` (N) and ``noise_position`` (m). ``controller`` may be a list
    with one design per scenario (same ``dt``). ``damage_threshold`` defaults to 1.5 × the command;
    ``band`` is the settling band as a fraction of the command. ``duration`` must cover the
    approach (gap / approach_speed) plus the grasp.
    """
    plant, thetas, cps, F, K0, G, S, NF, NX, dmg, dt, n_steps, sub = _prepare(
        controller, plant, force, k0, gap, seed, noise_force, noise_position, damage_threshold,
        duration)
    met, traj = _run(thetas, cps, np.ascontiguousarray(F[:, None]), NF, NX, S, dt, sub, band, dmg,
                     n_steps,
                     record, progress)
    return GraspBatch(met, F, K0, G, S, dmg, dt, traj if record else None)


def _run(thetas, cps, fprofs, NF, NX, S, dt, sub, band, dmg, n_steps, record, progress):
    P = thetas.shape[0]
    if not (math.isfinite(band) and 0 < band < 1):
        raise ConfigError(f"band: expected a fraction in (0, 1), found {band!r}")
    met = np.empty((P, len(METRICS)))
    traj = np.empty((P, n_steps if record else 1, 7))
    chunk = 256
    run = GraspRun(dt, sub, float(band), n_steps, bool(record))
    for a in track(range(0, P, chunk), description="grasp simulations",
                   enabled=progress and P > 2 * chunk):
        b = min(P, a + chunk)
        _grasp_batch(thetas[a:b], cps[a:b], fprofs[a:b], NF[a:b], NX[a:b], S[a:b], dmg[a:b], run,
                     traj[a:b], met[a:b])
    return met, traj


def simulate_hybrid_grasp(controller: HybridForcePosition | None = None, plant=None, *,
                          force: float = 20e-6,
                          k0: float | None = None, gap: float | None = None, seed: int = 0,
                          duration: float = 0.1,
                          noise_force: float = 50e-9, noise_position: float = 1e-9,
                          damage_threshold: float | None = None, band: float = 0.02,
                          force_profile=None) -> HybridGraspResult:
    """One closed-loop approach-and-grasp on the FT-G100 plant (see :func:`grasp_batch`), with its
    trajectory. ``force_profile`` (optional, N, one value per controller sample over ``duration``)
    replaces the constant command; the metrics then refer to its last value."""
    for name, v in (("force", force), ("k0", k0), ("gap", gap)):
        if v is not None and np.ndim(v) != 0:
            raise ConfigError(f"{name}: expected one number for simulate_hybrid_grasp (use "
                              "grasp_batch for arrays)")
    plant, thetas, cps, F, K0, G, S, NF, NX, dmg, dt, n_steps, sub = _prepare(
        controller, plant, force, k0, gap, seed, noise_force, noise_position, damage_threshold,
        duration)
    prof = F[:, None]
    if force_profile is not None:
        prof = np.asarray(force_profile, dtype=np.float64)
        if prof.shape != (n_steps,) or not np.isfinite(prof).all() or (prof <= 0).any():
            raise ConfigError(f"force_profile: expected {n_steps} positive forces (one per "
                              f"{dt:g} s sample over "
                              f"{duration:g} s), found shape {prof.shape}")
        prof = prof[None, :]
        F = prof[:, -1].copy()
        dmg = np.full(1, 1.5 * F[0]) if damage_threshold is None else dmg
    met, tr = (_run(thetas, cps, np.ascontiguousarray(prof), NF, NX, S, dt, sub, band, dmg, n_steps,
                    True, False))
    b = GraspBatch(met, F, K0, G, S, dmg, dt, tr)
    tr = tr[0]
    traj = Trajectory(tr[:, 0], {"x_a": tr[:, 1], "x_b": tr[:, 2], "F_c": tr[:, 3],
                                 "F_meas": tr[:, 4],
                                 "V": tr[:, 5], "mode": tr[:, 6]},
                      {"x_a": "m", "x_b": "m", "F_c": "N", "F_meas": "N", "V": "V", "mode": "1"},
                      {"dt": dt, "model": "ftg100-plant + hybrid force/position"})
    return (HybridGraspResult(traj, b.rows()[0], float(F[0]), float(dmg[0]), float(K0[0]),
                              float(G[0])))


def impact_speed_limit(force: float, k0: float, plant_parameters: ParameterSet | None = None,
                       fraction: float = 0.1) -> float:
    """Approach speed (m/s) whose impact transient stays below ``fraction`` × ``force``.

    At first touch the tips meet at the approach speed v; the object spring k0 between the two
    tip masses m_a = M_a/D_a² and m_b = M_b/D_b² rings at √(k0/m_r) (m_r = m_a m_b/(m_a + m_b)) with
    a force amplitude v √(k0 m_r) that the 20 kHz loop cannot see or damp (35-60 kHz for the
    FT-G100 and a glass ball; damped only by the structure and the contact, ζ ≈ 0.002 with the
    seed's pure spring). Hence v ≤ fraction · F / √(k0 m_r): 0.48 mm/s for 20 µN, k0 = 1560 N/m.
    """
    ps = plant_parameters if plant_parameters is not None else _pp()
    ma = ps.value("M_a") / ps.value("D_a") ** 2
    mb = ps.value("M_b") / ps.value("D_b") ** 2
    mr = ma * mb / (ma + mb)
    if not (force > 0 and k0 > 0 and fraction > 0):
        raise ConfigError("impact_speed_limit: expected positive force, k0 and fraction")
    return fraction * force / math.sqrt(k0 * mr)
