"""Physical model components (one concept per module)."""

from .mass_spring_damper import MassSpringDamper as MassSpringDamper
from .bellows_finger import BellowsFinger as BellowsFinger
