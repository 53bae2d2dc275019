"""Properties of the rigid-body kernels: the mass matrix is symmetric positive definite
(hypothesis), Ṁ − 2C is skew (energy balance), energy is conserved by the frictionless unforced
chain to the integrator's accuracy (RK4: error ∝ h⁴), and bad descriptions are refused."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from gripkit.errors import ModelError, SimulationError
from gripkit.multibody import Coupling, CoupledChain, DHChain
from gripkit.systems.dlr_hit.parameters import finger


def chain_from(seed, n, prismatic=False):
    rng = np.random.default_rng(seed)
    inertia = []
    for _ in range(n):
        Q, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        inertia.append(Q @ np.diag(rng.uniform(0.5, 1.0, 3) * 1e-3) @ Q.T)
    types = "".join("P" if (prismatic and k % 2) else "R" for k in range(n))
    return DHChain(alpha=rng.uniform(-3, 3, n), a=rng.uniform(0, 0.3, n),
                   d=rng.uniform(-0.1, 0.1, n),
                   theta_offset=rng.uniform(-1, 1, n), joint_types=types,
                   mass=rng.uniform(0.05, 1.0, n),
                   com=rng.normal(size=(n, 3)) * 0.05, inertia=np.array(inertia),
                   gravity=(0, 0, -9.81))


@given(seed=st.integers(0, 10_000), n=st.integers(1, 7), prismatic=st.booleans(),
       q=st.lists(st.floats(-math.pi, math.pi), min_size=7, max_size=7))
def test_mass_matrix_symmetric_positive_definite(seed, n, prismatic, q):
    ch = chain_from(seed, n, prismatic)
    M = ch.mass_matrix(np.array(q[:n]))
    np.testing.assert_allclose(M, M.T, rtol=0, atol=1e-14 * max(1.0, np.abs(M).max()))
    assert np.linalg.eigvalsh(M).min() > 0


@given(q=st.lists(st.floats(-math.pi, math.pi), min_size=3, max_size=3))
def test_finger_mass_matrix_spd(q):
    ch = finger(check=False).chain()
    M = ch.mass_matrix(np.array(q))
    np.testing.assert_allclose(M, M.T, rtol=0, atol=1e-16)
    assert np.linalg.eigvalsh(M).min() > 0.02  # the reflected rotor inertia alone is ≥ 0.0221 kg·m²


@given(seed=st.integers(0, 10_000), n=st.integers(1, 6), prismatic=st.booleans(),
       coupled=st.booleans())
def test_one_state_path_equals_the_batched_kernels(seed, n, prismatic, coupled):
    """``rnea`` and ``mass_matrix`` on one float64 state (the low-overhead path of
    gripkit.multibody.onestate) give the batched kernels' values bit for bit on DH chains, with
    and without a coupling Γ (random n×m, m ≤ n, with offsets and armature)."""
    ch = chain_from(seed, n, prismatic)
    rng = np.random.default_rng(seed)
    if coupled:
        m = int(rng.integers(1, n + 1))
        ch = CoupledChain(ch, Coupling(rng.normal(size=(n, m)), rng.normal(size=n) * 0.1,
                                       rng.uniform(0, 1e-3, m), tuple(f"a{k}" for k in range(m))))
    q, qd, qdd = rng.normal(size=(3, 1, ch.dof))
    np.testing.assert_array_equal(ch.mass_matrix(q[0]), ch.mass_matrix(q)[0])
    np.testing.assert_array_equal(ch.rnea(q[0], qd[0], qdd[0]), ch.rnea(q, qd, qdd)[0])


def test_one_state_path_hands_bad_states_to_the_checks():
    """A state of the wrong length or with NaN gets the validating path's ModelError; a list, a
    float32 array or a strided view is converted there and gives the float64 answer."""
    ch = finger(check=False).chain()
    q = np.array([0.1, -0.2, 0.3])
    with pytest.raises(ModelError, match="expected shape"):
        ch.mass_matrix(q[:2])
    with pytest.raises(ModelError, match="NaN"):
        ch.mass_matrix(np.array([np.nan, 0.0, 0.0]))
    np.testing.assert_allclose(ch.mass_matrix(q.tolist()), ch.mass_matrix(q), rtol=1e-15)
    np.testing.assert_allclose(ch.mass_matrix(q.astype(np.float32)),
                               ch.mass_matrix(q.astype(np.float32).astype(float)),
                               rtol=1e-15)
    # a non-contiguous view: the kernel refuses it, the checks copy it
    strided = np.column_stack([q, -q])[:, 0]
    np.testing.assert_array_equal(ch.mass_matrix(strided), ch.mass_matrix(q))


def test_one_state_out_workspace():
    """``out=``: a controller's preallocated workspace gets the same values bit for bit and is
    returned; a strided out is filled through the validating path; an out of the wrong shape,
    dtype or a read-only one is refused with an ArgumentError naming it (the kernel writes
    nothing out of bounds); a bad state still gets the ModelError."""
    from gripkit.errors import ArgumentError

    ch = finger(check=False).chain()
    q, qd, qdd = np.array([0.1, -0.2, 0.3]), np.array([1.0, 0.5, -2.0]), np.array([3.0, -1.0, 0.5])
    M, tau = np.full((3, 3), np.nan), np.full(3, np.nan)
    assert ch.mass_matrix(q, out=M) is M and ch.rnea(q, qd, qdd, out=tau) is tau
    np.testing.assert_array_equal(M, ch.mass_matrix(q))
    M2 = np.full((3, 3), np.nan)  # out by position (the parameter is not keyword-only)
    assert ch.mass_matrix(q, M2) is M2
    np.testing.assert_array_equal(M2, M)
    np.testing.assert_array_equal(tau, ch.rnea(q, qd, qdd))
    strided = np.zeros((3, 6))[:, ::2]
    np.testing.assert_array_equal(ch.mass_matrix(q, out=strided), M)
    np.testing.assert_array_equal(ch.rnea(q, qd, qdd, gravity=False, out=tau),
                                  ch.rnea(q, qd, qdd, gravity=False))
    for bad in (np.empty((2, 2)), np.empty((3, 3), dtype=np.float32), np.empty(9), [[0.0] * 3] * 3):
        with pytest.raises(ArgumentError, match=r"out: expected a writable float64 array "
                                                r"of shape \(3, 3\)"):
            ch.mass_matrix(q, out=bad)
    ro = np.empty(3)
    ro.flags.writeable = False
    with pytest.raises(ArgumentError, match="read-only"):
        ch.rnea(q, qd, qdd, out=ro)
    with pytest.raises(ArgumentError, match=r"shape \(3,\)"):
        ch.rnea(q, qd, qdd, out=np.empty(4))
    with pytest.raises(ModelError, match="NaN"):
        ch.mass_matrix(np.array([np.nan, 0.0, 0.0]), out=M)


def test_power_balance_qd_C_equals_half_qd_Mdot_qd():
    """q̇ᵀ(Ṁ/2 − C_mat)q̇ = 0, i.e. q̇ᵀ c(q, q̇) = ½ q̇ᵀ Ṁ q̇ for the Coriolis vector c (Ṁ by
    central
    differences along q̇)."""
    ch = chain_from(4, 5)
    rng = np.random.default_rng(0)
    for _ in range(10):
        q, qd = rng.normal(size=(2, 5))
        eps = 1e-6
        Mdot = (ch.mass_matrix(q + eps * qd) - ch.mass_matrix(q - eps * qd)) / (2 * eps)
        assert qd @ ch.coriolis(q, qd) == pytest.approx(0.5 * qd @ Mdot @ qd, rel=1e-7, abs=1e-12)


def test_energy_conserved_to_rk4_accuracy():
    """Frictionless, unforced chain: the energy error after 2 s is the integrator's — it shrinks
    by 2⁴ = 16 (within 20 %) each time the step halves, and is below 1e-6 of the energy at
    h = 1 ms."""
    ch = chain_from(12, 4)
    q0 = np.array([0.3, -0.5, 1.0, 0.2])
    qd0 = np.array([1.0, -2.0, 0.5, 3.0])
    E0 = ch.energy(q0, qd0)
    drifts = []
    for h in (4e-3, 2e-3, 1e-3):
        N = int(round(2.0 / h))
        q, qd = ch.simulate_free(q0, qd0, np.zeros((N + 1, 4)), h, method="rk4")
        drifts.append(np.max(np.abs(ch.energy(q, qd) - E0)))
    for a, b in zip(drifts[:-1], drifts[1:]):
        assert 16 / 1.2 < a / b < 16 * 1.2
    assert drifts[-1] < 1e-6 * abs(E0)


def test_constant_torque_work_energy_balance():
    """With a constant torque τ, E(t) − E0 = τ·(q(t) − q0) (work done)."""
    ch = chain_from(6, 3)
    tau = np.array([0.2, -0.1, 0.05])
    def balance_error(h):
        n = int(round(1.0 / h)) + 1
        q, qd = ch.simulate_free(np.zeros(3), np.zeros(3), np.tile(tau, (n, 1)), h, method="rk4")
        return np.abs(ch.energy(q, qd) - ch.energy(q, qd)[0] - (q - q[0]) @ tau).max()

    # RK4's global error is C·h⁴: the run at h/2 estimates it by Richardson (e_h ≈ 16·e_{h/2}), so
    # at h it is bounded by 2·16·e_{h/2}, plus the roundings of 1000 steps.
    e_h, e_half = balance_error(1e-3), balance_error(5e-4)
    assert e_h < 2 * 16 * e_half + 1000 * np.finfo(np.float64).eps
    assert e_h < 1e-9  # the balance itself holds to the integrator's accuracy


def test_coupled_forward_dynamics_inverts_rnea():
    ch = finger(check=False).chain()
    rng = np.random.default_rng(1)
    p, pd, pdd = rng.normal(size=(3, 20, 3))
    np.testing.assert_allclose(ch.forward_dynamics(p, pd, ch.rnea(p, pd, pdd)), pdd, atol=1e-10)


@pytest.mark.parametrize("kwargs, match", [
    (dict(alpha=[0, 0], a=[0, 1], d=[0]), "d: expected shape"),
    (dict(alpha=[0], a=[0], d=[0], mass=[-1.0]), "mass"),
    (dict(alpha=[0], a=[0], d=[0], inertia=[np.diag([1.0, 0.1, 0.1])]), "triangle inequality"),
    (dict(alpha=[0], a=[np.nan], d=[0]), "NaN"),
    (dict(alpha=[0], a=[0], d=[0], joint_types="X"), "joint_types"),
])
def test_bad_chains_are_refused(kwargs, match):
    with pytest.raises(ModelError, match=match):
        DHChain(**kwargs)


def test_bad_states_and_couplings_are_refused():
    ch = chain_from(1, 3)
    with pytest.raises(ModelError, match=r"expected shape \(3,\)"):
        ch.mass_matrix(np.zeros(4))
    with pytest.raises(ModelError, match="NaN"):
        ch.gravity([0.0, np.nan, 0.0])
    with pytest.raises(ModelError, match="full column rank"):
        Coupling(np.ones((3, 2)), np.zeros(3), np.zeros(2), ("a", "b"))
    with pytest.raises(ModelError, match="joint rows"):
        CoupledChain(ch, Coupling(np.eye(2), np.zeros(2), np.zeros(2), ("a", "b")))
    with pytest.raises(SimulationError, match="method"):
        ch.simulate_free(np.zeros(3), np.zeros(3), np.zeros((2, 3)), 1e-3, method="euler")


def test_one_state_mass_matrix_entry_point_takes_only_exact_float64_vectors():
    """The unchecked entry point (onestate.mass_matrix_entry) gets only a 1-D native float64
    array (ndim, dtype checked in Python): states that numba would misread there (int64 items of
    the same size, a (3, 1) array, big-endian) go through the validating path and give the
    float64 answer; an object with a float64 dtype that is not an ndarray (the entry point's
    TypeError) and a list take that path too; an ndarray subclass reaches it and gives the same
    numbers; 1-D views of another stride reach it and its kernel refuses them; each call returns
    a new array (no result is shared between calls)."""
    ch = finger(check=False).chain()
    q = np.array([0.1, -0.2, 0.3])
    ref = ch.mass_matrix(q)
    a, b = ch.mass_matrix(q), ch.mass_matrix(np.array([1.0, 0.5, -0.5]))
    assert a is not b and not np.shares_memory(a, b)
    np.testing.assert_array_equal(a, ref)
    qi = np.array([1, -2, 3])
    np.testing.assert_array_equal(ch.mass_matrix(qi), ch.mass_matrix(qi.astype(float)))
    np.testing.assert_array_equal(ch.mass_matrix(q.astype(">f8")), ref)
    np.testing.assert_array_equal(ch.mass_matrix(q.view(_Sub)), ref)
    np.testing.assert_array_equal(ch.mass_matrix(_ArrayLike(q)), ref)
    np.testing.assert_array_equal(ch.mass_matrix(list(q)), ref)
    with pytest.raises(ModelError, match="expected shape"):
        ch.mass_matrix(q[:, None])
    ro = q.copy()
    ro.flags.writeable = False
    np.testing.assert_array_equal(ch.mass_matrix(ro), ref)
    # 1-D float64 views of stride −8 and 16 reach the entry point, whose kernel refuses them
    # (it would read them as contiguous) and leaves its output untouched
    rev = np.array([0.3, -0.2, 0.1])[::-1]
    wide = np.array([0.1, 9.0, -0.2, 9.0, 0.3])[::2]
    buf, _, _, entry = ch._one
    for view in (rev, wide):
        np.testing.assert_array_equal(ch.mass_matrix(view), ref)
        M = np.full((3, 3), 7.0)
        assert not entry(buf, view, M) and (M == 7.0).all()
    M = np.full((3, 3), 7.0)
    assert entry(buf, q, M)
    np.testing.assert_array_equal(M, ref)


class _Sub(np.ndarray):
    """An ndarray subclass."""


class _ArrayLike:
    """Not an ndarray, with the float64 dtype and ndim of one (a pandas Series, say)."""

    ndim = 1
    dtype = np.dtype(np.float64)

    def __init__(self, values):
        self._values = values

    def __array__(self, dtype=None, copy=None):
        return np.asarray(self._values, dtype=dtype)


def test_one_state_path_runs_with_numba_jit_disabled():
    """Under NUMBA_DISABLE_JIT=1 (a user stepping through the kernels in a debugger) the
    one-state mass matrix and RNEA run as Python (no compiled entry point, the packed views by
    slicing) and give the compiled results (to rounding: Python has no fused multiply-add)."""
    import json
    import os
    import subprocess
    import sys

    code = (
        "import json, numpy as np\n"
        "from gripkit.multibody.dh import DHChain\n"
        "rng = np.random.default_rng(1); n = 3\n"
        "c = DHChain(alpha=rng.uniform(-3, 3, n), a=rng.uniform(0, 0.3, n),\n"
        "            d=rng.uniform(0, 0.3, n), mass=rng.uniform(0.1, 2, n),\n"
        "            com=rng.uniform(-0.1, 0.1, (n, 3)),\n"
        "            inertia=np.tile(np.eye(3) * 0.01, (n, 1, 1)))\n"
        "q = rng.standard_normal(n)\n"
        "print(json.dumps([c.mass_matrix(q).tolist(), c.rnea(q, q, q).tolist()]))\n")
    env = dict(os.environ, NUMBA_DISABLE_JIT="1")
    proc = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    M_py, tau_py = json.loads(proc.stdout)
    scope: dict = {}
    exec(code.replace("print(json.dumps([c.mass_matrix(q).tolist(), c.rnea(q, q, q).tolist()]))",
                      "out = (c.mass_matrix(q), c.rnea(q, q, q))"), scope)
    M, tau = scope["out"]
    np.testing.assert_allclose(M_py, M, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(tau_py, tau, rtol=1e-12, atol=1e-15)
