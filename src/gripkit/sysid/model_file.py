"""Identified linear models as JSON files: ``model.save(path)`` and :func:`load_model`.

A file holds (schema ``gripkit.linear-model``, version 1)::

    {"schema": "gripkit.linear-model", "schema_version": 1, "gripkit_version": "0.1.0",
     "structure": "pem-innovation", "kind": "ss" | "tf", "dt": 0.01 | null,
     "inputs":  [{"name": "current", "unit": "A", "offset": 0.85}, ...],
     "outputs": [{"name": "force", "unit": "N", "offset": 0.0}, ...],
     "system": {…},       the lti system's own description (LinearSystem.to_dict: arrays,
                          names, units, dt, covariance with its tangents)
     "innovation": {"K": … | null, "x0": … | null, "noise_covariance": … | null},
     "fit_percent": […], "singular_values": […] | null, "n_samples": N, "info": {…},
     "data": {"file": "run1.csv", "sha256": "…"} | null,
     "content_sha256": "…"}

``content_sha256`` is the SHA-256 of the canonical JSON (sorted keys, no spaces) of everything
else; :func:`load_model` warns when it does not match (the file was edited by hand) and refuses a
file of another schema or a newer version.
"""

from __future__ import annotations

import hashlib
import json
import warnings
from pathlib import Path

import numpy as np

from ..errors import AccuracyWarning, DataError, ModelError
from ..lti import LinearSystem, StateSpace

__all__ = ["save_model", "load_model", "file_sha256", "content_hash", "json_plain", "SCHEMA", "SCHEMA_VERSION"]

SCHEMA = "gripkit.linear-model"
SCHEMA_VERSION = 1


def file_sha256(path) -> str:
    """SHA-256 of a file's bytes (hex)."""
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def json_plain(x):
    """``x`` with numpy arrays and scalars made plain JSON values (non-finite floats → None)."""
    if isinstance(x, dict):
        return {str(k): json_plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return json_plain(x.tolist())
    if isinstance(x, (np.floating, float)):
        v = float(x)
        return v if np.isfinite(v) else None
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, (np.bool_,)):
        return bool(x)
    return x


def content_hash(doc: dict) -> str:
    """SHA-256 of the canonical JSON (sorted keys, no spaces) of ``doc`` less its ``content_sha256``."""
    body = {k: v for k, v in doc.items() if k != "content_sha256"}
    return hashlib.sha256(json.dumps(body, sort_keys=True, separators=(",", ":")).encode()).hexdigest()


def model_document(model) -> dict:
    """The JSON document of a :class:`~gripkit.sysid.linear_model.LinearModel`."""
    from .. import __version__

    s = model.system
    doc = {"schema": SCHEMA, "schema_version": SCHEMA_VERSION, "gripkit_version": __version__,
           "structure": model.structure, "kind": "ss" if isinstance(s, StateSpace) else "tf", "dt": s.dt,
           "inputs": [{"name": n, "unit": u, "offset": o} for n, u, o in zip(s.inputs, s.input_units, model.u_offset)],
           "outputs": [{"name": n, "unit": u, "offset": o}
                       for n, u, o in zip(s.outputs, s.output_units, model.y_offset)]}
    doc["system"] = s.to_dict()
    doc["innovation"] = {"K": model.K, "x0": model.x0, "noise_covariance": model.noise_covariance}
    doc.update(fit_percent=model.fit_percent, singular_values=model.singular_values, n_samples=model.n_samples,
               info=model.info,
               data=None if model.data_file is None else {"file": model.data_file, "sha256": model.data_hash})
    doc = json_plain(doc)
    doc["content_sha256"] = content_hash(doc)
    return doc


def save_model(model, path) -> None:
    """Write ``model`` (a :class:`~gripkit.sysid.linear_model.LinearModel`, or a
    :class:`~gripkit.sysid.PolynomialModel`, converted) to ``path`` as JSON."""
    from .linear_model import LinearModel, from_polynomial

    if not isinstance(model, LinearModel):
        model = from_polynomial(model)
    path = Path(path)
    if path.suffix.lower() != ".json":
        raise DataError(f"model file: expected a .json path, found {str(path)!r}")
    text = json.dumps(model_document(model), indent=1, allow_nan=False)
    try:
        path.write_text(text + "\n")
    except OSError as exc:
        raise DataError(f"model file {str(path)!r} cannot be written: {exc.strerror}") from None


def _arr(x, name, path):
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        raise ModelError(f"model file {path}: field {name!r} is not an array of numbers") from None
    return a


def load_model(path):
    """Read a model written by ``model.save(path)``.

    Raises ModelError for a file that is not a gripkit model (wrong ``schema``), of a newer
    ``schema_version``, or with missing fields; warns (AccuracyWarning) when the content hash does
    not match (the file was edited after it was saved).

    Examples
    --------
    >>> import tempfile, os
    >>> from gripkit.lti import StateSpace
    >>> from gripkit.sysid.linear_model import LinearModel
    >>> from gripkit.sysid import load_model
    >>> m = LinearModel(StateSpace([[0.5]], [[1.0]], [[1.0]], dt=0.1, inputs="V", outputs="x"), "n4sid")
    >>> p = os.path.join(tempfile.mkdtemp(), "m.json"); m.save(p)
    >>> load_model(p).system.A.tolist(), load_model(p).inputs
    ([[0.5]], ('V',))
    """
    from .linear_model import LinearModel

    path = Path(path)
    try:
        doc = json.loads(path.read_text())
    except FileNotFoundError:
        raise DataError(f"model file {str(path)!r} does not exist") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ModelError(f"model file {str(path)!r} is not valid JSON ({exc})") from None
    where = repr(str(path))
    if not isinstance(doc, dict) or doc.get("schema") != SCHEMA:
        found = doc.get("schema") if isinstance(doc, dict) else type(doc).__name__
        raise ModelError(f"model file {where}: expected schema {SCHEMA!r}, found {found!r}",
                         hint="give a file written by gripkit identify --out or model.save()")
    ver = doc.get("schema_version")
    if not isinstance(ver, int) or ver < 1 or ver > SCHEMA_VERSION:
        raise ModelError(f"model file {where}: expected schema_version 1 … {SCHEMA_VERSION}, found {ver!r}",
                         hint="upgrade gripkit to read files written by a newer version")
    if doc.get("content_sha256") != content_hash(doc):
        warnings.warn(f"model file {where}: content hash mismatch (the file was edited after it was saved); "
                      f"using it as it is", AccuracyWarning, stacklevel=2)
    try:
        ins, outs = doc["inputs"], doc["outputs"]
        system = LinearSystem.from_dict(doc["system"])
        if list(system.inputs) != [d["name"] for d in ins] or list(system.outputs) != [d["name"] for d in outs]:
            raise ModelError(f"model file {where}: the inputs/outputs lists disagree with the system's names")
        inn = doc.get("innovation") or {}
        K, x0, lam = (None if inn.get(k) is None else _arr(inn[k], k, where) for k in ("K", "x0", "noise_covariance"))
        data = doc.get("data") or {}
        sv = doc.get("singular_values")
        return LinearModel(system, doc["structure"], K=K, x0=x0, noise_covariance=lam,
                           u_offset=[d["offset"] for d in ins], y_offset=[d["offset"] for d in outs],
                           fit_percent=doc.get("fit_percent"), singular_values=None if sv is None else np.asarray(sv),
                           n_samples=doc.get("n_samples"), data_file=data.get("file"), data_hash=data.get("sha256"),
                           info=doc.get("info") or {})
    except (KeyError, TypeError) as exc:
        raise ModelError(f"model file {where}: a required field is missing or malformed ({exc})",
                         hint="regenerate the file with gripkit identify --out") from None
