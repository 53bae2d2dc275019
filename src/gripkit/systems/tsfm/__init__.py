"""The two-smart-fingers piezoelectric microgripper, TSFM (``001_0b92a7da96e7aa46.txt``).

- :mod:`.parameters` — Table II/III with provenance, the zoo's fingers and gripper, simulated
  experiments;
- :mod:`.end_effector`, :mod:`.gripper` — the sensorized end-effector (lever + force sensor,
  eqs 5–10) and one finger / both fingers with hybrid contacts (eqs 3–13);
- :mod:`.identification` — the §IV procedure for one finger;
- :mod:`.tip_position`, :mod:`.micropart` — end-effector position and micropart width/stiffness
  estimation (§V);
- :mod:`.stiffness_study` — Table III reproduced by the seed's whole protocol, k̂ ± σ beside the
  seed's "Estimated" column;
- :mod:`.grasp` — the two-finger grasp (§I); :mod:`.grasp_batch` (with :mod:`.grasp_kernels`,
  :mod:`.grasp_gpu`) — many grasps at once, the sweep scenario ``tsfm-grasp``;
- :mod:`.robustness` — the Monte Carlo grasp robustness study on that scenario (its statistics
  from :mod:`gripkit.batch.montecarlo`);
- :mod:`.demo` — the demo-report section.

A flat list of explicit re-exports.
"""

from .grasp import GraspSettings as GraspSettings
from .grasp import TwoFingerGrasp as TwoFingerGrasp
from .grasp import TwoFingerGraspResult as TwoFingerGraspResult
from .grasp import simulate_two_finger_grasp as simulate_two_finger_grasp
from .gripper import TSFMFinger as TSFMFinger
from .gripper import TSFMFingerContact as TSFMFingerContact
from .gripper import TSFMGripper as TSFMGripper
from .identification import FingerIdentification as FingerIdentification
from .identification import identify_finger as identify_finger
from .micropart import MicropartEstimate as MicropartEstimate
from .micropart import estimate_micropart as estimate_micropart
from .stiffness_study import StiffnessComparison as StiffnessComparison
from .stiffness_study import TableIIIStudy as TableIIIStudy
from .stiffness_study import table_iii_study as table_iii_study
from .tip_position import TipPositionEstimator as TipPositionEstimator

__all__ = ["estimate_micropart", "FingerIdentification", "GraspSettings", "identify_finger",
           "MicropartEstimate", "simulate_two_finger_grasp", "StiffnessComparison",
           "table_iii_study",
           "TableIIIStudy", "TipPositionEstimator", "TSFMFinger", "TSFMFingerContact",
           "TSFMGripper",
           "TwoFingerGrasp", "TwoFingerGraspResult"]
