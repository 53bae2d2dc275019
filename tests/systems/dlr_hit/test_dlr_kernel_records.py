"""A guard for refactoring the DLR/HIT finger kernels (issue 12's named records): every path of
the kernels (four friction models, RK4, thermal, the parallel hand, joint and Cartesian impedance
with a wall, friction drift and online adaptation) gives the recorded trajectories
(tests/reference/kernel_records.json, written by tests/reference/record_kernels.py) to
RECORD_RTOL (tests/conftest.py): exact on the machine that recorded them, ~1e-16 apart on
another CPU."""

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from gripkit.errors import ConsistencyWarning
from gripkit.systems.dlr_hit.friction_adaptation import tracking_reference
from gripkit.systems.dlr_hit.friction_drift import stiction_step, warmup_drift
from gripkit.systems.dlr_hit.hand import hand
from gripkit.systems.dlr_hit.impedance import (LOOP_ADAPTATION, ImpedanceController, Wall,
                                               simulate_impedance)
from gripkit.systems.dlr_hit.parameters import finger

DEG = math.pi / 180
REFERENCE = (json.loads((Path(__file__).parents[2] / "reference"
                         / "kernel_records.json").read_text())["dlr_hit"])


def _pwm(n):
    t = np.arange(n) * 1e-3
    return np.column_stack([2500 * np.sin(2 * math.pi * 3 * t),
                            -3000 * np.sin(2 * math.pi * 2 * t + 0.4),
                            np.where(t < 0.15, 3900.0, -1500.0)])


def _trajectories():
    """The recorded scenarios: near the proximal end stop, sign-changing PWM on all three drives
    (stick-slip, end-stop contact); each friction model; RK4; the five-finger hand; impedance
    loops with a warm-up drift and a stiction step, with and without adaptation; a Cartesian
    impedance pressing on a wall with two substeps."""
    out = {}
    x0q = (10 * DEG, 20 * DEG, 80 * DEG)
    for fr in ("table", "stribeck", "lugre", "none"):
        f = finger(check=False, friction=fr, thermal=(fr == "stribeck"))
        out[f"open_{fr}"] = f.simulate(_pwm(300), dt=1e-3, x0=f.state(q=x0q)).as_array()
    f = finger(check=False, integrator="rk4", friction="table")
    out["open_rk4_table"] = f.simulate(_pwm(300), dt=1e-3, x0=f.state(q=x0q)).as_array()
    f = finger(check=False, integrator="rk4", friction="lugre", thermal=True)
    out["open_rk4_lugre"] = f.simulate(_pwm(300), dt=1e-3, x0=f.state(q=x0q)).as_array()
    uh = np.tile(_pwm(120), (1, 5)) * np.repeat([1.0, 0.8, -0.6, 0.5, 1.1], 3)
    out["hand_parallel"] = hand(check=False).simulate(uh, dt=1e-3).as_array()
    f = finger(check=False)
    ref = tracking_reference(0.4)
    drift = warmup_drift(0.4).combine(stiction_step(0.2))
    joint = ImpedanceController("joint", (8, 8, 8), (0.6, 0.6, 0.6))
    adaptive = ImpedanceController("joint", (8, 8, 8), (0.6, 0.6, 0.6), adaptation=LOOP_ADAPTATION)
    out["joint_adapt_drift"] = simulate_impedance(f, adaptive, ref, friction_drift=drift).as_array()
    out["joint_stribeck_drift"] = simulate_impedance(finger(check=False, friction="stribeck"),
                                                     joint, ref,
                                                     friction_drift=drift).as_array()
    cart = (ImpedanceController("cartesian", (400, 400, 400), (4, 4, 4),
                                actuator_damping=(0.02, 0.02, 0.02)))
    x0 = f.state(q=(0.0, 30 * DEG, 30 * DEG))
    tip0 = f.chain().tip_position(x0[:3])
    wall = (Wall(normal=(0.0, 0.0, 1.0), point=tuple(tip0 - np.array([0.0, 0.0, 0.005])),
                 stiffness=2e3, damping=5.0))
    out["cartesian_wall"] = simulate_impedance(f, cart,
                                               np.tile(tip0 + np.array([0.0, 0.0, -0.01]),
                                                                (300, 1)),
                                               x0=x0, wall=wall, substeps=2).as_array()
    return out


@pytest.fixture(scope="module")
def trajectories():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ConsistencyWarning)
        return _trajectories()


@pytest.mark.parametrize("name", sorted(REFERENCE))
def test_trajectories_are_the_recorded_ones(trajectories, name, assert_matches_record):
    assert_matches_record(name, trajectories[name], REFERENCE[name])


def test_parameter_index_names_every_parameter_and_compiles_to_a_constant():
    """``IX`` (generated from FINGER_PARAMETERS) maps each name to its position, and numba folds an
    index read from it into the load's address: the compiled ``th[IX.fs_base1 + k]`` has the
    constant byte offset 8·index and loads nothing from ``IX`` at run time."""
    import numba

    from gripkit.systems.dlr_hit.finger import FINGER_PARAMETERS, IX

    assert (list(IX._fields) == list(FINGER_PARAMETERS)
            and list(IX) == list(range(len(FINGER_PARAMETERS))))

    @numba.njit
    def stiction(th, k):
        return th[IX.fs_base1 + k]

    th = np.arange(len(FINGER_PARAMETERS), dtype=np.float64)
    assert stiction(th, 1) == IX.fs_base1 + 1
    ir = stiction.inspect_llvm(stiction.signatures[0])
    assert f"i64 {8 * IX.fs_base1}" in ir


def test_closed_loop_output_columns_follow_the_generated_index_table():
    """The kernels write block b of the closed-loop outputs from column YL.b on; the column names
    and units (impedance.LOOP_OUTPUTS) come from the same block table, in the same order."""
    from gripkit.systems.dlr_hit.finger import LOOP_OUTPUT_BLOCKS, YF, YL
    from gripkit.systems.dlr_hit.impedance import LOOP_OUTPUTS

    assert tuple(LOOP_OUTPUTS) == LOOP_OUTPUT_BLOCKS
    assert [getattr(YL, b) for b in LOOP_OUTPUT_BLOCKS] == list(range(0, 39, 3))
    assert all(len(names) == 3 for names, _ in LOOP_OUTPUTS.values())
    assert YL.scale_hat == 27 and YL.fric_ff == 36 and YF.temperature == 15
