"""gripkit: model, simulate, identify, estimate and control robotic grippers and fingers.

Subpackages: :mod:`gripkit.io`, :mod:`gripkit.signals`, :mod:`gripkit.sysid`, :mod:`gripkit.sim`,
:mod:`gripkit.models`, :mod:`gripkit.multibody`, :mod:`gripkit.estimation`,
:mod:`gripkit.control`, :mod:`gripkit.zoo`, :mod:`gripkit.batch`, :mod:`gripkit.report`.
Importing gripkit has no side effects and does not compile anything.
"""

from .consistency import ConsistencyReport as ConsistencyReport
from .consistency import Finding as Finding
from .consistency import check as check_consistency
from .errors import ArgumentError as ArgumentError
from .errors import ConfigError as ConfigError
from .errors import ConsistencyWarning as ConsistencyWarning
from .errors import DataError as DataError
from .errors import DataWarning as DataWarning
from .errors import GripkitError as GripkitError
from .errors import GripkitWarning as GripkitWarning
from .errors import IdentificationError as IdentificationError
from .errors import ModelError as ModelError
from .errors import ParameterError as ParameterError
from .errors import PathError as PathError
from .errors import SimulationError as SimulationError
from .errors import UnidentifiableError as UnidentifiableError
from .params import Parameter as Parameter
from .params import ParameterSet as ParameterSet
from .signals.trajectory import Trajectory as Trajectory

__version__ = "0.1.0"

__all__ = ["ArgumentError", "check_consistency", "ConfigError", "ConsistencyReport",
           "ConsistencyWarning",
           "DataError", "DataWarning", "Finding", "GripkitError", "GripkitWarning",
           "IdentificationError",
           "ModelError", "Parameter", "ParameterError", "ParameterSet", "PathError",
           "SimulationError",
           "Trajectory", "UnidentifiableError", "__version__"]
