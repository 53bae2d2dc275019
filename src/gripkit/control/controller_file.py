"""The controller file (``"format": "gripkit.controller"``): a PID, RST or state-feedback (LQR)
controller as JSON, for ``gripkit export c CONTROLLER.json --kind pid|rst|lqr`` and for reuse.

Schema (version 1)::

    {"format": "gripkit.controller", "version": 1, "kind": "pid" | "rst" | "lqr",
     "dt": <s>, "parameters": {...}, "design": {...}}

* ``pid``: ``kp``, ``ki``, ``kd``, ``tf``, ``b``, ``c``, ``tt`` (s; null: no back-calculation),
  ``u_min``, ``u_max`` (null: unlimited) — :class:`~gripkit.control.PID`'s arguments;
* ``rst``: ``R``, ``S``, ``T``, ``A_aw`` (coefficients in powers of q⁻¹, R and A_aw monic and of
  equal length), ``anti_windup`` (false: A_aw = R, the plain clamped law), ``u_min``, ``u_max``
  (null: unlimited);
* ``lqr``: ``K`` (m × n), ``Nr`` (m × p, or null for the regulator u = −K x), ``u_min``,
  ``u_max`` (m values each, null entries unlimited).

``design`` is provenance only (the SIMC reduction, the RST pole placement), never read back into
the law. Files are written atomically (:mod:`gripkit.atomic`); reading checks the format tag, the
version, the kind and every number, and a bad file is a ConfigError naming the file and field.

The file ends with ``content_sha256``, the content digest every model file carries
(:func:`gripkit.sysid.model_file.content_hash`: the SHA-256 of the canonical JSON of every other
entry). A file whose gains, limits or sample time were edited after gripkit wrote it loads with
one DataWarning naming the file (:func:`~gripkit.sysid.model_file.check_content_hash`; the
edited numbers are used, so a deliberate edit stays possible, and writing the file again with
:data:`RESAVE` drops the warning) before ``gripkit export c`` turns it into code for a target; a
file without the entry (written before gripkit wrote one) loads silently.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from ..atomic import write_text
from ..errors import ConfigError, GripkitError, PathError
from ..sysid.model_file import check_content_hash, content_hash
from .pid import PID
from .rst import RSTController
from .state_feedback import StateFeedback

__all__ = ["FORMAT", "VERSION", "KINDS", "RESAVE", "controller_to_dict", "controller_from_dict",
           "save_controller", "load_controller"]

FORMAT = "gripkit.controller"
VERSION = 1
KINDS = ("pid", "rst", "lqr")
#: how to write a controller file again (the hint of the edited-file warning)
RESAVE = "gripkit.control.save_controller(gripkit.control.load_controller(path), path)"


def _lim(v):
    return None if v is None or not math.isfinite(float(v)) else float(v)


def _plain(x):
    """``x`` as JSON-safe values (arrays as lists, complex as [re, im]; others dropped)."""
    if isinstance(x, dict):
        return {str(k): v for k, v in ((k, _plain(v)) for k, v in x.items()) if v is not _DROP}
    if isinstance(x, (list, tuple, np.ndarray)):
        out = [_plain(v) for v in (x.tolist() if isinstance(x, np.ndarray) else x)]
        return [v for v in out if v is not _DROP]
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, complex):
        return [x.real, x.imag]
    if isinstance(x, str) or x is None:
        return x
    return _DROP


_DROP = object()


def controller_to_dict(controller) -> dict:
    """The controller file's content for a PID, RSTController or StateFeedback."""

    if isinstance(controller, PID):
        tt = controller.tt
        params = dict(kp=controller.kp, ki=controller.ki, kd=controller.kd, tf=controller.tf,
                      b=float(controller.params[4]), c=float(controller.params[5]),
                      tt=None if math.isinf(tt) else tt, u_min=_lim(controller.limits[0]),
                      u_max=_lim(controller.limits[1]))
        kind, dt, design = "pid", controller.dt, controller.design
    elif isinstance(controller, RSTController):
        if controller.dt is None:
            raise ConfigError("controller file: this RST controller has no sample time (no "
                              "plant, no dt)", hint="build it with design_rst(plant) or give dt=")
        params = dict(R=controller.R.tolist(), S=controller.S.tolist(), T=controller.T.tolist(),
                      A_aw=controller.A_aw.tolist(), anti_windup=controller.anti_windup,
                      u_min=_lim(controller.u_min),
                      u_max=_lim(controller.u_max))
        kind, dt = "rst", controller.dt
        design = {k: v for k, v in controller.design.items() if k in ("wn", "zeta", "observer",
                                                                       "method")}
    elif isinstance(controller, StateFeedback):
        params = dict(K=controller.K.tolist(),
                      Nr=controller.Nr.tolist() if controller.has_reference else None,
                      u_min=[_lim(v) for v in controller.u_min],
                      u_max=[_lim(v) for v in controller.u_max])
        kind, dt, design = "lqr", controller.dt, {}
    else:
        raise ConfigError(f"controller file: expected a PID, RSTController or StateFeedback, "
                          f"found {type(controller).__name__}")
    return dict(format=FORMAT, version=VERSION, kind=kind, dt=float(dt), parameters=params,
                design=_plain(design))


def save_controller(controller, path) -> Path:
    """Write ``controller`` to ``path`` (JSON, atomically, ending with its ``content_sha256``:
    :func:`~gripkit.sysid.model_file.content_hash` of the document as the reader sees it);
    returns the path."""
    doc = json.loads(json.dumps(controller_to_dict(controller), allow_nan=False))
    doc["content_sha256"] = content_hash(doc)
    text = json.dumps(doc, indent=2, allow_nan=False) + "\n"
    return write_text(Path(path), text, what="controller file")


def _num(d: dict, key: str, where: str, *, allow_none: bool = False):
    if key not in d:
        raise ConfigError(f"{where}: the field {key!r} is missing")
    v = d[key]
    if v is None and allow_none:
        return None
    if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
        raise ConfigError(f"{where}: {key!r} must be a finite number"
                          f"{' or null' if allow_none else ''}, found {v!r:.60}")
    return float(v)


def _arr(d: dict, key: str, where: str, ndim: int, *, allow_none: bool = False):
    if key not in d:
        raise ConfigError(f"{where}: the field {key!r} is missing")
    v = d[key]
    if v is None and allow_none:
        return None
    try:
        a = np.array(v, dtype=np.float64)
    except (TypeError, ValueError):
        raise ConfigError(f"{where}: {key!r} must be a {ndim}-D array of numbers, found "
                          f"{v!r:.60}") from None
    if a.ndim != ndim or a.size == 0 or not np.isfinite(a).all():
        raise ConfigError(f"{where}: {key!r} must be a non-empty {ndim}-D array of finite "
                          f"numbers, found shape {a.shape}")
    return a


def controller_from_dict(d, where: str = "controller file"):
    """A PID, RSTController or StateFeedback from the controller file's content."""

    if not isinstance(d, dict) or d.get("format") != FORMAT:
        raise ConfigError(f"{where}: not a controller file (expected \"format\": \"{FORMAT}\")",
                          hint="write one with gripkit.control.save_controller(controller, path)")
    if d.get("version") != VERSION:
        raise ConfigError(f"{where}: version {d.get('version')!r} is not supported (expected "
                          f"{VERSION})", hint="upgrade gripkit")
    kind = d.get("kind")
    if kind not in KINDS:
        raise ConfigError(f"{where}: kind must be one of {', '.join(KINDS)}, found {kind!r:.40}")
    p = d.get("parameters")
    if not isinstance(p, dict):
        raise ConfigError(f"{where}: the field 'parameters' must be an object")
    dt = _num(d, "dt", where)
    if not dt > 0:
        raise ConfigError(f"{where}: 'dt' must be a positive sample time in s, found {dt!r}")
    design = d.get("design") if isinstance(d.get("design"), dict) else {}
    w = f"{where} ({kind} parameters)"
    try:
        if kind == "pid":
            gains = [_num(p, k, w) for k in ("kp", "ki", "kd", "tf", "b", "c")]
            lo, hi = _num(p, "u_min", w, allow_none=True), _num(p, "u_max", w, allow_none=True)
            tt = _num(p, "tt", w, allow_none=True)
            return PID(*gains[:3], dt=dt, tf=gains[3], b=gains[4], c=gains[5],
                       tt=math.inf if tt is None else tt,
                       u_min=-math.inf if lo is None else lo, u_max=math.inf if hi is None else hi,
                       design=design)
        if kind == "rst":
            lo, hi = _num(p, "u_min", w, allow_none=True), _num(p, "u_max", w, allow_none=True)
            aw = p.get("anti_windup", True)
            if not isinstance(aw, bool):
                raise ConfigError(f"{w}: 'anti_windup' must be true or false, found {aw!r:.20}")
            return RSTController(_arr(p, "R", w, 1), _arr(p, "S", w, 1), _arr(p, "T", w, 1),
                                 A_aw=_arr(p, "A_aw", w, 1) if aw else None, anti_windup=aw,
                                 u_min=-math.inf if lo is None else lo,
                                 u_max=math.inf if hi is None else hi, design=design, dt=dt)
        K = _arr(p, "K", w, 2)
        lims = []
        for key, inf in (("u_min", -math.inf), ("u_max", math.inf)):
            v = p.get(key)
            if not isinstance(v, list) or len(v) != K.shape[0]:
                raise ConfigError(f"{w}: {key!r} must be a list of {K.shape[0]} numbers or nulls")
            lims.append([inf if x is None else _num({key: x}, key, w) for x in v])
        return StateFeedback(K, Nr=_arr(p, "Nr", w, 2, allow_none=True), dt=dt, u_min=lims[0],
                             u_max=lims[1])
    except ConfigError:
        raise
    except Exception as e:  # the classes' own checks (ModelError from RST, ...)
        if isinstance(e, GripkitError):
            raise ConfigError(f"{where}: {e.message}") from None
        raise


def load_controller(path):
    """Read a controller file (:func:`save_controller`); one DataWarning naming the file when
    its ``content_sha256`` does not match its content (edited after it was saved: the file is
    used as it now stands), none for a file without the entry."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as e:
        raise PathError(f"controller file {str(path)!r}: cannot be read ({e.strerror})") from None
    except UnicodeDecodeError:
        raise ConfigError(f"controller file {path.name!r}: not UTF-8 text (a controller file is "
                          "JSON)") from None
    try:
        d = json.loads(text)
    except json.JSONDecodeError as e:
        raise ConfigError(f"controller file {path.name!r}: not valid JSON (line {e.lineno}: "
                          f"{e.msg})") from None
    except (RecursionError, ValueError):  # nesting past the recursion limit, huge integers
        raise ConfigError(f"controller file {path.name!r}: cannot be read (its JSON nests too "
                          "deep or holds a number of too many digits; a controller file nests "
                          "a few levels)") from None
    if isinstance(d, dict) and d.get("format") == FORMAT:
        try:
            check_content_hash(d, f"controller file {str(path)!r}", RESAVE)
        except RecursionError:
            raise ConfigError(f"controller file {path.name!r}: its JSON nests lists or objects "
                              "too deep to be read; a controller file nests a few levels") from None
    return controller_from_dict(d, f"controller file {path.name!r}")
