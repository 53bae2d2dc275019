"""Model files: the JSON document of an identified model, written and read with its checks.

The models themselves (:class:`~gripkit.sysid.LinearModel`: ``model.save(path)`` and
:func:`~gripkit.sysid.load_model`) build and read the documents; this module knows only the file.

The linear-model document is described at :func:`gripkit.sysid.linear.linear_model.model_document`.

Every model file gripkit writes (linear, dynamics and the nonlinear families') ends with
``content_sha256``, the digest of its content (:func:`content_hash`): the SHA-256 of the canonical
JSON of every other entry of the document (schema and versions, names, units, sample time,
coefficients, σ, covariance, offsets, fit, provenance), written atomically with the rest. On load
a digest that does not match is one DataWarning (:func:`check_content_hash`): the file was edited
after gripkit wrote it, and is used as it now stands. A file without the entry warns as well
where gripkit has always written one (linear and dynamics model files); a nonlinear family's file
without it (written before gripkit wrote one, under the same version) loads silently.
:func:`load_model` refuses a file of another schema or a newer version.
"""

from __future__ import annotations

import hashlib
import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..atomic import write_text
from ..errors import DataError, DataWarning, ModelError, ParameterError, PathError, emit_warning
from ..units import si_factor

__all__ = ["file_sha256", "plain", "write_document", "read_document", "read_family_document",
           "FamilyFile", "file_provenance", "Domain", "check_family_fields", "SAMPLE_TIME",
           "SCHEMA", "SCHEMA_VERSION", "content_hash", "check_content_hash", "RESAVE"]

SCHEMA = "gripkit.linear-model"
SCHEMA_VERSION = 2


def file_sha256(path) -> str:
    """SHA-256 of a file's bytes (hex): :func:`gripkit.io.file_sha256`, the hash
    :func:`gripkit.io.load` records in a trajectory's ``meta['sha256']``."""
    from ..io.formats import file_sha256 as sha256

    return sha256(path)


def plain(x):
    """``x`` with arrays, numpy scalars and tuples as JSON types (non-finite floats as null,
    complex numbers as ``[re, im]``)."""
    if isinstance(x, dict):
        return {str(k): plain(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [plain(v) for v in x]
    if isinstance(x, np.ndarray):
        return plain(x.tolist())
    if isinstance(x, (np.floating, float)):
        v = float(x)
        return v if np.isfinite(v) else None
    if isinstance(x, (np.integer,)):
        return int(x)
    if isinstance(x, (np.bool_,)):
        return bool(x)
    if isinstance(x, (complex, np.complexfloating)):
        return [plain(x.real), plain(x.imag)]
    return x


def content_hash(doc: dict) -> str:
    """The content digest of a model file's document ``doc`` (as JSON reads it back): the SHA-256
    (hex) of the UTF-8 bytes of ``json.dumps(body, sort_keys=True, separators=(",", ":"),
    ensure_ascii=True)``, ``body`` being ``doc`` less its ``content_sha256``. Keys sorted at every
    level, no spaces, non-ASCII text escaped, each number as Python writes it (the shortest text
    that reads back the same double; NaN for a family that writes NaN), so the digest depends on
    neither the file's indentation and key order nor the platform. A number is hashed as JSON
    reads it back, an integer as an int and anything with a fraction or exponent as a float:
    a float spelled otherwise ("1.50", "15e-1", "1.5E0") gives the same digest, but ``1`` and
    ``1.0`` (or ``10`` and ``1e1``, ``0.0`` and ``-0.0``) do not, so a tool that rewrites 1.0
    as 1 (JavaScript's JSON.stringify does) makes the file read as edited. Ints and floats are
    not merged into one form because every file written so far was hashed without it: merged,
    the digest of each such file holding a whole-number float (``"dt": 1.0``) would change and
    the unedited file would warn."""
    body = {k: v for k, v in doc.items() if k != "content_sha256"}
    text = json.dumps(body, sort_keys=True, separators=(",", ":"), ensure_ascii=True)
    return hashlib.sha256(text.encode()).hexdigest()


#: how to write a model file again (the hint of :func:`check_content_hash`'s warning)
RESAVE = "gripkit.sysid.load_model(path).save(path)"


def check_content_hash(doc: dict, what: str, resave: str = RESAVE, *,
                       required: bool = False) -> None:
    """One DataWarning when the document ``doc`` of the model file ``what`` (how the message
    names it) holds a ``content_sha256`` that is not its :func:`content_hash`: the file was
    edited after gripkit wrote it (a hand edit stays possible: the file is used as it stands);
    ``resave`` says how to write it again. Without the entry: one DataWarning as well when
    ``required`` (a format gripkit has always written with its digest: linear and dynamics
    model files, so a file without it was edited or written by another program), silent
    otherwise (a nonlinear family's or a controller file written before gripkit wrote one, of
    the same schema version: nothing says it was edited)."""
    if "content_sha256" not in doc:
        if required:
            emit_warning(f"{what}: its content cannot be checked against what gripkit wrote "
                         "(content_sha256 is missing, and gripkit writes it in every such file: "
                         "edited after it was saved or written by another program), so its "
                         "numbers and units are used as they now stand; if the file is meant, "
                         f"write it again to drop this warning: {resave}", DataWarning)
        return
    if doc["content_sha256"] != content_hash(doc):
        emit_warning(f"{what}: its content differs from what gripkit wrote (content_sha256 does "
                     "not match: edited after it was saved), so its numbers and units are used "
                     f"as they now stand; if the edit is meant, write it again to drop this "
                     f"warning: {resave}", DataWarning)


def write_document(doc: dict, path) -> None:
    """Write ``doc`` (made JSON-ready, with its ``content_sha256``) to the ``.json`` ``path``."""
    path = Path(path)
    if path.suffix.lower() != ".json":
        raise DataError(f"model file: expected a .json path, found {str(path)!r}")
    doc = plain(doc)
    doc["content_sha256"] = content_hash(doc)
    write_text(path, json.dumps(doc, indent=1, allow_nan=False) + "\n", what="model file")


@dataclass(kw_only=True)
class FamilyFile:
    """The one ``save`` of the nonlinear families' models (NARX, Hammerstein–Wiener, NLSS,
    hysteresis), whose readers check the file with :func:`read_family_document`. A class names
    its file in ``_file_what`` (for the write's errors) and sets ``_file_allow_nan = False``
    where its :meth:`to_dict` writes non-finite numbers as null (a NaN left is then refused).

    The provenance of the estimation data, the fields (keyword-only) and meaning of a linear
    model's (:class:`~gripkit.sysid.LinearModel`): ``data_file`` (the file's name, of several
    records the names joined by ``', '``) and ``data_hash`` (the SHA-256 of its bytes; None for
    several records), None for data built in memory; set by :func:`gripkit.sysid.identify`,
    written by :meth:`save` as the linear model file writes them (``data``: ``{"file",
    "sha256"}`` or null) and read back by :func:`file_provenance` (None from a file written
    before they were)."""

    data_file: str | None = None
    data_hash: str | None = None

    _file_what = "model"
    _file_allow_nan = True

    def save(self, path) -> Path:
        """Write the model as JSON (the document of :meth:`to_dict`, its ``schema`` naming the
        family, the provenance ``data`` and the content digest ``content_sha256``:
        :func:`content_hash`), atomically. A ModelError, and no file, for a
        model whose fit is NaN or ±inf or one of whose σ is infinite (a failed fit)."""
        _check_usable(self, path)
        text = json.dumps({**self.to_dict(), **self.provenance_document()},
                          allow_nan=self._file_allow_nan)
        doc = json.loads(text)  # the digest of the document as the reader will see it
        doc["content_sha256"] = content_hash(doc)
        return write_text(path, json.dumps(doc, indent=1, allow_nan=self._file_allow_nan) + "\n",
                          what=self._file_what)

    def provenance_document(self) -> dict:
        """The provenance entry of the model file: ``{"data": {"file": data_file, "sha256":
        data_hash}}``, ``{"data": None}`` without a data file (the linear model file's form)."""
        return {"data": None if self.data_file is None else {"file": self.data_file,
                                                             "sha256": self.data_hash}}


def _check_usable(model, path) -> None:
    """Refuse to save ``model`` (to ``path``) when its ``fit_percent`` is not finite or a
    ``theta_std`` entry is infinite: the numbers of a fit that failed, not a model."""
    fit = getattr(model, "fit_percent", None)
    std = getattr(model, "theta_std", None)
    bad = None
    if isinstance(fit, (float, np.floating)) and not np.isfinite(fit):
        bad = f"its fit is {fit} %"
    elif std is not None and np.isinf(np.asarray(std, dtype=np.float64)).any():
        bad = "a parameter's σ is infinite"
    if bad is not None:
        raise ModelError(f"{Path(path).name}: not written: {bad}, so the fit failed (often data "
                         "at an extreme scale or with corrupt samples)",
                         hint="check the data (the warnings above), rescale or repair it and "
                              "identify again")


def file_provenance(doc: dict) -> dict:
    """``data_file`` and ``data_hash`` of a nonlinear family's model file document (written by
    :meth:`FamilyFile.save`, checked by :func:`read_family_document`), None where the file has
    none (written before the entry was, or of data built in memory)."""
    data = doc.get("data") or {}
    return dict(data_file=data.get("file"), data_hash=data.get("sha256"))


def _check_provenance(doc: dict, what: str) -> None:
    """A ModelError naming ``what`` when the document's ``data`` is neither null (or absent) nor
    ``{"file": name, "sha256": hash or null}``."""
    data = doc.get("data")
    if data is None or (isinstance(data, dict) and isinstance(data.get("file"), str)
                        and isinstance(data.get("sha256"), (str, type(None)))):
        return
    raise ModelError(f"{what}: the entry 'data' must be null or {{\"file\": name, \"sha256\": "
                     f"hash or null}}, found {json.dumps(data)[:80]}",
                     hint="write the file again with model.save")


#: the deepest nesting of lists and objects a model file may hold (gripkit writes at most 4 levels)
MAX_NESTING = 32


def _nesting(doc) -> int:
    """How deep ``doc`` nests lists and dicts, found without recursion (a hostile file nests
    deeper than Python's recursion limit allows to hash or walk it)."""
    deepest, stack = 0, [(doc, 0)]
    while stack:
        node, depth = stack.pop()
        if isinstance(node, (list, dict)):
            deepest = max(deepest, depth + 1)
            if deepest > MAX_NESTING:
                return deepest
            children = node.values() if isinstance(node, dict) else node
            stack.extend((v, depth + 1) for v in children)
    return deepest


def read_document(path, schema: str = SCHEMA, newest: int = SCHEMA_VERSION, *,
                  what: str = "model file",
                  hint: str = "give a file written by gripkit identify --out "
                              "or model.save()", resave: str = RESAVE) -> dict:
    """The JSON document of the model file ``path``, checked: ``schema`` and a ``schema_version``
    from 1 to ``newest`` (ModelError otherwise), and its content digest
    (:func:`check_content_hash`: a DataWarning, whose hint is ``resave``, when the file was
    edited after it was saved or has no digest: every version of both schemas read here, linear
    and dynamics model files, was written with one)."""
    path = Path(path)
    try:
        doc = json.loads(path.read_text())
    except FileNotFoundError:
        raise DataError(f"{what} {str(path)!r} does not exist") from None
    except IsADirectoryError:
        raise DataError(f"{what} {str(path)!r} is a folder, expected a JSON file") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise ModelError(f"{what} {str(path)!r} is not valid JSON ({exc})", hint=hint) from None
    except RecursionError:
        raise ModelError(f"{what} {str(path)!r} cannot be read: its JSON nests lists or objects "
                         f"deeper than Python's recursion limit ({sys.getrecursionlimit()}); a "
                         f"model file nests a few levels", hint=hint) from None
    except ValueError as exc:  # an integer beyond Python's limit on digits read from text
        raise ModelError(f"{what} {str(path)!r} cannot be read: {str(exc).split(';')[0]} (a number "
                         f"in the file has more digits than any model parameter)",
                         hint=hint) from None
    where = repr(str(path))
    if _nesting(doc) > MAX_NESTING:
        raise ModelError(f"{what} {where}: its JSON nests lists or objects more than "
                         f"{MAX_NESTING} deep; a model file nests a few levels", hint=hint)
    if not isinstance(doc, dict) or doc.get("schema") != schema:
        found = doc.get("schema") if isinstance(doc, dict) else type(doc).__name__
        raise ModelError(f"{what} {where}: expected schema {schema!r}, found {found!r}", hint=hint)
    ver = doc.get("schema_version")
    if not isinstance(ver, int) or ver < 1 or ver > newest:
        raise ModelError(f"{what} {where}: expected schema_version 1 … {newest}, found {ver!r}",
                         hint="upgrade gripkit to read files written by a newer version")
    check_content_hash(doc, f"{what} {where}", resave, required=True)
    return doc


def read_family_document(path, schema: str, version, *, family: str, writer: str,
                         version_key: str = "version") -> dict:
    """The JSON document of a nonlinear family's model file ``path`` (``family``: 'narx', 'hw',
    …; ``writer``: what writes such a file), checked: readable JSON, its ``schema`` and its
    ``version_key`` equal to ``version`` (an int, or a tuple of the versions read), its provenance
    ``data`` null, absent or a file's name and hash (:func:`file_provenance`), its content digest
    (:func:`check_content_hash`: a DataWarning for a file edited after it was saved). PathError
    for a missing or unreadable file, ModelError for anything else."""
    versions = version if isinstance(version, tuple) else (version,)
    p = Path(path)
    what = f"{family} model file {str(p)!r}"
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise PathError(f"{what} does not exist; give the path of a file written by "
                        f"{writer}") from None
    except OSError as exc:
        raise PathError(f"{what} cannot be read ({exc.strerror or exc}); give the path of a "
                        "readable file") from None
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise ModelError(f"{what} is not JSON ({exc}); expected a file of schema "
                         f"{schema!r}") from None
    except RecursionError:
        raise ModelError(f"{what} cannot be read: its JSON nests lists or objects deeper than "
                         "Python's recursion limit; a model file nests a few levels") from None
    except ValueError as exc:  # an integer beyond Python's limit on digits read from text
        raise ModelError(f"{what} cannot be read: {str(exc).split(';')[0]}") from None
    found = doc.get("schema") if isinstance(doc, dict) else None
    if found != schema:
        raise ModelError(f"{str(p)!r} has schema {found!r}, expected {schema!r}; load other "
                         "model files with gripkit.sysid.load_model")
    found = doc.get(version_key)
    if isinstance(found, bool) or found not in versions:
        raise ModelError(f"{str(p)!r} is a {schema} of {version_key} {found!r}; this gripkit "
                         f"reads {version_key} {' or '.join(map(str, versions))}",
                         hint=f"write it again with this gripkit ({writer})")
    if _nesting(doc) > MAX_NESTING:  # before writing or hashing any part of it
        raise ModelError(f"{what}: its JSON nests lists or objects more than {MAX_NESTING} deep; "
                         "a model file nests a few levels")
    _check_provenance(doc, what)
    check_content_hash(doc, what)
    return doc


@dataclass(frozen=True)
class Domain:
    """Where a number of a model file may lie: from ``lo`` (excluded with ``strict``) to
    ``hi``, a whole number with ``integer``, null allowed with ``optional``."""

    lo: float = -math.inf
    hi: float = math.inf
    strict: bool = False
    integer: bool = False
    optional: bool = False

    def holds(self, v) -> bool:
        if v is None:
            return self.optional
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            return False
        if self.integer and v != int(v):
            return False
        return (v > self.lo if self.strict else v >= self.lo) and v <= self.hi

    def describe(self) -> str:
        kind = "a whole number" if self.integer else "a finite number"
        if self.lo > -math.inf and self.hi < math.inf:
            kind += f" in {'(' if self.strict else '['}{self.lo:g}, {self.hi:g}]"
        elif self.lo > -math.inf:
            kind += f" {'>' if self.strict else '≥'} {self.lo:g}"
        return kind + (" or null" if self.optional else "")


#: a sample time (s) of a discrete model
SAMPLE_TIME = Domain(0.0, strict=True)


def _first_not_finite(x):
    """The first index (a tuple) of a non-finite entry of the nested list ``x`` (null counts as
    one); None when every entry is finite or ``x`` is not an array of numbers (the family's
    reader then names what is wrong)."""
    try:
        a = np.asarray(x, dtype=np.float64)
    except (TypeError, ValueError):
        return None
    bad = np.argwhere(~np.isfinite(a))
    return tuple(int(i) for i in bad[0]) if bad.size else None


def check_family_fields(doc: dict, what: str, writer: str, *, numbers: dict | None = None,
                        finite=(), units=()) -> None:
    """The fields of a nonlinear family's model file document (``what``: how the errors name
    the file; ``writer``: what writes one), checked on load as a linear model file's system is
    when it is built: each number of ``numbers`` ({key: :class:`Domain`}) in its domain, each
    array of ``finite`` without a null or non-finite entry, each unit (or list of units) of
    ``units`` one gripkit can read. A malformed-file ModelError naming the field otherwise; a
    field missing is left to the family's reader."""
    def bad(field_: str, expected: str, found) -> ModelError:
        shown = "null" if found is None else repr(found)[:40]
        return ModelError(f"{what}: malformed: {field_!r} must be {expected}, found {shown}",
                          hint=f"write it again with {writer}")

    for key, dom in (numbers or {}).items():
        if key in doc and not dom.holds(doc[key]):
            raise bad(key, dom.describe(), doc[key])
    for key in finite:
        idx = _first_not_finite(doc[key]) if key in doc else None
        if idx is not None:
            v = np.asarray(doc[key], dtype=np.float64)[idx]
            raise bad(f"{key}[{']['.join(map(str, idx))}]", "a finite number",
                      None if math.isnan(v) else float(v))
    for key in units:
        values = doc.get(key, [])
        for i, u in enumerate(values if isinstance(values, list) else [values]):
            name = key if not isinstance(values, list) else f"{key}[{i}]"
            try:
                if not isinstance(u, str):
                    raise ParameterError("not a string")
                si_factor(u)
            except ParameterError:
                raise bad(name, "a unit gripkit can read (an SI spelling such as 'm', 'N', "
                                "'V', '1')", u) from None
