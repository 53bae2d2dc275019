"""The DLR/HIT Hand II modular finger (``002_ddea254371185ad3.txt``).

- :mod:`.finger` — the complete finger of chapter 7: PWM → BLDC motor (eq 5.10) → belts and
  harmonic drive → friction with stick-slip → coupled Newton-Euler dynamics;
- :mod:`.parameters` — the thesis's parameters with provenance (Table 6.1, Appendices F and G),
  Appendix G's friction tables, the zoo's finger and its consistency checks;
- :mod:`.hand` — five fingers on a palm (§3.1, §6.3), the zoo's hand;
- :mod:`.impedance` — joint and Cartesian impedance control with gravity and friction
  compensation, with online friction adaptation inside the loop; :mod:`.friction_adaptation` —
  the adapter on a finger log and the loop with/without adaptation compared;
  :mod:`.friction_drift` — the plant's friction changing during a run (Fig. 5.7 warm-up,
  stiction step);
- :mod:`.demo` — the demo-report section.

A flat list of explicit re-exports.
"""

from .finger import DLRFinger as DLRFinger
from .friction_adaptation import adapt_finger_friction as adapt_finger_friction
from .friction_adaptation import compare_adaptation as compare_adaptation
from .friction_drift import FrictionDrift as FrictionDrift
from .friction_drift import stiction_step as stiction_step
from .friction_drift import warmup_drift as warmup_drift
from .hand import DLRHand as DLRHand
from .impedance import LOOP_ADAPTATION as LOOP_ADAPTATION
from .impedance import ImpedanceController as ImpedanceController
from .impedance import Wall as Wall
from .impedance import impedance_margins as impedance_margins
from .impedance import simulate_impedance as simulate_impedance
from .impedance import stability_margins as stability_margins
from .parameters import DLRHITFinger as DLRHITFinger

__all__ = ["adapt_finger_friction", "compare_adaptation", "DLRFinger", "DLRHand", "DLRHITFinger",
           "FrictionDrift", "impedance_margins", "ImpedanceController", "LOOP_ADAPTATION",
           "simulate_impedance", "stability_margins", "stiction_step", "Wall", "warmup_drift"]
