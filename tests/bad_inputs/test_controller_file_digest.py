"""Controller files edited by hand: a file whose gain or limit was changed loaded without a word
and was then exported to C (``gripkit export c``) and run on a target. A controller file now ends
with ``content_sha256``, the content digest every model file carries (the same function,
:func:`gripkit.sysid.model_file.content_hash`); a file whose content no longer matches it loads
with one DataWarning naming the file (the edited numbers are used: a deliberate edit stays
possible), in Python and as one ``warning:`` line of ``gripkit export c`` (and in its JSON
``warnings``); a file without the entry (written before it existed) loads silently.

The controllers: a SIMC PID of the second-order plant of tests/export/test_c_controllers.py, an
RST pole placement of it, and an LQR state feedback with limits, built here."""

from __future__ import annotations

import json

import numpy as np
import pytest
from corpus import assert_warned, documented_digest, loaded_with_data_warnings

from gripkit.control import StateFeedback, design_rst, load_controller, save_controller, tune_pid
from gripkit.lti import TransferFunction

PHRASE = "its content differs from what gripkit wrote"
RESAVE = "gripkit.control.save_controller(gripkit.control.load_controller(path), path)"


def _plant():
    return TransferFunction.from_polynomials([1.0, -1.5, 0.56], [0.0, 0.0, 0.2, 0.1], dt=0.01)


CONTROLLERS = {
    "pid": lambda: tune_pid(_plant(), tau_c=0.05, u_min=-1.0, u_max=2.0),
    "rst": lambda: design_rst(_plant(), wn=12.0, u_min=-1.0, u_max=1.0),
    "lqr": lambda: StateFeedback([[1.0, 2.0]], Nr=[[3.0]], dt=0.1, u_min=[-2.0], u_max=[3.0]),
}
#: a gain of each kind's file (a path of keys and indices) and its limit u_max
GAIN = {"pid": ("kp",), "rst": ("S", 0), "lqr": ("K", 0, 1)}
LIMIT = {"pid": ("u_max",), "rst": ("u_max",), "lqr": ("u_max", 0)}


@pytest.fixture(params=list(CONTROLLERS))
def saved(request, tmp_path):
    """(kind, path of the controller file written by ``save_controller``)."""
    path = tmp_path / f"{request.param}_ctl.json"
    save_controller(CONTROLLERS[request.param](), path)
    return request.param, path


def _at(doc, keys):
    node = doc["parameters"]
    for k in keys[:-1]:
        node = node[k]
    return node[keys[-1]], lambda v: node.__setitem__(keys[-1], v)


def _gain(c, kind):
    """The gain GAIN[kind] as the loaded controller uses it."""
    return {"pid": lambda: c.kp, "rst": lambda: float(c.S[0]),
            "lqr": lambda: float(c.K[0, 1])}[kind]()


def test_written_file_loads_silently_and_its_digest_is_the_documented_one(saved):
    """As written: no warning, and ``content_sha256`` (the last entry) is the SHA-256 of the rest
    of the document serialised as documented (sorted keys, no spaces, ASCII), recomputed here
    with hashlib from the specification."""
    _, path = saved
    _, caught = loaded_with_data_warnings(load_controller, path)
    assert caught == []
    doc = json.loads(path.read_text())
    assert doc["content_sha256"] == documented_digest(doc)
    assert list(doc)[-1] == "content_sha256"


@pytest.mark.parametrize("what", ["gain", "limit"])
def test_an_edited_gain_or_limit_warns_once_naming_the_file(saved, what):
    """A gain doubled (PID kp, RST s₀, LQR K₀₁) or the limit u_max changed to 5: one DataWarning,
    on one line, naming the file, saying how to write it again; the controller carries the
    edited number (used as it now stands)."""
    kind, path = saved
    doc = json.loads(path.read_text())
    value, put = _at(doc, (GAIN if what == "gain" else LIMIT)[kind])
    new = 2.0 * value if what == "gain" else 5.0
    put(new)
    path.write_text(json.dumps(doc, indent=2))
    c, caught = loaded_with_data_warnings(load_controller, path)
    assert len(caught) == 1
    message = str(caught[0].message)
    assert PHRASE in message and str(path) in message and RESAVE in message
    assert "\n" not in message
    if what == "gain":
        assert _gain(c, kind) == new
    else:
        assert float(np.ravel(c.u_max if kind != "pid" else c.limits[1])[0]) == 5.0


def test_round_trip_is_byte_for_byte(saved, tmp_path):
    """save → load → save writes the same bytes (the same digest)."""
    _, path = saved
    c, _ = loaded_with_data_warnings(load_controller, path)
    again = tmp_path / "again.json"
    save_controller(c, again)
    assert again.read_bytes() == path.read_bytes()


def test_layout_and_key_order_do_not_matter(saved):
    """Re-indented with the keys in reverse order at every level: the same content, no warning."""
    _, path = saved

    def reverse(x):
        if isinstance(x, dict):
            return {k: reverse(x[k]) for k in reversed(list(x))}
        return [reverse(v) for v in x] if isinstance(x, list) else x

    path.write_text(json.dumps(reverse(json.loads(path.read_text())), indent=5))
    assert loaded_with_data_warnings(load_controller, path)[1] == []


def test_file_without_digest_loads_silently(saved, tmp_path):
    """The entry removed (a file written before gripkit wrote one), a gain edited too: no
    warning (nothing says it was edited); saved again, it gets its digest."""
    kind, path = saved
    doc = json.loads(path.read_text())
    del doc["content_sha256"]
    value, put = _at(doc, GAIN[kind])
    put(2.0 * value)
    path.write_text(json.dumps(doc, indent=2))
    c, caught = loaded_with_data_warnings(load_controller, path)
    assert caught == [] and _gain(c, kind) == 2.0 * value
    save_controller(c, tmp_path / "again.json")
    assert "content_sha256" in json.loads((tmp_path / "again.json").read_text())


def test_export_c_shows_the_warning_as_one_line(cli, tmp_path):
    """``gripkit export c`` of a PID file whose kp was edited: exit 0, the C files written,
    exactly one ``warning: DataWarning: …`` line naming the file, and with --json the same
    text in the JSON ``warnings`` list; the untouched file gives no warning."""
    path = tmp_path / "force_pid.json"
    save_controller(CONTROLLERS["pid"](), path)
    res = cli("export", "c", path, "--kind", "pid", "--out", tmp_path / "c0", "--json")
    assert res.code == 0 and json.loads(res.out)["warnings"] == []
    doc = json.loads(path.read_text())
    doc["parameters"]["kp"] *= 10.0
    path.write_text(json.dumps(doc, indent=2))
    res = cli("export", "c", path, "--kind", "pid", "--out", tmp_path / "c1")
    assert res.code == 0, res.err
    lines = [ln for ln in res.err.splitlines() if PHRASE in ln]
    assert len(lines) == 1 and lines[0].startswith("warning: DataWarning: ")
    assert str(path) in lines[0]
    assert (tmp_path / "c1" / "force_pid.c").exists()
    res = cli("export", "c", path, "--kind", "pid", "--out", tmp_path / "c2", "--json")
    assert res.code == 0, res.err
    assert_warned(res, PHRASE)
    assert sum(PHRASE in w for w in json.loads(res.out)["warnings"]) == 1
