"""The TSFM grasp as a batch scenario: the metrics-only kernel reproduces the single-grasp
simulation (``simulate_two_finger_grasp``, 001_0b92a7da96e7aa46.txt §I) job by job, the physics
of the population shows (stiffer parts, higher peaks; the hold strategy keeps centred parts), and
the sweep scenarios give the same numbers whatever the chunking or backend."""

import math
import warnings
from dataclasses import replace

import numpy as np
import pytest

from gripkit.batch import SweepSpec, sweep
from gripkit.errors import ConfigError
from gripkit.systems.tsfm import simulate_two_finger_grasp
from gripkit.systems.tsfm import parameters as z
from gripkit.systems.tsfm.grasp_batch import FAST_GRASP, METRICS, record_metrics, tsfm_grasp_batch

FS, DUR = 20000.0, 0.06
# sums: order-dependent
EXACT = [m for m in METRICS if m not in ("final_error", "final_force", "stiffness_error")]


@pytest.fixture(scope="module")
def gripper():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return z.gripper(check=False)


def test_batch_kernel_reproduces_the_single_grasp(gripper):
    """Three parts (stiffness from Table III's range, widths, off-centre positions, approach
    speeds): the batch kernel, fed the same sensor noise, gives the metrics computed with numpy
    from the full record of simulate_two_finger_grasp — bit for bit for the sample-wise metrics,
    to 1e-12 for the averaged ones (summation order)."""
    jobs = ([(72.5, 370e-6, 200e-6, 1e-3), (469.0, 360e-6, 206e-6, 1.5e-3),
             (12.1, 380e-6, 196e-6, 0.8e-3)])
    N = int(DUR * FS)
    refs, noises = [], []
    for j, (k, w, xp, v) in enumerate(jobs):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            g = z.gripper(stiffness=k, width=w, centre=xp, check=False)
        r = simulate_two_finger_grasp(g, settings=replace(FAST_GRASP, approach_speed=v),
                                      duration=DUR, dt=1 / FS,
                                      noise_std=2e-6, seed=j)
        refs.append(record_metrics(r, gap=400e-6, width=w, stiffness=k))
        noises.append(np.random.default_rng(j).standard_normal((N, 2)) * 2e-6)  # the noise it drew
    res = tsfm_grasp_batch(gripper, k_e=[j[0] for j in jobs], w=[j[1] for j in jobs],
                           X_p=[j[2] for j in jobs],
                           approach_speed=[j[3] for j in jobs], noise=np.array(noises),
                           duration=DUR, dt=1 / FS)
    for m in METRICS:
        ref = np.array([r[m] for r in refs])
        if m in EXACT:
            np.testing.assert_array_equal(res[m], ref, err_msg=m)
        else:
            np.testing.assert_allclose(res[m], ref, rtol=1e-12, err_msg=m)
    # §V-C: < 2 µm
    assert np.isfinite(res["width_error"]).all() and (np.abs(res["width_error"]) < 2e-6).all()
    assert (res["grasped"] == 1).all()


def test_stiffer_parts_give_higher_peaks_and_damage(gripper):
    """Fixed controller, centred 370 µm part, no noise: the impact and the force loop's overshoot
    grow with the part's stiffness; 1000 N/m crosses a 250 µN damage force, 10 N/m does not."""
    k = np.array([10.0, 100.0, 1000.0])
    res = (tsfm_grasp_batch(gripper, k_e=k, w=370e-6, noise_std=0.0, duration=0.1,
                            damage_force=250e-6))
    assert np.all(np.diff(res["peak_force"]) > 0)
    assert res["damage"].tolist() == [0.0, 0.0, 1.0]
    assert res["peak_force"][0] == pytest.approx(200e-6, rel=0.03)  # a soft part: no overshoot


def test_the_hold_strategy_keeps_centred_parts_the_naive_grasp_loses_off_centre_ones(gripper):
    """§I: the finger that touches first waits. Centred parts over 10-1000 N/m and widths of
    320-380 µm are never lost (grasped, displaced < 5 µm, median < 1 µm); parts 20 µm off-centre on
    20 µN
    friction are pushed away by the naive grasp (wait_for_other=False)."""
    rng = np.random.default_rng(5)
    n = 16
    k = np.exp(rng.uniform(np.log(10), np.log(1000), n))
    w = rng.uniform(320e-6, 380e-6, n)
    ok = tsfm_grasp_batch(gripper, k_e=k, w=w, offset=0.0, approach_speed=1.5e-3, duration=0.12)
    assert (ok["lost"] == 0).all() and (ok["grasped"] == 1).all()
    assert ok["max_displacement"].max() < 5e-6 and np.median(ok["max_displacement"]) < 1e-6
    naive = tsfm_grasp_batch(gripper, k_e=k, w=np.minimum(w, 340e-6), offset=20e-6,
                             approach_speed=1.5e-3,
                             duration=0.12, settings=replace(FAST_GRASP, wait_for_other=False))
    assert naive["lost"].mean() > 0.5
    assert np.nanmin(naive["max_displacement"]) > 10e-6


def test_bad_parts_are_refused_with_a_clear_error(gripper):
    with pytest.raises(ConfigError, match="does not fit"):
        tsfm_grasp_batch(gripper, w=390e-6, offset=10e-6)
    with pytest.raises(ConfigError, match="k_e"):
        tsfm_grasp_batch(gripper, k_e=[-1.0, 2.0])


def _spec(chunk, **extra):
    return SweepSpec.from_dict({
        "sweep": {"scenario": "tsfm-grasp", "model": "tsfm-gripper", "samples": 8, "seed": 2,
                  "chunk_size": chunk},
        "parameters": {"k_e": {"loguniform": ["10 N/m", "1000 N/m"]},
                       "w": {"uniform": ["340 um", "380 um"]},
                       "noise_std": {"uniform": ["1 uN", "3 uN"]}, **extra},
        "scenario": {"duration": "40 ms", "grip_force": "150 uN"}})


def test_scenario_is_independent_of_chunking_and_backend(tmp_path):
    """Each job's noise is seeded by its job id: chunks of 8, of 3 on the process pool give the
    same table; a part that does not fit is one recorded failure, not a failed sweep."""
    a = sweep(_spec(8), backend="in-process", progress=False)
    b = sweep(_spec(3), backend="process", workers=2, out=tmp_path / "pp", progress=False)
    for m in ("peak_force", "settling_time", "t_contact1", "width_error", "final_error"):
        np.testing.assert_array_equal(a[m], b[m], err_msg=m)
    assert not a.failed.any()
    bad = sweep(_spec(8, offset={"grid": [0.0, 30e-6]}), backend="in-process", progress=False)
    assert bad.failed.sum() > 0 and all("does not fit" in e for _, e in bad.failures)
    assert np.isfinite(bad["peak_force"][~bad.failed]).all()


def test_ftg100_scenario_matches_grasp_batch():
    """The ftg100-grasp scenario is grasp_batch (seed = job id) in sweep form."""
    from gripkit.systems.ftg100.hybrid_control import grasp_batch

    spec = SweepSpec.from_dict({"sweep": {"scenario": "ftg100-grasp"},
                                "parameters": {"k0": {"grid": [520.0, 1560.0]}},
                                "scenario": {"duration": "30 ms", "approach_speed": "0.4 mm/s"}})
    res = sweep(spec, backend="in-process", progress=False)
    from gripkit.systems.ftg100.hybrid_control import HybridForcePosition

    ref = grasp_batch(HybridForcePosition.for_plant(approach_speed=4e-4),
                      k0=np.array([520.0, 1560.0]),
                      seed=np.arange(2), duration=0.03, progress=False)
    for m in ("peak_force", "settling_time", "overshoot_percent"):
        np.testing.assert_array_equal(res[m], ref[m])
    assert math.isfinite(res["peak_force"][0])


def test_settings_vector_is_read_by_name():
    """GraspSettings.vector in SETTINGS_VECTOR order: the entries the kernels read as cp[SX.<name>]
    are the settings given (the gains and dt passed, the commanded force, the loop bandwidths as
    2π f)."""
    from gripkit.systems.tsfm.grasp import SETTINGS_VECTOR, SX, GraspSettings
    gs = GraspSettings(grip_force=150e-6, position_bandwidth_hz=80.0, force_bandwidth_hz=15.0,
                       threshold=4e-6, release=2e-6, wait_for_other=False)
    cp = gs.vector((0.7, 0.9), 5e-5)
    assert cp.shape == (len(SETTINGS_VECTOR),)
    assert (cp[SX.gain1], cp[SX.gain2], cp[SX.dt]) == (0.7, 0.9, 5e-5)
    assert (cp[SX.grip_force], cp[SX.threshold], cp[SX.release]) == (150e-6, 4e-6, 2e-6)
    assert cp[SX.position_gain] == pytest.approx(2 * math.pi * 80.0, rel=1e-15)
    assert cp[SX.force_gain] == pytest.approx(2 * math.pi * 15.0, rel=1e-15)
    assert cp[SX.wait_for_other] == 0.0
