"""``gripkit export c --kind pid|rst|lqr CONTROLLER.json`` and ``gripkit export c --rls …``:
what the ``export c`` command does for controllers and the RLS update (kept apart from
:mod:`gripkit.cli.export_c`, which dispatches here)."""

from __future__ import annotations

from pathlib import Path

from ..errors import ArgumentError
from ..export.c_code import check_c_name
from ..export.c_controllers import KINDS, export_controller_c, kind_of
from .common import report_warnings


def export_command(path, out, name, *, kind, rls, na, nb, nk, lam, p0, windup) -> dict:
    """What ``gripkit export c --kind …`` / ``--rls`` does; returns the JSON result."""
    import warnings

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        if rls:
            from ..sysid.linear.rls import RLS
            from ..export.c_rls import export_rls_c

            if path is not None or kind is not None:
                raise ArgumentError("--rls: takes no MODEL and no --kind (the estimator is "
                                    "given by --na, --nb, --nk, --lam)")
            if na is None or nb is None:
                raise ArgumentError("--rls: give the ARX orders --na and --nb (and --nk, "
                                    "default 1)", hint="e.g. --rls --na 3 --nb 3 --nk 1")
            name = name or "rls"
            check_c_name(name)
            try:
                est = RLS(na, nb, nk, forgetting=lam, p0=p0, windup=windup)
            except Exception as e:
                from ..errors import DataError

                if isinstance(e, DataError):
                    raise ArgumentError(f"--rls: {e.message}") from None
                raise
            paths = export_rls_c(est, out, name)
            what = f"RLS [{na} {nb} {nk}] update (λ = {lam:g}, windup {windup})"
            extra = dict(na=na, nb=nb, nk=nk, forgetting=lam, p0=p0, windup=windup)
        else:
            from ..control.controller_file import load_controller

            if kind not in KINDS:
                raise ArgumentError(f"--kind: expected one of {', '.join(KINDS)}, found {kind!r}")
            if path is None:
                raise ArgumentError("--kind: give the controller file (CONTROLLER.json)")
            c = load_controller(path)
            found = kind_of(c)
            if found != kind:
                raise ArgumentError(f"--kind {kind}: the file {Path(path).name!r} holds a "
                                    f"{found} controller", hint=f"use --kind {found}")
            if name is None:
                name = Path(path).stem
                if not name.isidentifier() or not name.isascii():
                    raise ArgumentError(f"--name: the file's stem {name!r} is no C identifier",
                                        hint="give one: --name force_pid")
            paths = export_controller_c(c, out, name)
            what = f"{kind} controller"
            extra = dict(controller=str(path), kind=kind, dt=c.dt)
    return dict(what=what, files=[str(p) for p in paths], name=name, **extra,
                warnings=report_warnings(caught))
