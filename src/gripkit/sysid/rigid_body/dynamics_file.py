"""Identified rigid-body dynamics models as JSON files: ``result.save(path)`` on the result of
:func:`gripkit.sysid.identify_dynamics`, and :func:`gripkit.sysid.load_dynamics_model`.

A file holds (schema ``gripkit.dynamics-model``, version 1; the same conventions as the linear
models of :mod:`gripkit.sysid.model_file`)::

    {"schema": "gripkit.dynamics-model", "schema_version": 1, "gripkit_version": "0.1.0",
     "urdf": {"text": "<robot …>", "sha256": "…", "base_link": "base" | null, "tip_link": … | null},
     "gravity": [gx, gy, gz],            m/s², in the base link's frame
     "joints": ["theta1", …],            the actuated joints, in the columns' order
     "friction_model": "coulomb-viscous", "armature": false,
     "structure": {"standard_names": […], "independent": […], "dependent": […], "beta": [[…]]},
     "parameters": {"names": […], "values": […], "std": […], "covariance": [[…]]},
     "base_parameters": {name: {"value": v, "std": σ}}, "friction": {joint: {"coulomb": …,
     "coulomb_std": …}},
     "residual_std": {joint: σ}, "relative_error_percent": …, "condition_number": …, "n_samples": N,
     "constrained": false, "unconstrained_values": […],
     "consistency": {"consistent": …, "distance_sigma": …, "failing_links": […],
                     "standard_parameters": […], "values": […], "dof": n, "bound_sigma": …,
                     "level": 0.95, "p_value": …, "estimate_consistent": …, "solver": "…",
                     "converged": …, "iterations": …} | null,   (the fields after "values" are
                     optional on reading: files written before them read with the defaults)
     "warnings": […], "data": {"file": "log.csv", "sha256": "…"} | null,
     "content_sha256": "…"}

The URDF text makes the file self-contained: the chain is rebuilt from it with the stored links
and gravity; the base structure (K of φ_b = K φ,
:class:`~gripkit.sysid.rigid_body.dynamics.BaseStructure`)
is stored rather than found again, so that the loaded model predicts τ = X(q, q̇, q̈) θ with the
very columns and parameters it was identified with. ``base_parameters`` and ``friction`` repeat
``parameters`` for a reader of the file; the loader uses ``parameters``.
"""

from __future__ import annotations

import hashlib
import json
import tempfile
from pathlib import Path

import numpy as np

from ... import __version__
from ...atomic import write_text
from ...errors import DataError, ModelError
from ...multibody import to_urdf
from ..model_file import content_hash, plain, read_document

__all__ = ["SCHEMA", "SCHEMA_VERSION", "dynamics_document", "float_array", "read_dynamics_document",
           "save_dynamics_model"]

SCHEMA = "gripkit.dynamics-model"
SCHEMA_VERSION = 1


def _urdf_text(result) -> str:
    """The URDF the result's chain came from, or the chain written as URDF."""
    if result.urdf_text is not None:
        return result.urdf_text
    with tempfile.TemporaryDirectory() as tmp:
        return Path(to_urdf(result.chain, Path(tmp) / "chain.urdf")).read_text()


def dynamics_document(result) -> dict:
    """The JSON document of a :class:`~gripkit.sysid.rigid_body.dynamics.DynamicsResult`."""
    text = _urdf_text(result)
    st = result.structure
    cons = result.consistency
    doc = {"schema": SCHEMA, "schema_version": SCHEMA_VERSION, "gripkit_version": __version__,
           "urdf": {"text": text, "sha256": hashlib.sha256(text.encode()).hexdigest(),
                    "base_link": result.base_link, "tip_link": result.tip_link},
           "gravity": result.chain.gravity_vector, "joints": list(result.chain.coordinate_names),
           "friction_model": result.friction_model, "armature": result.armature_identified,
           "structure": {"standard_names": st.standard_names, "independent": st.independent,
                         "dependent": st.dependent, "beta": st.beta},
           "parameters": {"names": result.names, "values": result.theta, "std": result.std,
                          "covariance": result.covariance},
           "base_parameters": {n: {"value": v, "std": result.base_parameters_std[n]}
                               for n, v in result.base_parameters.items()},
           "friction": result.friction, "residual_std": result.residual_std,
           "relative_error_percent": result.relative_error_percent,
           "condition_number": result.condition_number,
           "n_samples": result.n_samples, "constrained": result.constrained,
           "unconstrained_values": result.unconstrained_theta,
           "consistency": None if cons is None else {
               "consistent": cons.consistent, "distance_sigma": cons.distance,
               "failing_links": cons.failing_links,
               "standard_parameters": cons.standard_parameters, "values": cons.theta,
               "dof": cons.dof, "bound_sigma": cons.bound, "level": cons.level,
               "p_value": cons.p_value, "estimate_consistent": cons.inside, "solver": cons.solver,
               "converged": cons.converged, "iterations": cons.iterations},
           "warnings": list(result.warnings),
           "data": None if result.data_file is None else {"file": result.data_file,
                                                          "sha256": result.data_hash}}
    doc = plain(doc)
    doc["content_sha256"] = content_hash(doc)
    return doc


def save_dynamics_model(result, path) -> None:
    """Write ``result`` (a :class:`~gripkit.sysid.rigid_body.dynamics.DynamicsResult`) to ``path``
    (.json)."""
    path = Path(path)
    if path.suffix.lower() != ".json":
        raise DataError(f"dynamics model file: expected a .json path, found {str(path)!r}")
    text = json.dumps(dynamics_document(result), indent=1, allow_nan=False)
    write_text(path, text + "\n", what="dynamics model file")


def float_array(x, name, where, shape=None) -> np.ndarray:
    try:
        a = np.asarray(x, dtype=np.float64)  # null (a non-finite number when saved) reads as NaN
    except (TypeError, ValueError):
        raise ModelError(f"dynamics model file {where}: field {name!r} is not an "
                         "array of numbers") from None
    if shape is not None and a.shape != shape:
        raise ModelError(f"dynamics model file {where}: field {name!r} has shape {a.shape}, "
                         f"expected {shape}")
    return a


def read_dynamics_document(path) -> dict:
    """The checked JSON document of a model written by ``result.save(path)``
    (:func:`gripkit.sysid.load_dynamics_model` builds the model from it): DataError for a missing
    file or a folder, ModelError for a file that is not JSON, of another ``schema`` or of a newer
    ``schema_version``, and a DataWarning when the content digest does not match or is missing
    (the file was edited after it was saved: gripkit writes the digest in every dynamics model
    file); :func:`gripkit.sysid.model_file.read_document` does the checks."""
    return read_document(path, SCHEMA, SCHEMA_VERSION, what="dynamics model file",
                         hint="give a file written by gripkit identify dynamics --out or "
                              "result.save(); "
                              "gripkit.sysid.load_model reads gripkit.linear-model files",
                         resave="gripkit.sysid.load_dynamics_model(path).save(path)")
