"""The one protocol of an identified model, and the one door that reads any model file.

Every identified model (linear: ARX, ARMAX, OE, state space, transfer function; nonlinear: NARX,
Hammerstein–Wiener, nonlinear state space, hysteresis) is an object with these names, so that
``gripkit simulate``, ``compare``, ``report`` and ``export`` take any model file::

    m.structure                  # 'arx', 'n4sid', 'narx', 'hw', ...
    m.inputs, m.outputs          # column names, in the model's order
    m.dt                         # sample time [s] (None for a continuous-time model)
    m.parameters                 # ParameterSet: every free parameter with its unit and 1σ
    m.simulate(data)             # free run on data's input columns -> (N, ny), in the file's units
    m.compare(data)              # ModelFit: the fit (%) per output by m.fit_definition
    m.save(path)                 # atomic JSON; load_model(path) gives the same type back

A model family registers its JSON schema in :data:`MODEL_FILES` (schema → module of this package
and the name of its reader); `load_model` reads the schema and hands the file to that reader.
A new family goes into ``sysid/nonlinear/`` (or ``sysid/linear/``) and adds one line here.
"""

from __future__ import annotations

import importlib
import json
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol, runtime_checkable

import numpy as np

from ..errors import ModelError, PathError

__all__ = ["IdentifiedModel", "ModelFit", "MODEL_FILES", "file_schema", "load_model"]


@dataclass(frozen=True)
class ModelFit:
    """The validation fit of a model on one record: ``fit_percent`` per output (None where the
    free run diverged), the free run ``simulated`` (N, ny) and the ``definition`` of the fit."""

    outputs: tuple[str, ...]
    fit_percent: list[float | None]
    simulated: np.ndarray
    definition: str


@runtime_checkable
class IdentifiedModel(Protocol):
    """What every identified model offers (see the module docstring)."""

    structure: str
    fit_definition: str

    @property
    def inputs(self) -> tuple[str, ...]: ...

    @property
    def outputs(self) -> tuple[str, ...]: ...

    def simulate(self, data, *args, **kwargs) -> np.ndarray: ...

    def compare(self, data, *args, **kwargs) -> ModelFit: ...

    def save(self, path) -> object: ...


# schema -> (module of gripkit.sysid, reader function); one line per model family
MODEL_FILES: dict[str, tuple[str, str]] = {
    "gripkit.linear-model": ("linear.linear_model", "load_linear_model"),
    "gripkit.narx-model": ("nonlinear.narx", "load_narx"),
    "gripkit.hw-model": ("nonlinear.hammerstein_wiener", "load_hw"),
    "gripkit.hysteresis-model": ("nonlinear.hysteresis", "load_hysteresis"),
}


def file_schema(path) -> str | None:
    """The ``schema`` field of a JSON model file; None when it has none or cannot be read (the
    family's reader then names what is wrong)."""
    try:
        doc = json.loads(Path(path).read_text(encoding="utf-8"))
    except (OSError, ValueError, RecursionError):
        return None
    return doc.get("schema") if isinstance(doc, dict) else None


def load_model(path):
    """Read any gripkit model file with its family's reader (:data:`MODEL_FILES`); the same type
    that was saved comes back. Raises PathError for a missing file and ModelError for a schema no
    family knows."""
    p = Path(path)
    if not p.is_file():
        raise PathError(f"model file {str(p)!r} does not exist", hint="give the path written by "
                        "gripkit identify --out or model.save(path)")
    schema = file_schema(p)
    if schema is None:  # the linear reader names what is wrong with the file
        schema = "gripkit.linear-model"
    if schema not in MODEL_FILES:
        raise ModelError(f"model file {str(p)!r}: unknown schema {schema!r}; gripkit reads "
                         f"{', '.join(sorted(MODEL_FILES))}",
                         hint="regenerate the file with gripkit identify --out")
    module, reader = MODEL_FILES[schema]
    return getattr(importlib.import_module(f"{__package__}.{module}"), reader)(p)
