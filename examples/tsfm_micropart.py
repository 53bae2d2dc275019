"""Measure a micropart's width and stiffness with the TSFM microgripper and no position sensor
(001_0b92a7da96e7aa46.txt §V-C/D): both fingers close on a 300 µm part of Table III's 72.5 N/m,
the tips are estimated from voltage and force (eq 11), contact is detected at 5 µN, and the width
w = gap − (y1 + y2) and stiffness k = F/δ (eq 16) come out with their uncertainties."""

from gripkit.systems.tsfm import parameters as tsfm
from gripkit.systems.tsfm.grasp import GraspSettings, simulate_two_finger_grasp

gripper = tsfm.gripper(stiffness=72.5, width=300e-6, centre=220e-6, check=False)  # 20 µm off-centre
# (check=False: the Table II contradictions are reported by `gripkit zoo check tsfm-gripper`)
res = simulate_two_finger_grasp(gripper, settings=GraspSettings(grip_force=150e-6), duration=3.0,
                                noise_std=2e-6, seed=1)
est = res.estimate
print(f"width: {est.width * 1e6:.3f} ± {est.width_std * 1e6:.3f} µm (true 300 µm)")
print(f"stiffness: {est.stiffness:.1f} ± {est.stiffness_std:.1f} N/m (true 72.5 N/m)")
print(f"part moved by {res.part_displacement * 1e6:.2f} µm while grasped")
