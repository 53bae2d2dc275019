"""Physical model components (one concept per module)."""

from .mass_spring_damper import MassSpringDamper as MassSpringDamper
from .hysteresis import BoucWen as BoucWen
from .piezo import PiezoActuator as PiezoActuator
