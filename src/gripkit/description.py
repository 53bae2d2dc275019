"""Models and experiments described in a TOML file, behind ``gripkit simulate MODEL.toml``.

A description names a model type (or a zoo model), overrides parameters (numbers are SI, strings
carry their unit), sets the sampling, and gives each model input as a signal::

    [model]
    type = "tsfm-finger-contact"     # a zoo model (`gripkit zoo list`); or `zoo = "tsfm-left"`
    zoo = "tsfm-left"                # optional for the TSFM finger types: start from this finger

    [parameters]
    x_w = "62.4 um"                  # the part face (Fig. 13)
    k_e = "72.5 N/m"

    [simulation]
    fs = 20000                       # Hz (or dt = 5e-5)
    duration = 10.0                  # s

    [inputs.U]                       # one table per model input
    kind = "sine"                    # constant | step | ramp | sine | steps | file
    amplitude = 25.0
    offset = 25.0
    frequency = 0.1
    phase_deg = -90.0

    [output]
    file = "fig13.parquet"           # optional: where `gripkit simulate` writes the result

Input kinds and their keys (times in s, values in the input's unit):
``constant``: value; ``step``: initial, final, time; ``ramp``: start, end, t0, t1 (linear between
t0 and t1, held outside); ``sine``: amplitude, frequency, offset = 0, phase_deg = 0;
``steps``: levels, durations (held in turn, the last to the end); ``file``: path (relative to the
TOML file), column, optionally time (column name; else the file's own time base) — interpolated
onto the simulation's time base.

Model names resolve in the zoo (:mod:`gripkit.zoo`), the one registry of buildable models: other
developers add one with :func:`gripkit.zoo.register`. ``[model]`` options: ``loads`` (bool) for a
``piezo-actuator``; ``zoo = "tsfm-left" | "tsfm-right"`` (the side) for ``tsfm-finger`` and
``tsfm-finger-contact``, which needs ``x_w`` and ``k_e`` in ``[parameters]``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from . import zoo
from .arguments import check_path
from .errors import ConfigError, GripkitError
from .io import load
from .io.toml_file import read_toml
from .signals.trajectory import Trajectory

__all__ = ["Description", "load_description", "simulate_description", "input_signal"]


_SIDES = {"tsfm-left": "left", "tsfm-right": "right"}


def _finger_options(params: Mapping, options: Mapping) -> dict:
    side = _SIDES.get(options.get("zoo", "tsfm-left"))
    if side is None:
        raise ConfigError(f"[model] zoo = {options.get('zoo')!r}: a TSFM finger type starts from "
                          "'tsfm-left' or 'tsfm-right'")
    return {"side": side}


def _contact_options(params: Mapping, options: Mapping) -> dict:
    for key in ("x_w", "k_e"):
        if key not in params:
            raise ConfigError(f"[parameters]: a tsfm-finger-contact needs {key!r} "
                              "(x_w: part face, k_e: stiffness)")
    return _finger_options(params, options)


#: [model] options of the types that take some → keywords of their zoo factory
_OPTIONS: dict[str, Callable] = {
    "piezo-actuator": lambda params, options: {"loads": bool(options.get("loads", True))},
    "tsfm-finger": _finger_options,
    "tsfm-finger-contact": _contact_options,
}


def _build(mtype: str, params: Mapping, options: Mapping):
    """The zoo model ``mtype`` built with its [model] options, unchecked when its factory allows
    (the [parameters] are applied afterwards)."""
    entry = zoo.get(mtype)
    kwargs = _OPTIONS[mtype](params, options) if mtype in _OPTIONS else {}
    names = entry.keywords()
    if names is None or "check" in names:
        kwargs["check"] = False
    return entry.build(**kwargs)


@dataclass(frozen=True)
class Description:
    """A loaded description: the model (parameters applied), its inputs as a Trajectory, the
    default output file (or None) and the raw TOML."""

    model: object
    inputs: Trajectory
    output: Path | None
    raw: dict


def _num(spec: Mapping, key: str, where: str, default=None) -> float:
    if key not in spec:
        if default is None:
            raise ConfigError(f"{where}: missing {key!r}")
        return float(default)
    return _number(spec[key], f"{where}: {key!r}")


def _number(v, what: str) -> float:
    if isinstance(v, bool) or not isinstance(v, (int, float)):
        raise ConfigError(f"{what} must be a number, found {v!r:.60}")
    if not math.isfinite(v):
        raise ConfigError(f"{what} must be finite, found {v!r}")
    return float(v)


def _numbers(spec: Mapping, key: str, where: str) -> list[float]:
    v = spec.get(key)
    if not isinstance(v, list) or not v:
        raise ConfigError(f"{where}: {key!r} must be a non-empty list of numbers, found {v!r:.60}")
    return [_number(x, f"{where}: {key}[{i}]") for i, x in enumerate(v)]


def _table(raw: Mapping, key: str, where: str) -> dict:
    v = raw.get(key) or {}
    if not isinstance(v, Mapping):
        raise ConfigError(f"{where}: {key!r} must be a table ([{key}]), found {v!r:.60}")
    return dict(v)


_KINDS = {"constant": {"value"}, "step": {"initial", "final", "time"},
          "ramp": {"start", "end", "t0", "t1"},
          "sine": {"amplitude", "frequency", "offset", "phase_deg"},
          "steps": {"levels", "durations"},
          "file": {"path", "column", "time"}}


def input_signal(spec: Mapping, t: np.ndarray, where: str, base: Path | None = None) -> np.ndarray:
    """The samples of one input described by ``spec`` at the times ``t`` (see the module
    docstring)."""
    kind = spec.get("kind")
    if kind not in _KINDS:
        raise ConfigError(f"{where}: kind = {kind!r}; expected one of {', '.join(_KINDS)}")
    unknown = set(spec) - _KINDS[kind] - {"kind"}
    if unknown:
        raise ConfigError(f"{where}: unknown keys {sorted(unknown)} for kind {kind!r}",
                          hint=f"{kind} takes {', '.join(sorted(_KINDS[kind]))}")
    if kind == "constant":
        return np.full(t.size, _num(spec, "value", where))
    if kind == "step":
        return (np.where(t < _num(spec, "time", where), _num(spec, "initial", where, 0.0),
                         _num(spec, "final", where)))
    if kind == "ramp":
        t0, t1 = _num(spec, "t0", where, 0.0), _num(spec, "t1", where)
        if t1 <= t0:
            raise ConfigError(f"{where}: t1 must be after t0, found t0 = {t0}, t1 = {t1}")
        a, b = _num(spec, "start", where, 0.0), _num(spec, "end", where)
        return a + (b - a) * np.clip((t - t0) / (t1 - t0), 0.0, 1.0)
    if kind == "sine":
        f = _num(spec, "frequency", where)
        return (_num(spec, "offset", where, 0.0) + _num(spec, "amplitude", where)
                * np.sin(2 * np.pi * f * t + math.radians(_num(spec, "phase_deg", where, 0.0))))
    if kind == "steps":
        lv, du = _numbers(spec, "levels", where), _numbers(spec, "durations", where)
        if len(du) != len(lv):
            raise ConfigError(f"{where}: steps needs lists 'levels' and 'durations' of "
                              "the same length, "
                              f"found {len(lv)} and {len(du)}")
        if min(du) <= 0:
            raise ConfigError(f"{where}: durations must be positive (s), found {min(du):g}")
        edges = np.cumsum([0.0] + du)
        out = np.full(t.size, lv[-1])
        for v, a, b in zip(lv, edges[:-1], edges[1:]):
            out[(t >= a) & (t < b)] = v
        return out

    if "path" not in spec or "column" not in spec:
        raise ConfigError(f"{where}: kind 'file' needs 'path' and 'column'")
    for key in ("path", "column", "time"):
        if key in spec and not isinstance(spec[key], str):
            raise ConfigError(f"{where}: {key!r} must be a string, found {spec[key]!r:.60}")
    path = Path(spec["path"])
    if base is not None and not path.is_absolute():
        path = base / path
    tr = load(path, columns=[spec["column"]], time=spec.get("time"))
    return np.interp(t, tr.t - tr.t[0], tr[spec["column"]])


def load_description(path, overrides: Mapping | None = None) -> Description:
    """Read a TOML description (see the module docstring) and build its model and inputs."""
    check_path(path, "model description", "load_description()")
    path = Path(path)
    raw = read_toml(path, "model description")
    unknown = set(raw) - {"model", "parameters", "simulation", "inputs", "output"}
    if unknown:
        raise ConfigError(f"{path.name}: unknown sections {sorted(unknown)}",
                          hint="sections: model, parameters, simulation, inputs, output")
    mspec = _table(raw, "model", path.name)
    params = _table(raw, "parameters", path.name)
    params.update(overrides or {})
    for key in ("type", "zoo"):
        if key in mspec and not isinstance(mspec[key], str):
            raise ConfigError(f"{path.name}: [model] {key} must be a string, found "
                              f"{mspec[key]!r:.60}")
    zoo_names = [e.name for e in zoo.entries()]
    if "type" not in mspec and "zoo" not in mspec:
        raise ConfigError(f"{path.name}: [model] needs 'type' or 'zoo' "
                          f"(a zoo model: {', '.join(zoo_names)})")
    mtype = mspec.get("type")
    try:
        if mtype is None:
            model = zoo.build(mspec["zoo"])
        elif mtype in zoo_names:
            model = _build(mtype, params, mspec)
        else:
            raise ConfigError(f"{path.name}: [model] type = {mtype!r} is unknown",
                              hint="types (the zoo's models, `gripkit zoo list`): "
                                   f"{', '.join(zoo_names)}")
        if not hasattr(model, "simulate"):
            raise ConfigError(f"{path.name}: zoo model {mtype or mspec.get('zoo')!r} cannot be "
                              "simulated", hint="`gripkit zoo list` shows the models; pick one "
                                                "with inputs and outputs")
        names = set(model.parameters.names)
        bad = sorted(set(params) - names)
        if bad:
            raise ConfigError(f"{path.name}: [parameters] {bad} are not parameters of {model.name}",
                              hint=f"parameters: {', '.join(model.parameters.names)}")
        if params:
            model = model.with_parameters(**params)
    except ConfigError:
        raise
    except GripkitError as exc:
        raise ConfigError(f"{path.name}: {exc}") from None
    sim = _table(raw, "simulation", path.name)
    bad = set(sim) - {"fs", "dt", "duration"}
    if bad:
        raise ConfigError(f"{path.name}: [simulation] unknown "
                          f"keys {sorted(bad)}", hint="keys: fs or dt, duration")
    if ("fs" in sim) == ("dt" in sim):
        raise ConfigError(f"{path.name}: [simulation] needs exactly one of fs (Hz) or dt (s)")
    step = _num(sim, "fs" if "fs" in sim else "dt", "[simulation]")  # the file's fs (Hz) or dt (s)
    duration = _num(sim, "duration", "[simulation]")
    if step <= 0 or duration <= 0:
        raise ConfigError(f"{path.name}: [simulation] {'fs' if 'fs' in sim else 'dt'} and duration "
                          "must be positive")
    dt = 1.0 / step if "fs" in sim else step
    n = duration / dt
    if not 1 <= round(n) <= 50_000_000:
        raise ConfigError(f"{path.name}: [simulation] duration / dt = {n:.4g} samples; expected "
                          "1 to 50 million")
    n = int(round(n))
    t = np.arange(n) * dt
    ispec = _table(raw, "inputs", path.name)
    names = [s.name for s in model.inputs]
    missing = [nm for nm in names if nm not in ispec]
    if missing:
        raise ConfigError(f"{path.name}: [inputs] "
                          f"misses {missing}", hint=f"{model.name} has inputs {names}")
    extra = sorted(set(ispec) - set(names))
    if extra:
        raise ConfigError(f"{path.name}: [inputs] {extra} are not inputs "
                          f"of {model.name}", hint=f"inputs: {names}")
    for nm in names:
        if not isinstance(ispec[nm], Mapping):
            raise ConfigError(f"{path.name}: inputs.{nm} must be a table ([inputs.{nm}]), found "
                              f"{ispec[nm]!r:.60}")
    ch = {nm: input_signal(ispec[nm], t, f"{path.name} [inputs.{nm}]", path.parent) for nm in names}
    units = {s.name: s.unit for s in model.inputs}
    inputs = Trajectory(t, ch, units, {"dt": dt, "source": path.name})
    out = _table(raw, "output", path.name).get("file")
    if out is not None and not isinstance(out, str):
        raise ConfigError(f"{path.name}: [output] file must be a string (a path), "
                          f"found {out!r:.60}")
    return Description(model, inputs, (path.parent / out) if out else None, raw)


def simulate_description(path, overrides: Mapping | None = None) -> Trajectory:
    """Load a description and simulate it: a Trajectory of its inputs and outputs."""
    d = load_description(path, overrides)
    return d.model.simulate(d.inputs)
