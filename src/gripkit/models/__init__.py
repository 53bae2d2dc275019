"""Physical model components (one concept per module)."""

from .mass_spring_damper import MassSpringDamper as MassSpringDamper
from .hysteresis import BoucWen as BoucWen
from .piezo import PiezoActuator as PiezoActuator
from .tsfm import TSFMFinger as TSFMFinger
from .tsfm import TSFMFingerContact as TSFMFingerContact
from .tsfm import TSFMGripper as TSFMGripper
