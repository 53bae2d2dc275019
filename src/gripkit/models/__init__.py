"""Physical model components (one concept per module, naming no reference system): actuators
(piezo with Bouc-Wen hysteresis, electrostatic comb drive, BLDC motor), beams, friction,
transmissions, second-order and mass-spring-damper structures; :mod:`.reference` builds some with
reference values (the zoo's ``generic`` entries)."""

from .beams import clamped_clamped_stiffness as clamped_clamped_stiffness
from .beams import cubic_stiffness as cubic_stiffness
from .beams import suspension_force as suspension_force
from .bldc import BLDCMotor as BLDCMotor
from .bldc import MotorTestBed as MotorTestBed
from .comb_drive import comb_drive_force as comb_drive_force
from .comb_drive import comb_drive_voltage as comb_drive_voltage
from .friction import FrictionDrive as FrictionDrive
from .friction import FrictionTable as FrictionTable
from .friction import Stribeck as Stribeck
from .hysteresis import BoucWen as BoucWen
from .mass_spring_damper import MassSpringDamper as MassSpringDamper
from .piezo import PiezoActuator as PiezoActuator
from .reference import reference_bouc_wen as reference_bouc_wen
from .reference import reference_mass_spring_damper as reference_mass_spring_damper
from .reference import reference_piezo_actuator as reference_piezo_actuator
from .second_order import SecondOrderSystem as SecondOrderSystem
from .transmission import Transmission as Transmission
from .transmission import harmonic_drive as harmonic_drive
from .transmission import timing_belt as timing_belt

__all__ = ["BLDCMotor", "BoucWen", "FrictionDrive", "FrictionTable", "MassSpringDamper",
           "MotorTestBed",
           "PiezoActuator", "SecondOrderSystem", "Stribeck", "Transmission",
           "clamped_clamped_stiffness",
           "comb_drive_force", "comb_drive_voltage", "cubic_stiffness", "harmonic_drive",
           "reference_bouc_wen", "reference_mass_spring_damper", "reference_piezo_actuator",
           "suspension_force", "timing_belt"]
