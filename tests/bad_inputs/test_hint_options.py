"""Messages name only options that exist (issue 22, "Unclear messages"): hints said
``--resample HZ`` and ``repeat --column``, options no gripkit command has. Every ``--option``
written in a string of ``src/gripkit`` (error messages, hints, warnings, help texts, docstrings)
must be an option of some ``gripkit`` command (or click's own ``--help``)."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import numpy as np
import pytest
import typer
from corpus import assert_user_error

from gripkit.cli import _build
from gripkit.errors import DataError

SRC = Path(__file__).resolve().parents[2] / "src" / "gripkit"
#: ``--name`` not preceded by a word character or a dash (so ``a--b`` and ``---`` are not options)
OPTION = re.compile(r"(?<![\w-])--([a-z][a-z0-9]*(?:-[a-z0-9]+)*)")
#: click adds --help to every command itself
BUILTIN = {"--help"}


def cli_options() -> dict[str, list[str]]:
    """Every long option of every command and group of the CLI → the commands that take it."""
    app = _build()
    found: dict[str, list[str]] = {}

    def walk(cmd, path):
        for p in cmd.params:
            for o in [*p.opts, *p.secondary_opts]:
                if o.startswith("--"):
                    found.setdefault(o, []).append(path)
        for name, sub in getattr(cmd, "commands", {}).items():
            walk(sub, f"{path} {name}")

    walk(typer.main.get_command(app), "gripkit")
    return found


def mentioned_options(source: str, filename: str = "<src>") -> list[tuple[str, int, str]]:
    """(option, line, text around it) for every ``--option`` in a string constant of ``source``
    (f-strings included: their literal parts are constants)."""
    out = []
    for node in ast.walk(ast.parse(source, filename)):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            for m in OPTION.finditer(node.value):
                around = node.value[max(0, m.start() - 30):m.end() + 20]
                out.append(("--" + m.group(1), node.lineno, around))
    return out


def test_the_scan_finds_a_wrong_hint():
    """The scan itself: an f-string hint with an option that does not exist is reported."""
    src = 'raise DataError(f"bad {x}", hint="resample first (CLI --resample HZ) or --fill drop")\n'
    found = {o for o, _, _ in mentioned_options(src)}
    assert found == {"--resample", "--fill"}
    known = cli_options()
    assert "--resample" not in known and "--column" not in known
    assert {"--fill", "--fs", "--allow-code", "--memory-limit", "--time-limit",
            "--scheduler"} <= set(known)


def test_every_option_named_in_src_exists():
    known = set(cli_options()) | BUILTIN
    wrong, seen = [], set()
    for path in sorted(SRC.rglob("*.py")):
        for option, line, text in mentioned_options(path.read_text(), str(path)):
            seen.add(option)
            if option not in known:
                wrong.append(f"{path.relative_to(SRC)}:{line}: {option} in {text!r}")
    assert not wrong, "options that no gripkit command has:\n" + "\n".join(wrong)
    # the scan reads the hints: options that only hints and messages name are among those seen
    assert {"--fill", "--resume", "--allow-code", "--keep-transient",
            "--velocity-threshold"} <= seen


def test_non_uniform_sampling_hint_names_what_exists(cli, tmp_path):
    """The hint named ``--resample HZ``; it now names the Python function and the way back to
    the command line."""
    rng = np.random.default_rng(0)
    n = 400
    t = np.cumsum(0.01 * (1 + 0.2 * rng.random(n)))  # intervals 10-12 ms
    u = rng.standard_normal(n)
    y = np.convolve(u, [0.0, 1.0, 0.5])[:n]
    p = tmp_path / "jitter.csv"
    np.savetxt(p, np.column_stack([t, u, y]), delimiter=",", header="t,u,y", comments="")
    res = cli("identify", "arx", p, "--input", "u", "--output", "y",
              "--na", 1, "--nb", 1, "--nk", 1)
    assert_user_error(res, "DataError", "ARX identification needs uniform sampling")
    assert ("resample the data first (gripkit.signals.resample(tr, dt); for the command line, "
            "save the result with gripkit.io.save)") in res.err
    assert "--resample" not in res.err


def test_mcap_without_columns_hint_names_what_exists(tmp_path):
    """The message said ``CLI: repeat --column``; no command has that option."""
    from mcap_ros2.writer import Writer

    from gripkit.io import load

    p = tmp_path / "run.mcap"
    with open(p, "wb") as f:
        w = Writer(f)
        schema = w.register_msgdef("std_msgs/Float64", "float64 data\n")
        for k in range(5):
            w.write_message("/force", schema, {"data": float(k)}, log_time=k * 10**7,
                            publish_time=k * 10**7)
        w.finish()
    with pytest.raises(DataError) as e:
        load(p)
    msg = str(e.value)
    assert msg.startswith("run.mcap: name the MCAP columns to read "
                          "(gripkit.io.load(path, columns=[...]))")
    assert "the commands take the same names as their column options (--input /cmd:data[0]" in msg
    assert "--column" not in msg
    assert load(p, columns=["f=/force:data"])["f"].tolist() == [0.0, 1.0, 2.0, 3.0, 4.0]
