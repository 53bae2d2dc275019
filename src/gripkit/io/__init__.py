"""Data I/O: one :func:`load` for CSV, Parquet and HDF5, and :func:`save`."""

from .formats import FORMATS as FORMATS
from .formats import load as load
from .formats import save as save

__all__ = ["FORMATS", "load", "save"]
