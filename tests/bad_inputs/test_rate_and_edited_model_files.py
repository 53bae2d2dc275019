"""Silent wrong answers of the model files and the nonlinear families (audit of 27 Nov):

1. every rate-dependent nonlinear family (NARX, Hammerstein–Wiener, nonlinear state space, the
   Bouc-Wen oscillator) refuses data sampled at another interval than the model's, with the
   linear models' DataError (one shared check), in Python and in the CLI; arrays (no time)
   and the rate-independent hysteresis forms keep working;
2. an edited model file whose copies of a value disagree, or whose field is out of its
   domain, is refused on load with a one-line malformed-file ModelError naming the field.

Every model is identified on a short synthetic record built here (a saturated input into the
ARX [2 2 1] y(t) = 1.2 y(t−1) − 0.5 y(t−2) + 0.8 w(t−1) + 0.3 w(t−2), noise σ = 0.01)."""

from __future__ import annotations

import json

import numpy as np
import pytest
from corpus import assert_user_error, clipped_arx_record

from gripkit import Trajectory
from gripkit.errors import DataError, ModelError
from gripkit.sysid import (BoucWenModel, BoucWenOscillatorModel, arx, compare, hammerstein_wiener,
                           load_model, narx, nlss)

DT = 0.01


U, Y = clipped_arx_record()
#: the Bouc-Wen forms built from known parameters (none estimated: ``free=()``)
OSC = BoucWenOscillatorModel(mass=1.0, damping=6.0, k_e=2000.0, k_h=2000.0, beta=300.0,
                             gamma=100.0, offset=0.0, dt=1e-3, free=())
BW = dict(d=0.5, alpha=1.0, beta=0.5, gamma=0.2, dt=DT, free=())


def _models() -> dict:
    return {"narx": narx(U, Y, degree=2, lags=2, dt=DT),
            "hw": hammerstein_wiener(U, Y, input_nonlinearity="saturation", nb=2, nf=2, nk=1,
                                     dt=DT),
            "nlss": nlss((U, Y), order=2, degree=2, dt=DT, progress=False),
            "bouc-wen oscillator": OSC}


MODELS = _models()


def _trajectory(m, dt: float) -> Trajectory:
    return Trajectory.uniform(dt=dt, **{m.inputs[0]: U, m.outputs[0]: Y})


@pytest.mark.filterwarnings("ignore")
@pytest.mark.parametrize("family", list(MODELS))
def test_nonlinear_family_refuses_data_at_another_rate(family):
    """Item 1: compare, simulate and sysid.compare refuse a record at twice the model's interval
    with the message of the linear models (an ARX model says the same words); at the model's
    interval the fit is that of the bare arrays, which carry no time and keep working."""
    m = MODELS[family]
    wrong = _trajectory(m, 2 * m.dt)
    phrase = f"data: sampled every {2 * m.dt:g} s, the model every {m.dt:g} s"
    for call in (lambda: m.compare(wrong), lambda: m.simulate(wrong),
                 lambda: compare(m, wrong, None), lambda: compare(m, U, Y, dt=2 * m.dt)):
        with pytest.raises(DataError) as err:
            call()
        assert phrase in err.value.message
    lin = arx(U, Y, 2, 2, 1, dt=m.dt, input_name=m.inputs[0], output_name=m.outputs[0])
    with pytest.raises(DataError) as err:
        lin.compare(_trajectory(lin, 2 * m.dt))
    assert phrase in err.value.message
    assert m.compare(_trajectory(m, m.dt)).fit_percent == m.compare(U, Y).fit_percent


def test_rate_independent_hysteresis_takes_any_rate():
    """Item 1, the hysteresis forms: the actuator-form Bouc-Wen (its output a function of the
    input's path only) gives the same run at any sample interval."""
    m = BoucWenModel(**BW)
    u = np.sin(np.linspace(0.0, 6 * np.pi, 300))
    tr = Trajectory.uniform(dt=DT, u=u)
    np.testing.assert_array_equal(m.simulate(Trajectory.uniform(dt=5 * DT, u=u)), m.simulate(tr))


def test_cli_compare_and_simulate_refuse_another_rate(cli, tmp_path):
    """Item 1 in the CLI: a NARX model identified at 100 Hz compared with (or run on) a record
    read at --fs 50 is one DataError line; at --fs 100 the fit is the model's on the arrays."""
    m = MODELS["narx"]
    path = m.save(tmp_path / "narx.json") or tmp_path / "narx.json"
    data = tmp_path / "rec.csv"
    np.savetxt(data, np.column_stack([U, Y]), delimiter=",", header="u,y", comments="",
               fmt="%.17g")
    for args in (("compare", path, data), ("simulate", path, "--data", data)):
        assert_user_error(cli(*args, "--fs", 50), "DataError",
                          "data: sampled every 0.02 s, the model every 0.01 s")
    res = cli("compare", path, data, "--fs", 100, "--json")
    assert res.code == 0, res.err
    assert res.json()["fit_percent"][0] == pytest.approx(m.compare(U, Y).fit_percent[0],
                                                         rel=1e-12)


def _edited(tmp_path, path, edit, name="edited.json"):
    """A copy of the model file ``path`` with ``edit(doc)`` applied (its content hash left
    stale, as a hand edit leaves it)."""
    doc = json.loads(path.read_text())
    edit(doc)
    out = tmp_path / name
    out.write_text(json.dumps(doc))
    return out


@pytest.fixture
def arx_file(tmp_path):
    """An ARX [2 2 1] model of the record (current [A] → force [N], offsets 0.5 A and 1 N),
    saved; with its fit on the record."""
    m = arx(U + 0.5, Y + 1.0, 2, 2, 1, dt=DT, input_name="current", output_name="force",
            input_unit="A", output_unit="N", u_offset=0.5, y_offset=1.0)
    path = tmp_path / "arx.json"
    m.save(path)
    return path, m.compare(U, Y).fit_percent


def _set(keys, value):
    def edit(doc):
        d = doc
        for k in keys[:-1]:
            d = d[k]
        d[keys[-1]] = value
    return edit


@pytest.mark.filterwarnings("ignore::gripkit.errors.AccuracyWarning")
@pytest.mark.filterwarnings("ignore::gripkit.errors.DataWarning")  # edited: content differs
@pytest.mark.parametrize("keys, value, phrase", [
    (("system", "den", 0, 0, 1), -1.4, "'system.den' and the 'polynomial' section disagree"),
    (("system", "den", 0, 0, 2), 1.5, "'system.den' and the 'polynomial' section disagree"),
    (("polynomial", "A", 1), -1.4, "'info.A' and the 'polynomial' section disagree"),
    (("info", "B", 1), 0.5, "'info.B' and the 'polynomial' section disagree"),
])
def test_arx_file_copies_that_disagree_are_refused(arx_file, tmp_path, cli, keys, value, phrase):
    """Item 2a: the system (B/(A F), the copy for readers without polynomials) edited alone, made
    unstable, or the polynomial edited alone: a malformed-file ModelError naming both fields,
    in Python and as the CLI's one line, never a fit from the other copy."""
    path, _ = arx_file
    bad = _edited(tmp_path, path, _set(keys, value))
    with pytest.raises(ModelError, match="malformed") as err:
        load_model(bad)
    assert phrase in err.value.message
    assert_user_error(cli("export", "c", bad, "--out", tmp_path / "c"), "ModelError", phrase)


@pytest.mark.filterwarnings("ignore::gripkit.errors.AccuracyWarning")
@pytest.mark.filterwarnings("ignore::gripkit.errors.DataWarning")  # edited: content differs
@pytest.mark.parametrize("keys, value, phrase", [
    (("dt",), 0.5, "'dt' is 0.5 but 'system.dt' is 0.01"),
    (("outputs", 0, "offset"), "x", "'outputs[0].offset' must be a finite number, found 'x'"),
    (("inputs", 0, "offset"), None, "'inputs[0].offset' must be a finite number, found 'None'"),
    (("outputs", 0, "unit"), "m", "'outputs[0].unit' is 'm' but 'system.output_units[0]' is 'N'"),
])
def test_arx_file_fields_that_contradict_the_system_are_refused(arx_file, tmp_path, cli, keys,
                                                                value, phrase):
    """Items 2b and 2c: a top-level dt or unit contradicting the system's, an offset that is no
    number: one malformed-file ModelError line naming the field (not an unexpected ValueError)."""
    path, _ = arx_file
    bad = _edited(tmp_path, path, _set(keys, value))
    with pytest.raises(ModelError, match="malformed") as err:
        load_model(bad)
    assert phrase in err.value.message
    data = tmp_path / "rec.csv"
    np.savetxt(data, np.column_stack([U + 0.5, Y + 1.0]), delimiter=",",
               header="current [A],force [N]", comments="", fmt="%.17g")
    assert_user_error(cli("compare", bad, data, "--fs", 100), "ModelError", phrase)


def test_untouched_arx_file_loads_with_the_same_fit(arx_file, recwarn):
    """An untouched file loads without a warning and gives the fit of the model that wrote it."""
    path, fit = arx_file
    back = load_model(path)
    assert back.compare(U, Y).fit_percent == fit
    assert not [w for w in recwarn if "edited" in str(w.message)]


#: (family, field path, edited value, key phrase of the malformed-file ModelError)
NONLINEAR_EDITS = [
    ("narx", ("output_unit",), "zorkmid", "'output_unit' must be a unit gripkit can read"),
    ("narx", ("degree",), -3, "'degree' must be a whole number ≥ 1, found -3"),
    ("narx", ("dt",), 0, "'dt' must be a finite number > 0, found 0"),
    ("hw", ("theta", 0), None, "'theta[0]' must be a finite number, found null"),
    ("hw", ("dt",), -0.01, "'dt' must be a finite number > 0, found -0.01"),
    ("nlss", ("A", 0, 0), None, "'A[0][0]' must be a finite number, found null"),
    ("nlss", ("output_units", 0), 7, "'output_units[0]' must be a unit gripkit can read"),
    ("bouc-wen", ("n",), -1, "'n' must be a finite number in [1, 10], found -1"),
    ("bouc-wen oscillator", ("dt",), 0, "'dt' must be a finite number > 0, found 0"),
]


def _saved(family: str, tmp_path):
    m = (BoucWenModel(**BW) if family == "bouc-wen"
         else MODELS[family])
    path = tmp_path / f"{family.replace(' ', '_')}.json"
    m.save(path)
    return m, path


@pytest.mark.filterwarnings("ignore::gripkit.errors.DataWarning")  # edited: content differs
@pytest.mark.parametrize("family, keys, value, phrase", NONLINEAR_EDITS)
def test_nonlinear_file_field_out_of_domain_is_refused(family, keys, value, phrase, tmp_path,
                                                       cli):
    """Item 2d: a unit gripkit cannot read, a degree below 1, a sample time ≤ 0, a null
    parameter, a Bouc-Wen exponent outside [1, 10] (where hysteresis() fits it): refused on load
    with a malformed-file ModelError naming the field (not accepted, not "diverged"), in Python
    and as the CLI's one line."""
    _, path = _saved(family, tmp_path)
    bad = _edited(tmp_path, path, _set(keys, value))
    with pytest.raises(ModelError, match="malformed") as err:
        load_model(bad)
    assert phrase in err.value.message
    data = tmp_path / "rec.csv"
    np.savetxt(data, np.column_stack([U, Y]), delimiter=",", header="u,y", comments="",
               fmt="%.17g")
    assert_user_error(cli("compare", bad, data, "--fs", 100), "ModelError", phrase)


@pytest.mark.filterwarnings("ignore")
@pytest.mark.parametrize("family", ["narx", "hw", "nlss", "bouc-wen", "bouc-wen oscillator"])
def test_untouched_nonlinear_file_gives_the_same_fit(family, tmp_path):
    """The files written by the families load as before: the same fit on the record."""
    m, path = _saved(family, tmp_path)
    assert load_model(path).compare(U, Y).fit_percent == m.compare(U, Y).fit_percent


@pytest.mark.filterwarnings("ignore::gripkit.errors.DataWarning")  # edited: content differs
def test_nonlinear_model_reads_the_data_in_its_units(tmp_path):
    """Item 2d, a readable unit of another quantity: a NARX file whose output_unit says
    'furlong' (a length) compared with a record whose output is in V is refused with the linear
    models' DataError; a record in the model's units (V → m) fits as the arrays do."""
    m, path = _saved("narx", tmp_path)
    doc = json.loads(path.read_text())
    doc.update(input_unit="V", output_unit="furlong")
    path.write_text(json.dumps(doc))
    back = load_model(path)
    volts = Trajectory.uniform(dt=DT, u=U, y=Y, units={"u": "V", "y": "V"})
    with pytest.raises(DataError, match="a different physical quantity"):
        back.compare(volts)
    doc.update(output_unit="m")
    path.write_text(json.dumps(doc))
    metres = Trajectory.uniform(dt=DT, u=U, y=Y, units={"u": "V", "y": "m"})
    assert load_model(path).compare(metres).fit_percent == m.compare(U, Y).fit_percent


@pytest.mark.filterwarnings("ignore::gripkit.errors.AccuracyWarning")
@pytest.mark.filterwarnings("ignore::gripkit.errors.DataWarning")  # edited: content differs
def test_arx_polynomial_edited_with_its_info_copy_is_refused(arx_file, tmp_path):
    """Item 2a: a1 edited in the polynomial section and in info alike (the system left): the
    system the file shows is not the model's, so the file is refused, naming 'system.den'."""
    path, _ = arx_file

    def edit(doc):
        doc["polynomial"]["A"][1] = doc["info"]["A"][1] = -1.4

    with pytest.raises(ModelError, match="malformed") as err:
        load_model(_edited(tmp_path, path, edit))
    assert "'system.den' and the 'polynomial' section disagree" in err.value.message
    assert "is -1.2" in err.value.message and "-1.4 by 'polynomial'" in err.value.message


def test_a_model_runs_on_the_record_it_was_identified_from_at_any_rate():
    """fs = 610.35 Hz: the identified model keeps dt = 1/fs to 9 significant digits (2.6·10⁻⁹
    relative from the record's); compare on that very record is no rate mismatch (it was refused
    at a 10⁻⁹ tolerance), while a record at 610 Hz still is."""
    from gripkit.sysid import identify

    rng = np.random.default_rng(5)
    u = rng.standard_normal(600)
    y = np.convolve(u, [0.0, 0.5, 0.25])[:600] + 0.01 * rng.standard_normal(600)
    tr = Trajectory.uniform(dt=1 / 610.35, u=u, y=y)
    model = identify(tr, "arx", input="u", output="y", na=1, nb=2, nk=1)
    assert model.dt != tr.dt and abs(model.dt - tr.dt) < 1e-8 * tr.dt
    assert model.compare(tr).fit_percent[0] > 90.0
    assert compare(model, tr, None).fit_percent[0] == model.compare(tr).fit_percent[0]
    with pytest.raises(DataError, match="sampled every"):
        model.compare(Trajectory.uniform(dt=1 / 610.0, u=u, y=y))
