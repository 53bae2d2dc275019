"""Batch runs: parameter sweeps and Monte Carlo studies on in-process, process-pool or Dask
executors, with results checkpointed per chunk in Parquet, and their statistics (confidence
intervals of probabilities and quantiles). A system's study built on them lives with the system
(the TSFM grasp robustness: :mod:`gripkit.systems.tsfm.robustness`)."""

from .executors import DaskExecutor as DaskExecutor
from .executors import InProcessExecutor as InProcessExecutor
from .executors import ProcessExecutor as ProcessExecutor
from .executors import make_executor as make_executor
from .identify_many import IDENTIFIERS as IDENTIFIERS
from .identify_many import identify_many as identify_many
from .montecarlo import Estimate as Estimate
from .montecarlo import binned_probability as binned_probability
from .montecarlo import probability as probability
from .montecarlo import quantile as quantile
from .spec import SweepSpec as SweepSpec
from .sweep import SweepResult as SweepResult
from .sweep import sweep as sweep

__all__ = ["binned_probability", "DaskExecutor", "Estimate", "IDENTIFIERS", "identify_many",
           "InProcessExecutor", "make_executor", "probability", "ProcessExecutor", "quantile",
           "sweep", "SweepResult", "SweepSpec"]
