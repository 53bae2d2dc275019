"""Data I/O: one :func:`load` for CSV, Parquet and HDF5, and :func:`save`."""

from .formats import FORMATS as FORMATS
from .formats import file_sha256 as file_sha256
from .formats import load as load
from .formats import save as save

__all__ = ["FORMATS", "file_sha256", "load", "save"]
