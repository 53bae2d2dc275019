"""The FemtoTools FT-G100 electrostatic MEMS microgripper (``003_abd62b560633beaf.txt``).

- :mod:`.parameters` — every number the seed gives, with provenance (the one home of them);
- :mod:`.model` — the knowledge-based models, which read those numbers: actuated and sensing
  subsystems, the coupled model, the nonlinear plant, the discrete state space at 20 kHz
  (eqs 1–18), and the zoo's model factories;
- :mod:`.identification` — the seed's identification experiments, simulated, and their
  Levenberg-Marquardt identification (§III-B, §III-D);
- :mod:`.hybrid_control` — hybrid force/position control of the gripper arm (the seed's future
  work); :mod:`.scenario` — the ``ftg100-grasp`` sweep scenario;
- :mod:`.demo` — the demo-report section.

A flat list of explicit re-exports.
"""

from .hybrid_control import HybridForcePosition as HybridForcePosition
from .hybrid_control import HybridGraspResult as HybridGraspResult
from .hybrid_control import simulate_hybrid_grasp as simulate_hybrid_grasp
from .model import FTG100Actuated as FTG100Actuated
from .model import FTG100Coupled as FTG100Coupled
from .model import FTG100Plant as FTG100Plant
from .model import FTG100Sensing as FTG100Sensing

__all__ = ["FTG100Actuated", "FTG100Coupled", "FTG100Plant", "FTG100Sensing", "HybridForcePosition",
           "HybridGraspResult", "simulate_hybrid_grasp"]
