"""Model files edited by hand (audit of 27 Nov): a file whose two copies of the output unit were
both changed from "N" to "kN" loaded without a word, and every prediction was then 1000× off in
the user's eyes. Every model file gripkit writes (linear, dynamics, each nonlinear family) now
ends with ``content_sha256``, the SHA-256 of the canonical JSON of the rest of the document
(:func:`gripkit.sysid.model_file.content_hash`); a file whose content no longer matches it loads
with one DataWarning naming the file (a deliberate edit stays possible), in Python and as one
``warning:`` line of the CLI (and in its JSON ``warnings``); a file without the entry loads
silently where it may predate the digest (a nonlinear family's file), with one DataWarning where
gripkit has always written one (a linear model file).

The models are identified on a short synthetic record built here (a saturated input current [A]
into the ARX [2 2 1] force [N] y(t) = 1.2 y(t−1) − 0.5 y(t−2) + 0.8 w(t−1) + 0.3 w(t−2),
noise σ = 0.01), or built from known parameters (the Bouc-Wen oscillator)."""

from __future__ import annotations

import hashlib
import json

import numpy as np
import pytest
from corpus import assert_warned, clipped_arx_record, documented_digest, loaded_with_data_warnings

from gripkit import Trajectory
from gripkit.errors import DataWarning, ModelError
from gripkit.sysid import BoucWenOscillatorModel, identify, load_model

DT = 0.01
PHRASE = "its content differs from what gripkit wrote"
MISSING = "its content cannot be checked against what gripkit wrote (content_sha256 is missing"


def _record(n: int = 400, seed: int = 0) -> Trajectory:
    u, y = clipped_arx_record(n, seed)
    return Trajectory.uniform(dt=DT, current=u, force=y, units={"current": "A", "force": "N"})


TR = _record()
IO = dict(input="current", output="force")
FAMILIES = {
    "arx": lambda: identify(TR, "arx", na=2, nb=2, nk=1, **IO),
    "narx": lambda: identify(TR, "narx", degree=2, lags=2, **IO),
    "rational narx": lambda: identify(TR, "narx", basis="rational", degree=1, den_degree=1,
                                      lags=2, **IO),
    "hw": lambda: identify(TR, "hw", input_nonlinearity="saturation", nb=2, nf=2, nk=1, **IO),
    "nlss": lambda: identify(TR, "nlss", order=2, degree=2, progress=False, **IO),
    "bouc-wen oscillator": lambda: BoucWenOscillatorModel(
        mass=1.0, damping=6.0, k_e=2000.0, k_h=2000.0, beta=300.0, gamma=100.0, offset=0.0,
        dt=1e-3, free=(), input_name="current", output_name="force", input_unit="A",
        output_unit="N"),
}


@pytest.fixture(params=list(FAMILIES))
def saved(request, tmp_path):
    """(family, path of the model file written by ``model.save``)."""
    path = tmp_path / f"{request.param.replace(' ', '_')}.json"
    FAMILIES[request.param]().save(path)
    return request.param, path


def test_written_file_loads_without_warning_and_its_digest_is_the_documented_one(saved):
    """A file as gripkit wrote it: no warning, and its ``content_sha256`` is the SHA-256 of the
    rest of the document serialised as documented (sorted keys, no spaces, ASCII): recomputed
    here from the specification with hashlib, not with gripkit's function."""
    _, path = saved
    _, caught = loaded_with_data_warnings(load_model, path)
    assert caught == []
    doc = json.loads(path.read_text())
    assert doc["content_sha256"] == documented_digest(doc)
    assert list(doc)[-1] == "content_sha256"


def test_units_edited_alike_warn_once_naming_the_file(saved):
    """The audit's case: "N" changed to "kN" everywhere in the file (both copies alike, numbers
    untouched) loads with one DataWarning naming the file, saying its content differs from what
    gripkit wrote and how to write it again; the model then carries the edited unit, as the
    warning says (its numbers and units used as they now stand)."""
    _, path = saved
    text = path.read_text()
    assert text.count('"N"') >= 1
    path.write_text(text.replace('"N"', '"kN"'))
    model, caught = loaded_with_data_warnings(load_model, path)
    assert len(caught) == 1
    message = str(caught[0].message)
    assert str(path) in message and PHRASE in message and "\n" not in message
    assert "numbers and units are used as they now stand" in message
    assert "gripkit.sysid.load_model(path).save(path)" in message
    assert list(model.output_units) == ["kN"]


def _first_number_path(doc, keys):
    """The value at ``keys`` (a path of keys and indices into ``doc``) and a setter for it."""
    node = doc
    for k in keys[:-1]:
        node = node[k]
    return node[keys[-1]], lambda v: node.__setitem__(keys[-1], v)


#: a number of each family's file that no other field repeats
NUMBER = {"narx": ("theta", 0), "rational narx": ("theta", 0), "hw": ("theta", 0),
          "nlss": ("A", 0, 0), "bouc-wen oscillator": ("k_e",)}


def test_a_number_edited_warns_or_is_refused(saved):
    """One number edited: the families' parameter (θ₀, A₀₀, k_e) loads with the warning and the
    edited value; in an ARX file the denominator edited in the system alone is the malformed
    file's ModelError (its two copies disagree), as before."""
    family, path = saved
    doc = json.loads(path.read_text())
    if family == "arx":
        doc["system"]["den"][0][0][1] = -1.4
        path.write_text(json.dumps(doc))
        with pytest.warns(DataWarning, match=PHRASE), pytest.raises(ModelError,
                                                                    match="disagree"):
            load_model(path)
        return
    value, put = _first_number_path(doc, NUMBER[family])
    put(2.0 * value)
    path.write_text(json.dumps(doc, indent=1))
    model, caught = loaded_with_data_warnings(load_model, path)
    assert len(caught) == 1 and PHRASE in str(caught[0].message)
    back = model.to_dict()
    assert _first_number_path(back, NUMBER[family])[0] == 2.0 * value


def test_round_trip_keeps_the_digest_and_the_bytes(saved, tmp_path):
    """save → load → save writes the same file byte for byte (same digest): the digest is of
    the content, stable across a round trip."""
    _, path = saved
    model, _ = loaded_with_data_warnings(load_model, path)
    again = tmp_path / "again.json"
    model.save(again)
    assert again.read_bytes() == path.read_bytes()
    assert json.loads(again.read_text())["content_sha256"] == json.loads(
        path.read_text())["content_sha256"]


def test_layout_and_key_order_do_not_matter(saved):
    """Re-indented, its keys in reverse order at every level, a number spelled otherwise but
    equal (1.0 as 1.00e0): the same content, so no warning."""
    _, path = saved

    def reverse(x):
        if isinstance(x, dict):
            return {k: reverse(x[k]) for k in reversed(list(x))}
        return [reverse(v) for v in x] if isinstance(x, list) else x

    text = json.dumps(reverse(json.loads(path.read_text())), indent=4)
    if "1.0," in text:
        text = text.replace("1.0,", "1.00e0,", 1)
    path.write_text(text)
    _, caught = loaded_with_data_warnings(load_model, path)
    assert caught == []


def test_file_without_digest_loads_silently_where_older_files_have_none(saved, tmp_path):
    """The entry removed from a nonlinear family's file (such a file written before gripkit wrote
    one has the same version): loads without a warning, the model as saved (saved again, it
    writes the original file). A linear model file has had its digest in every version, so
    there the missing entry is one DataWarning naming the file, and the file loads as it is."""
    family, path = saved
    original = path.read_bytes()
    doc = json.loads(original)
    del doc["content_sha256"]
    path.write_text(json.dumps(doc, indent=1))
    back, caught = loaded_with_data_warnings(load_model, path)
    if family == "arx":
        assert len(caught) == 1 and MISSING in str(caught[0].message)
        assert str(path) in str(caught[0].message)
    else:
        assert caught == []
    back.save(tmp_path / "again.json")
    assert (tmp_path / "again.json").read_bytes() == original


def test_linear_file_with_dt_edited_and_digest_deleted_warns(tmp_path):
    """Review reproducer: an ARX file whose dt was changed 0.01 → 0.02 s and whose digest was
    deleted loaded without a word before; now one DataWarning (the missing digest, the hint to
    save again), and the edited dt is used as it stands."""
    path = tmp_path / "arx.json"
    FAMILIES["arx"]().save(path)
    doc = json.loads(path.read_text())
    del doc["content_sha256"]
    text = json.dumps(doc)
    assert text.count('"dt": 0.01') >= 1
    path.write_text(text.replace('"dt": 0.01', '"dt": 0.02'))
    model, caught = loaded_with_data_warnings(load_model, path)
    assert len(caught) == 1
    assert MISSING in str(caught[0].message) and "load_model(path).save(path)" in str(
        caught[0].message)
    assert model.system.dt == 0.02


def test_digest_tells_an_integer_from_a_float():
    """content_hash's documented canonical form: a float spelled otherwise (1.50, 15e-1) hashes
    alike, but the integer 1 and the float 1.0 (and 0.0, -0.0) do not: JSON reads them as
    different numbers, and merging them would change the digest of files already written."""
    from gripkit.sysid.model_file import content_hash

    def h(text):
        return content_hash(json.loads(text))

    assert h('{"a": 1.50}') == h('{"a": 15e-1}') == h('{"a": 1.5E0}')
    assert h('{"a": 1}') != h('{"a": 1.0}')
    assert h('{"a": 0.0}') != h('{"a": -0.0}')


def test_cli_shows_the_warning_as_one_line(cli, tmp_path):
    """``gripkit compare`` and ``gripkit simulate`` of a NARX file whose unit was edited: exit 0,
    exactly one ``warning: DataWarning: …`` line naming the file, and with --json the same text
    in the JSON ``warnings`` list."""
    path = tmp_path / "narx.json"
    FAMILIES["narx"]().save(path)
    path.write_text(path.read_text().replace('"N"', '"mN"'))
    data = tmp_path / "rec.csv"
    np.savetxt(data, np.column_stack([TR["current"], TR["force"]]), delimiter=",",
               header="current [A],force [N]", comments="", fmt="%.17g")
    for args in (("compare", path, data, "--fs", 100),
                 ("simulate", path, "--data", data, "--fs", 100)):
        res = cli(*args)
        assert res.code == 0, res.err
        lines = [ln for ln in res.err.splitlines() if PHRASE in ln]
        assert len(lines) == 1 and lines[0].startswith("warning: DataWarning: ")
        assert str(path) in lines[0]
        res = cli(*args, "--json")
        assert res.code == 0, res.err
        assert_warned(res, PHRASE)


def test_canonical_text_is_the_documented_one():
    """The digest's text, written out by hand for a small document: keys sorted at every level,
    no spaces, non-ASCII escaped, each float as its shortest round-trip form (0.1, 1e-300, 1.0
    kept distinct from 1), the entry content_sha256 left out; dict order does not matter."""
    from gripkit.sysid.model_file import content_hash

    doc = {"units": {"y": "µN", "u": "A"}, "dt": 0.1, "a": [1.0, 1, -0.0, 1e-300, 2.5e17],
           "content_sha256": "anything"}
    text = ('{"a":[1.0,1,-0.0,1e-300,2.5e+17],"dt":0.1,'
            '"units":{"u":"A","y":"\\u00b5N"}}')
    assert content_hash(doc) == hashlib.sha256(text.encode("ascii")).hexdigest()
    assert content_hash(dict(reversed(list(doc.items())))) == content_hash(doc)
