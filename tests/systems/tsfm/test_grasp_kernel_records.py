"""The TSFM grasp kernels take named records (issue 12): the single grasp of
``001_0b92a7da96e7aa46.txt`` §I (``simulate_two_finger_grasp``), the batch of grasps reduced to
their metrics and the open-loop two-finger gripper give the recorded results
(tests/reference/kernel_records.json, written by tests/reference/record_kernels.py) to
RECORD_RTOL (tests/conftest.py)."""

import json
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from gripkit.systems.tsfm import parameters as z
from gripkit.systems.tsfm import simulate_two_finger_grasp
from gripkit.systems.tsfm.grasp_batch import FAST_GRASP, METRICS, tsfm_grasp_batch

REFERENCE = (json.loads((Path(__file__).parents[2] / "reference"
                         / "kernel_records.json").read_text())["tsfm"])


def _results():
    """A stiff off-centre part (Table III's range) grasped with sensor noise; four batch jobs
    (soft to stiff parts, offsets, approach speeds, explicit zero and generated noise); the
    gripper driven open loop by two voltage ramps into contact (the kernel's unclipped
    outputs)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        g = z.gripper(stiffness=469.0, width=360e-6, centre=206e-6, check=False)
        out = {}
        r = simulate_two_finger_grasp(g, settings=replace(FAST_GRASP, approach_speed=1.5e-3),
                                      duration=0.03,
                                      dt=5e-05, noise_std=2e-6, seed=3)
        out["single_grasp"] = r.trajectory.as_array()
        res = tsfm_grasp_batch(k_e=[72.5, 800.0, 12.1, 300.0], w=[396e-6, 394e-6, 380e-6, 370e-6],
                               offset=[0.0, 1e-6, -3e-6, 2e-6],
                               approach_speed=[1e-3, 1.5e-3, 0.8e-3, 1.2e-3],
                               noise_std=[2e-6, 1e-6, 0.0, 3e-6], duration=0.02, serial=True)
        out["batch_serial"] = np.column_stack([res[m] for m in METRICS])
        u = np.column_stack([np.linspace(0, 60, 400), np.linspace(0, 55, 400)])
        # the kernel's outputs (simulate_batch): Model.simulate clips the sensor readings at the
        # 2 mN sensing range (gripper.RANGES), which this stiff part's 2.19 mN exceeds
        y = g.simulate_batch(g.theta()[None, :], u, dt=5e-5)[0]
        out["gripper_open"] = np.column_stack([u, y])
    return out


@pytest.fixture(scope="module")
def results():
    return _results()


@pytest.mark.parametrize("name", sorted(REFERENCE))
def test_results_are_the_recorded_ones(results, name, assert_matches_record):
    assert_matches_record(name, results[name], REFERENCE[name])
