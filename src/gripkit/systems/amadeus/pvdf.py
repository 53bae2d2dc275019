"""PVDF slip sensor and the stick-slip fingertip contact that drives it
(``000_8f66dcc7ab06470c.txt`` §II-C, §IV-B, Figs 12–13).

PVDF film (§IV-B)
-----------------
A 52 µm PVDF film 1 mm below the elastomer surface develops a charge when deformed; "once it
stops deforming the charge built up on the surface quickly decays to zero". With the film's
capacitance discharging through the amplifier input (time constant τ = R C), the output voltage
obeys

    dv/dt = −v/τ + g · dd/dt,

a first-order high-pass of the deformation d (m) with sensitivity g (V/m): a step of deformation
gives a jump g·Δd that decays as e^{−t/τ}; a steady deformation gives nothing. For a deformation
held constant over each step (zero-order hold), v[n] = e^{−h/τ} v[n−1] + g (d[n] − d[n−1]) is
exact (sampled just after each step's jump). :class:`PVDFFilm` is that filter.

Stick-slip contact (what the film feels)
----------------------------------------
"The relative motion between two surfaces causes mechanical vibration in a direction normal to
the plane of motion" (§IV-B). :class:`StickSlipContact` models the fingertip pad as a small mass
m_p on the elastomer's tangential stiffness k_t and damping c_t, rubbing on the object with
static/kinetic (Stribeck) friction under the normal force F_n:

    μ(v) = μ_k + (μ_s − μ_k) e^{−|v|/v_s},   |F| ≤ μ_s F_n while stuck.

While stuck, the pad moves with the object (the pad shear follows the tangential load slowly).
When the required friction exceeds μ_s F_n the pad slips; the friction drop μ_s → μ_k releases the
stored shear and the pad rings at √(k_t/m_p) — a relaxation (stick-slip) oscillation whose rate
grows with the slip speed. Sliding also drags the object's surface texture (amplitude a, main
wavelength λ) over the pad, a normal deformation at frequency v/λ. The film sees
d = g_s/g · x_pad + F_n/k_n + texture(s) (pad shear, normal compression, texture at sliding
distance s); its output is the high-pass above, averaged over each output sample (a boxcar
anti-alias filter).

Two drives: ``StickSlipContact`` (grasp: the object of mass M is pulled by a load force F_load
and held only by friction; slip is an outcome) and ``SlipTestbed`` (Fig. 12(b): the surface is
driven at a prescribed speed). Parameters are assumed (the seed prints none) and chosen for a
phase-I fingertip: pad resonance ≈ 250 Hz, friction μ_s = 0.6, μ_k = 0.45 (wet elastomer).
:func:`pvdf_noise` adds sensor noise and a hydraulic-pump ripple tone.
"""

from __future__ import annotations

import math
from collections import namedtuple

import numba
import numpy as np
from numba import prange

from ...errors import DataError, SimulationError
from ...params import Parameter, ParameterSet
from ...sim.model import Model, Signal

__all__ = ["PVDFFilm", "pvdf_parameters", "StickSlipContact", "SlipTestbed", "contact_parameters",
           "pvdf_noise", "contact_step", "nonslip_grasp_inputs", "slip_onset_inputs"]

_SEED = "000_8f66dcc7ab06470c.txt"


def pvdf_parameters(*, gain: float = 2.0e3, tau: float = 0.01) -> ParameterSet:
    """PVDF film: sensitivity g (V/m of deformation) and charge-decay time constant τ (s)."""
    return ParameterSet([
        Parameter("gain", gain, "V/m", "film output per unit "
                                       "deformation (before decay)", bounds=(0.0, None),
                  source="assumed: 52 µm PVDF film (§IV-B); gives ~10-100 mV slip signals"),
        Parameter("tau", tau, "s", "charge decay time constant R·C of film and amplifier",
                  bounds=(1e-6, 100.0), source="assumed: 16 Hz high-pass corner ('quickly "
                                               "decays', §IV-B)",
                  display_unit="ms"),
    ], "pvdf")


@numba.njit(cache=True, parallel=True)
def _pvdf_batch(thetas, u, dt, x0, y):  # pragma: no cover - compiled
    """Film voltages y[p, n, 0] for parameter rows (g, τ) from states x0[p] = (v, previous d)."""
    for p in prange(thetas.shape[0]):
        g, a = thetas[p, 0], math.exp(-dt / thetas[p, 1])
        v, dprev = x0[p, 0], x0[p, 1]
        if math.isnan(dprev):
            dprev = u[0, 0]
        for n in range(u.shape[0]):
            v = a * v + g * (u[n, 0] - dprev)
            dprev = u[n, 0]
            y[p, n, 0] = v


class PVDFFilm(Model):
    """PVDF film: deformation d (m) → voltage v (V), dv/dt = −v/τ + g dd/dt (exact for ZOH
    input)."""

    name = "pvdf-film"
    description = "PVDF film: high-pass of the deformation rate (charge decays)"
    inputs = (Signal("d", "m", "film deformation"),)
    outputs = (Signal("v", "V", "film voltage"),)
    states = (Signal("v", "V", "film voltage"), Signal("d_prev", "m", "previous deformation"))
    integrator = "zoh"

    def __init__(self, parameters: ParameterSet | None = None, *, check: bool = True, **kw):
        super().__init__(parameters if parameters is not None else pvdf_parameters(**kw),
                         check=check)

    def initial_state(self, theta):
        return np.array([0.0, np.nan])

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        _pvdf_batch(thetas, u, dt, x0, y)


# --------------------------------------------------------------------------- stick-slip contact
_CONTACT_NAMES = ("m_pad", "k_t", "c_t", "mu_s", "mu_k", "v_stribeck", "m_obj", "c_obj", "k_n",
                  "texture", "wavelength", "shear_coupling", "gain", "tau")
#: the index of each contact parameter in the vector ``th`` the kernels take (``th[CX.k_t]``),
#: generated from _CONTACT_NAMES: a module-level namedtuple of ints that numba folds as constants
CX = namedtuple("ContactParameterIndex", _CONTACT_NAMES)(*range(len(_CONTACT_NAMES)))
#: the pad and object constants of one stick-slip substep: pad mass, object mass and drag, and
#: the Stribeck friction (μ_k, μ_s, v_s)
PadObject = namedtuple("PadObject", "m M co muk mus vs")
#: what the drive input of :func:`contact_step` is: the load on a grasped object, or the speed
#: of a testbed surface (the kernels' ``mode``)
GRASP, TESTBED = 0, 1


def contact_parameters(*, m_pad: float = 2.0e-3, k_t: float = 5.0e3, c_t: float = 1.5,
                       mu_s: float = 0.6,
                       mu_k: float = 0.45, v_stribeck: float = 5e-3, m_obj: float = 0.2,
                       c_obj: float = 15.0,
                       k_n: float = 2.0e4, texture: float = 2e-6, wavelength: float = 0.5e-3,
                       shear_coupling: float = 0.3, gain: float = 2.0e3,
                       tau: float = 0.01) -> ParameterSet:
    """Stick-slip fingertip contact plus PVDF film parameters (SI). All assumed (see module doc)."""
    a = "assumed: phase-I fingertip scale (the seed prints no contact parameters)"
    pv = pvdf_parameters(gain=gain, tau=tau)
    return ParameterSet([
        Parameter("m_pad", m_pad, "kg", "effective mass of the "
                                        "fingertip pad surface", bounds=(1e-9, None),
                  source=a, display_unit="g"),
        Parameter("k_t", k_t, "N/m", "tangential stiffness of "
                                     "the elastomer pad", bounds=(1e-6, None), source=a),
        Parameter("c_t", c_t, "N*s/m", "tangential damping of the pad", bounds=(0.0, None),
                  source=a),
        Parameter("mu_s", mu_s, "1", "static friction coefficient pad/object", bounds=(0.0, 5.0),
                  source=a),
        Parameter("mu_k", mu_k, "1", "kinetic friction "
                                     "coefficient at high speed", bounds=(0.0, 5.0), source=a),
        Parameter("v_stribeck", v_stribeck, "m/s", "Stribeck velocity of "
                                                   "the friction drop", bounds=(1e-9, None),
                  source=a, display_unit="mm/s"),
        Parameter("m_obj", m_obj, "kg", "mass of the grasped "
                                        "object (per finger)", bounds=(1e-9, None), source=a),
        Parameter("c_obj", c_obj, "N*s/m", "damping of the object's motion relative to the hand",
                  bounds=(0.0, None), source=a),
        Parameter("k_n", k_n, "N/m", "normal stiffness of the "
                                     "elastomer over the film", bounds=(1e-6, None),
                  source=a),
        Parameter("texture", texture, "m", "amplitude of the object's "
                                           "surface texture", bounds=(0.0, None),
                  source=a, display_unit="um"),
        Parameter("wavelength", wavelength, "m", "main wavelength of the "
                                                 "surface texture", bounds=(1e-9, None),
                  source=a, display_unit="mm"),
        Parameter("shear_coupling", shear_coupling, "1", "film deformation per unit pad shear",
                  bounds=(0.0, None), source=a),
        pv["gain"], pv["tau"],
    ], "stick-slip-contact")


@numba.njit(cache=True)
def _texture(s, a, lam):  # pragma: no cover - compiled
    tp = 2.0 * math.pi
    return a * (math.sin(tp * s / lam) + 0.5 * math.sin(tp * s / (0.43 * lam) + 1.3)
                + 0.3 * math.sin(tp * s / (0.27 * lam) + 2.1))


@numba.njit(cache=True)
def _testbed_substep(m, Fs, muk, mus, vs, Fn, spring, v_surface, h, vp, vo,
                     stuck):  # pragma: no cover - compiled
    """One substep of the testbed drive (mode 1): the surface moves at ``v_surface``. A stuck pad
    moves with it while the friction that takes, m·a − spring, stays within μ_s F_n (``Fs``); a
    slipping pad feels the Stribeck friction μ(v) F_n and sticks again when the relative
    velocity changes sign. Returns (v_pad, v_obj, stuck, F)."""
    ao = (v_surface - vo) / h
    if stuck > 0.5:
        Freq = m * ao - spring
        if abs(Freq) <= Fs:
            F = Freq
            vp = v_surface
        else:
            stuck = 0.0
            F = Fs if Freq > 0 else -Fs
            vp = vp + h * (spring + F) / m
    else:
        vrel = v_surface - vp
        mu = muk + (mus - muk) * math.exp(-abs(vrel) / vs)
        F = mu * Fn if vrel > 0 else -mu * Fn
        vp_new = vp + h * (spring + F) / m
        if (v_surface - vp_new) * vrel <= 0.0:
            vp_new = v_surface
            stuck = 1.0
        vp = vp_new
    return vp, v_surface, stuck, F


@numba.njit(cache=True)
def _grasp_substep(po, Fs, Fn, spring, F_load, h, vp, vo, stuck):  # pragma: no cover - compiled
    """One substep of the grasp (mode 0) with the constants ``po`` (:data:`PadObject`): the object
    (mass M, drag c_o·v) is pulled by ``F_load``
    and held only by friction. Stuck, pad and object accelerate together while the friction that
    takes stays within μ_s F_n (``Fs``); slipping, each moves under its own forces with the
    Stribeck friction, and they stick again at their common (momentum) velocity when the
    relative velocity changes sign. Returns (v_pad, v_obj, stuck, F)."""
    m, M, co, muk, mus, vs = po
    drag = -co * vo
    if stuck > 0.5:
        a = (F_load + drag + spring) / (m + M)
        Freq = m * a - spring
        if abs(Freq) <= Fs:
            F = Freq
            vp = vp + h * a
            vo = vp
        else:
            stuck = 0.0
            F = Fs if Freq > 0 else -Fs
            vp = vp + h * (spring + F) / m
            vo = vo + h * (F_load + drag - F) / M
    else:
        vrel = vo - vp
        mu = muk + (mus - muk) * math.exp(-abs(vrel) / vs)
        F = mu * Fn if vrel > 0 else -mu * Fn
        vp_new = vp + h * (spring + F) / m
        vo_new = vo + h * (F_load + drag - F) / M
        if (vo_new - vp_new) * vrel <= 0.0:
            vc = (m * vp_new + M * vo_new) / (m + M)
            vp_new = vc
            vo_new = vc
            stuck = 1.0
        vp = vp_new
        vo = vo_new
    return vp, vo, stuck, F


@numba.njit(cache=True)
def contact_step(th, mode, u, dt, substeps, st, y):  # pragma: no cover - compiled
    """Advance the contact over the rows of ``u`` (N, 2) = [F_n, drive]; ``mode`` 0: drive is the
    load force on the object (grasp, :func:`_grasp_substep`), 1: drive is the surface speed
    (testbed, :func:`_testbed_substep`). ``st`` (8,) = [x_pad, v_pad, x_obj, v_obj, stuck, s,
    v_film, d_prev] is updated in place. ``y`` (N, 6) = [film voltage (mean over the sample),
    slip velocity, slipping fraction, pad shear, object position, friction force]."""
    m, k, c, mus = th[CX.m_pad], th[CX.k_t], th[CX.c_t], th[CX.mu_s]
    muk, vs = th[CX.mu_k], th[CX.v_stribeck]
    M, co, kn, ta, lam = th[CX.m_obj], th[CX.c_obj], th[CX.k_n], th[CX.texture], th[CX.wavelength]
    alpha, g, tau = th[CX.shear_coupling], th[CX.gain], th[CX.tau]
    po = PadObject(m, M, co, muk, mus, vs)
    h = dt / substeps
    decay = math.exp(-h / tau)
    xp, vp, xo, vo, stuck, s, v, dprev = st[0], st[1], st[2], st[3], st[4], st[5], st[6], st[7]
    if math.isnan(dprev):
        dprev = alpha * xp + u[0, 0] / kn + _texture(s, ta, lam)
    for n in range(u.shape[0]):
        Fn = u[n, 0]
        if Fn < 0.0:
            Fn = 0.0
        drive = u[n, 1]
        vacc = 0.0
        slip_n = 0.0
        vrel_acc = 0.0
        F = 0.0
        for _ in range(substeps):
            Fs = mus * Fn
            spring = -k * xp - c * vp
            if mode == TESTBED:
                vp, vo, stuck, F = (_testbed_substep(m, Fs, muk, mus, vs, Fn, spring, drive, h, vp,
                                                     vo, stuck))
            else:
                vp, vo, stuck, F = _grasp_substep(po, Fs, Fn, spring, drive, h, vp, vo, stuck)
            xo += vo * h
            xp += vp * h
            vrel_now = vo - vp
            if stuck < 0.5:
                s += abs(vrel_now) * h
                slip_n += 1.0
            vrel_acc += vrel_now
            # the film: d = g_s/g·x_pad + F_n/k_n + texture(s), high-passed (module doc)
            d = alpha * xp + Fn / kn + _texture(s, ta, lam)
            v = decay * v + g * (d - dprev)
            dprev = d
            vacc += v
        y[n, 0] = vacc / substeps
        y[n, 1] = vrel_acc / substeps
        y[n, 2] = slip_n / substeps
        y[n, 3] = xp
        y[n, 4] = xo
        y[n, 5] = F
    st[0], st[1], st[2], st[3], st[4], st[5], st[6], st[7] = xp, vp, xo, vo, stuck, s, v, dprev


@numba.njit(cache=True, parallel=True)
def _contact_batch(thetas, mode, u, dt, substeps, x0, y):  # pragma: no cover - compiled
    for p in prange(thetas.shape[0]):
        st = x0[p].copy()
        contact_step(thetas[p], mode, u, dt, substeps, st, y[p])


class StickSlipContact(Model):
    """Fingertip pad with stick-slip friction on a grasped object, and the PVDF film in the pad.

    Inputs: ``F_n`` (N, normal grip force) and ``F_load`` (N, tangential load on the object).
    Outputs: ``v_pvdf`` (V), ``v_slip`` (m/s, object minus pad), ``slipping`` (fraction of the
    sample spent slipping: the ground truth for slip detection), ``x_pad`` (m), ``x_obj`` (m),
    ``F_t`` (N, friction force). Internally integrated at ≥ 20 kHz (semi-implicit Euler with an
    exact stick/slip switch), whatever the output rate.
    """

    name = "stick-slip-contact"
    description = "fingertip pad with stick-slip friction and an embedded PVDF film"
    inputs = (Signal("F_n", "N", "normal grip force"),
              Signal("F_load", "N", "tangential load on the object"))
    outputs = (Signal("v_pvdf", "V", "PVDF film voltage"), Signal("v_slip", "m/s", "slip velocity"),
               Signal("slipping", "1", "fraction of the sample spent slipping"),
               Signal("x_pad", "m", "pad shear displacement"),
               Signal("x_obj", "m", "object position"),
               Signal("F_t", "N", "friction force on the pad"))
    states = (Signal("x_pad", "m"), Signal("v_pad", "m/s"), Signal("x_obj", "m"),
              Signal("v_obj", "m/s"),
              Signal("stuck", "1"), Signal("s", "m", "sliding distance"), Signal("v_film", "V"),
              Signal("d_prev", "m"))
    integrator = "semi-implicit"
    _mode = GRASP
    internal_rate = 20_000.0

    def __init__(self, parameters: ParameterSet | None = None, *, check: bool = True, **kw):
        params = parameters if parameters is not None else contact_parameters(**kw)
        if tuple(params.names) != _CONTACT_NAMES:
            raise DataError(f"contact parameters must be {_CONTACT_NAMES} in this order, "
                            f"found {params.names}")
        if params.value("mu_k") > params.value("mu_s"):
            raise DataError(f"mu_k = {params.value('mu_k')} exceeds mu_s = {params.value('mu_s')}",
                            hint="kinetic friction cannot exceed static friction")
        super().__init__(params, check=check)

    def initial_state(self, theta):
        return np.array([0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, np.nan])

    def modes(self, theta):
        m, k, c = theta[0], theta[1], theta[2]
        wn = math.sqrt(k / m)
        return [(wn, c / (2.0 * math.sqrt(k * m)))]

    def substeps(self, dt, thetas):
        return max(super().substeps(dt, thetas), int(math.ceil(dt * self.internal_rate - 1e-9)))

    def _simulate_batch(self, thetas, u, dt, substeps, x0, y):
        _contact_batch(thetas, self._mode, u, dt, substeps, x0, y)

    def equilibrium_state(self, F_load: float = 0.0) -> np.ndarray:
        """A state at rest and stuck, the pad sheared by a held tangential load ``F_load`` (N):
        x_pad = F_load / k_t (start a record without an artificial loading transient)."""
        st = self.initial_state(self.theta())
        st[0] = float(F_load) / self.parameters.value("k_t")
        return st

    # streaming use inside a control loop ---------------------------------------------------
    def new_state(self) -> np.ndarray:
        """A fresh state vector for :meth:`advance` (stuck, at rest)."""
        return self.initial_state(self.theta())

    def advance(self, state: np.ndarray, F_n, drive, dt: float,
                substeps: int | None = None) -> np.ndarray:
        """Advance ``state`` (updated in place) over the samples of ``F_n``/``drive`` (arrays of one
        length, step ``dt``); returns the outputs (N, 6) as in :meth:`simulate`."""
        fn = np.atleast_1d(np.asarray(F_n, dtype=np.float64))
        dr = np.broadcast_to(np.asarray(drive, dtype=np.float64), fn.shape)
        if not (np.isfinite(fn).all() and np.isfinite(dr).all()):
            raise SimulationError("contact inputs contain NaN or inf")
        u = np.ascontiguousarray(np.column_stack([fn, dr]))
        th = self.theta()
        ns = self.substeps(dt, th[None, :]) if substeps is None else int(substeps)
        y = np.empty((u.shape[0], 6))
        contact_step(th, self._mode, u, float(dt), ns, state, y)
        return y


class SlipTestbed(StickSlipContact):
    """The sensor test rig of Fig. 12(b): the surface slides at a prescribed speed.

    Inputs ``F_n`` (N) and ``v_surface`` (m/s); outputs as :class:`StickSlipContact`."""

    name = "slip-testbed"
    description = ("PVDF slip sensor on a test rig: surface driven at a prescribed "
                   "speed (Fig. 12(b))")
    inputs = (Signal("F_n", "N", "normal force"), Signal("v_surface", "m/s", "surface speed"))
    _mode = TESTBED


def pvdf_noise(n: int, *, dt: float, rng=None, white: float = 2e-3, ripple: float = 4e-3,
               ripple_hz: float = 150.0, ripple_harmonics: int = 2) -> np.ndarray:
    """Additive PVDF-channel noise (V), shape (n,): white electronics noise of std ``white`` plus a
    hydraulic-pump ripple tone (amplitude ``ripple`` at ``ripple_hz`` and its harmonics, slowly
    wandering in amplitude). Assumed levels; the seed's Fig. 13 shows the non-slip signal is small
    but not zero."""
    rng = np.random.default_rng(rng)
    if n < 1 or not (dt > 0):
        raise DataError(f"pvdf_noise: need n >= 1 and dt > 0 (s), found n={n}, dt={dt}")
    rate = 1.0 / dt
    t = np.arange(n) / rate
    x = white * rng.standard_normal(n)
    wander = 1.0 + 0.3 * np.sin(2 * np.pi * 0.05 * t + rng.uniform(0, 2 * np.pi))
    for k in range(1, ripple_harmonics + 1):
        if k * ripple_hz < rate / 2:
            x += (ripple / k) * wander * np.sin(2 * np.pi * k * ripple_hz * t
                                                + rng.uniform(0, 2 * np.pi))
    return x


def nonslip_grasp_inputs(duration: float, *, dt: float, rng=None, normal_force: float = 2.0,
                         load: float = 0.4, load_std: float = 0.12, grip_std: float = 0.05,
                         tap_rate: float = 0.5, tap_amplitude=(0.1, 0.3),
                         tap_duration=(0.004, 0.02),
                         grip_step_rate: float = 0.2, grip_step: float = 0.3,
                         min_normal: float = 1.6) -> np.ndarray:
    """(N, 2) inputs [F_n, F_load] (N) of a held object that does not slip: a slowly wandering
    tangential load (3 Hz band-limited, std ``load_std``) and grip force, handling taps (half-cosine
    load pulses, Poisson ``tap_rate`` per s) and grip-force steps of the controller (10 ms ramps).
    The defaults keep |F_load| well under μ_s F_n; check the contact's ``slipping`` output for the
    ground truth."""
    rate = 1.0 / dt
    from scipy.signal import butter, sosfilt

    rng = np.random.default_rng(rng)
    n = int(round(duration * rate))
    if n < 10:
        raise DataError(f"duration {duration} s at dt = {dt:g} s gives fewer than 10 samples")
    sos = butter(2, 3.0, fs=rate, output="sos")
    w1 = sosfilt(sos, rng.standard_normal(n))
    w2 = sosfilt(sos, rng.standard_normal(n))
    w1 /= w1.std()
    w2 /= w2.std()
    Fl = load + load_std * w1
    Fn = normal_force + grip_std * w2
    for t0 in rng.uniform(0, duration, rng.poisson(tap_rate * duration)):
        i0 = int(t0 * rate)
        L = max(2, int(rng.uniform(*tap_duration) * rate))
        amp = rng.uniform(*tap_amplitude) * rng.choice([-1.0, 1.0])
        m = min(L, n - i0)
        Fl[i0:i0 + m] += amp * 0.5 * (1 - np.cos(2 * np.pi * np.arange(m) / L))
    for t0 in rng.uniform(0, duration, rng.poisson(grip_step_rate * duration)):
        i0 = int(t0 * rate)
        amp = rng.uniform(-grip_step, grip_step)
        L = max(1, int(0.01 * rate))
        ramp = np.minimum(np.arange(n - i0) / L, 1.0) * amp
        Fn[i0:] += ramp
    return np.column_stack([np.maximum(Fn, min_normal), Fl])


def slip_onset_inputs(duration: float, *, dt: float, normal_force: float = 2.0, load0: float = 0.6,
                      start: float = 0.3, rate: float = 3.0) -> np.ndarray:
    """(N, 2) inputs [F_n, F_load]: a constant grip and a tangential load that ramps from ``load0``
    at ``start`` s at ``rate`` N/s until the object slips (μ_s F_n is crossed)."""
    n = int(round(duration / dt))
    t = np.arange(n) * dt
    Fl = np.where(t > start, load0 + (t - start) * rate, load0)
    return np.column_stack([np.full(n, float(normal_force)), Fl])
