"""``gripkit zoo list|show|check NAME``: the reference systems, their parameters and checks."""

from __future__ import annotations

import warnings

import typer

from .app import zoo_app
from .common import JsonOpt, emit_json, table_console


def _build(name: str):
    from .. import zoo
    from ..errors import ConsistencyWarning

    with warnings.catch_warnings():  # the check command reports them; do not print twice
        warnings.simplefilter("ignore", ConsistencyWarning)
        return zoo.build(name)


@zoo_app.command("list")
def zoo_list(json_out: bool = JsonOpt):
    """List the zoo models."""
    from .. import zoo

    rows = ([dict(name=e.name, system=e.system, description=e.description,
                  seed=e.seed) for e in zoo.entries()])
    if json_out:
        emit_json({"models": rows})
        return
    from rich.table import Table

    t = Table("name", "system", "description")
    for r in rows:
        t.add_row(r["name"], r["system"], r["description"])
    _print(t)


def _print(renderable):
    table_console().print(renderable)


@zoo_app.command("show")
def zoo_show(name: str, json_out: bool = JsonOpt):
    """Show a zoo model's parameters with units, bounds and provenance."""
    from .. import zoo

    entry = zoo.get(name)
    model = _build(name)
    params = model.parameters
    if json_out:
        emit_json({"name": entry.name, "system": entry.system, "description": entry.description,
                   "seed": entry.seed, "parameters": params.to_dict()["parameters"]})
        return
    from rich.table import Table

    t = (Table("parameter", "value", "unit", "meaning", "source",
               title=f"{entry.name}: {entry.description}"))
    for row in params.table():
        val = f"{row['value']:.6g}" + (f" ± {row['std']:.2g}" if row["std"] is not None else "")
        t.add_row(row["name"], val, row["unit"], row["doc"], row["source"])
    _print(t)


@zoo_app.command("check")
def zoo_check(name: str, json_out: bool = JsonOpt):
    """Run a zoo model's parameter consistency checks; exit code 3 if any fails."""
    from ..consistency import check

    rep = check(_build(name))
    if json_out:
        emit_json({"name": name, "consistent": rep.ok, "findings": rep.to_dicts()})
    else:
        typer.echo(str(rep))
    if not rep.ok:
        raise typer.Exit(3)
