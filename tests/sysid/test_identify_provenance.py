"""Provenance in the library: gripkit.io.load records the file's name and SHA-256 in the
trajectory's meta, and sysid.identify hands them to the model it returns (one record: name and
hash; several: the names joined, no hash; data built in memory: none)."""

import hashlib
import json

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.io import load, save
from gripkit.sysid import identify, load_model


def _record(seed: int, n: int = 600) -> Trajectory:
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = 1.2 * y[t - 1] - 0.5 * y[t - 2] + 0.4 * u[t - 1]
    y += 0.01 * rng.standard_normal(n)
    return Trajectory.uniform(dt=0.01, u=u, y=y, units={"u": "V", "y": "N"})


@pytest.fixture
def files(tmp_path):
    paths = [tmp_path / "run1.csv", tmp_path / "run2.parquet"]
    for i, p in enumerate(paths):
        save(_record(i), p)
    return paths


def test_load_records_name_and_sha256(files):
    for p in files:
        tr = load(p)
        assert tr.meta["source"] == p.name
        assert tr.meta["sha256"] == hashlib.sha256(p.read_bytes()).hexdigest()


def test_identify_sets_the_model_provenance(files, tmp_path):
    digest = hashlib.sha256(files[0].read_bytes()).hexdigest()
    tr = load(files[0])
    ss = identify(tr, "ss", input="u", output="y", order=2)
    assert (ss.data_file, ss.data_hash) == ("run1.csv", digest)
    arx = identify(tr, "arx", input="u", output="y", na=2, nb=1, nk=1)
    assert (arx.data_file, arx.data_hash) == ("run1.csv", digest)
    ss.save(tmp_path / "m.json")
    back = load_model(tmp_path / "m.json")
    assert (back.data_file, back.data_hash) == ("run1.csv", digest)


def test_several_records_join_the_names_without_a_hash(files):
    m = identify([load(p) for p in files], "ss", input="u", output="y", order=2, refine=False)
    assert (m.data_file, m.data_hash) == ("run1.csv, run2.parquet", None)


def test_memory_data_leave_the_provenance_empty():
    m = identify(_record(3), "ss", input="u", output="y", order=2, refine=False)
    assert (m.data_file, m.data_hash) == (None, None)


# --- the nonlinear families: provenance and units of a record read from a file -----------------

#: a CSV of 400 samples at 100 Hz whose headers carry units: u [V] a decaying 1 Hz sweep (it
#: reverses, as a hysteresis needs) with a 7.3 Hz ripple, y [mm] a Prandtl–Ishlinskii operator
#: (thresholds 0, 0.3, 0.6, 0.9 V; weights 1, 0.5, 0.3, 0.2; offset 0.5) behind the lag
#: 0.4 q⁻¹/(1 − 0.6 q⁻¹), plus noise (σ 0.01 mm)
NL_N = 400


def _nonlinear_csv(path):
    from gripkit.sysid import PrandtlIshlinskiiModel

    t = np.arange(NL_N) * 0.01
    u = (2.0 * np.sin(2 * np.pi * t) * (1.0 - 0.5 * t / t[-1])
         + 0.2 * np.sin(2 * np.pi * 7.3 * t))
    h = PrandtlIshlinskiiModel(np.arange(4) * 0.3, np.array([1.0, 0.5, 0.3, 0.2]),
                               offset=0.5).simulate(u)[:, 0]
    y = np.zeros(NL_N)
    for k in range(1, NL_N):
        y[k] = 0.6 * y[k - 1] + 0.4 * h[k - 1]
    y += 0.01 * np.random.default_rng(5).standard_normal(NL_N)
    rows = "".join(f"{a:.2f},{b:.10g},{c:.10g}\n" for a, b, c in zip(t, u, y))
    path.write_text("t,u [V],y [mm]\n" + rows, encoding="utf-8")
    return path


#: each nonlinear family (with the rational NARX basis and both hysteresis models): its method
#: and options of sysid.identify, and the class that comes back
NONLINEAR = {
    "narx": ("narx", dict(degree=2, lags=2), "NARXModel"),
    "rational-narx": ("narx", dict(basis="rational", degree=1, lags=1), "RationalNARXModel"),
    "hw": ("hw", dict(nb=1, nf=1, nk=1, output_nonlinearity="poly:2"), "HWModel"),
    "prandtl-ishlinskii": ("hysteresis", dict(model="prandtl-ishlinskii", operators=4),
                           "PrandtlIshlinskiiModel"),
    "bouc-wen": ("hysteresis", dict(model="bouc-wen", progress=False), "BoucWenModel"),
    "nlss": ("nlss", dict(order=1, degree=2, progress=False), "NLSSModel"),
}


@pytest.fixture(scope="module")
def nl_file(tmp_path_factory):
    return _nonlinear_csv(tmp_path_factory.mktemp("nl") / "rec.csv")


@pytest.fixture(scope="module")
def linear_reference(nl_file):
    """What a linear model (ARX) fitted on the same file carries: the provenance and units the
    nonlinear families must match."""
    return identify(load(nl_file), "arx", input="u", output="y")


def _units(m) -> tuple:
    """(input units, output units) of a single-channel model or an NLSS model."""
    if hasattr(m, "input_units"):
        return tuple(m.input_units), tuple(m.output_units)
    return (m.input_unit,), (m.output_unit,)


@pytest.mark.parametrize("family", list(NONLINEAR))
def test_nonlinear_model_carries_provenance_and_units_through_its_file(family, nl_file,
                                                                       linear_reference,
                                                                       tmp_path):
    """Identified from the file, every nonlinear family carries the linear model's data_file
    ('rec.csv') and data_hash (the SHA-256 of the file's bytes), and the units of the columns:
    'V', and 'm' for the column written in mm (gripkit.io.load reads it in SI, as the ARX model
    records it); save → load_model gives the same type with the same four values."""
    import gripkit.sysid as sysid

    method, options, cls = NONLINEAR[family]
    digest = hashlib.sha256(nl_file.read_bytes()).hexdigest()
    lin = linear_reference
    assert (lin.data_file, lin.data_hash) == ("rec.csv", digest)
    assert (lin.input_unit, lin.output_unit) == ("V", "m")
    m = identify(load(nl_file), method, input="u", output="y", **options)
    assert type(m) is getattr(sysid, cls)
    assert (m.data_file, m.data_hash) == (lin.data_file, lin.data_hash)
    assert _units(m) == (("V",), ("m",)) and (m.inputs, m.outputs) == (("u",), ("y",))
    m.save(tmp_path / "m.json")
    doc = json.loads((tmp_path / "m.json").read_text(encoding="utf-8"))
    assert doc["data"] == {"file": "rec.csv", "sha256": digest}  # the linear model file's entry
    back = load_model(tmp_path / "m.json")
    assert type(back) is type(m)
    assert (back.data_file, back.data_hash) == ("rec.csv", digest)
    assert _units(back) == (("V",), ("m",)) and (back.inputs, back.outputs) == (("u",), ("y",))


@pytest.mark.parametrize("family", list(NONLINEAR))
def test_nonlinear_file_written_before_provenance_loads_with_none(family, nl_file, tmp_path):
    """A model file without the provenance entry (and, for NARX and HW, without the units: the
    files written before them) loads with data_file = data_hash = None (units '1'); the
    parameters are those saved."""
    method, options, _ = NONLINEAR[family]
    m = identify(load(nl_file), method, input="u", output="y", **options)
    m.save(tmp_path / "m.json")
    doc = json.loads((tmp_path / "m.json").read_text(encoding="utf-8"))
    old = {k: v for k, v in doc.items() if k not in ("data", "content_sha256")}
    if family in ("narx", "rational-narx", "hw"):
        old = {k: v for k, v in old.items() if k not in ("input_unit", "output_unit")}
    (tmp_path / "old.json").write_text(json.dumps(old), encoding="utf-8")
    back = load_model(tmp_path / "old.json")
    assert type(back) is type(m) and (back.data_file, back.data_hash) == (None, None)
    if family in ("narx", "rational-narx", "hw"):
        assert (back.input_unit, back.output_unit) == ("1", "1")
    assert [p.value for p in back.parameters.values()] == \
        [p.value for p in m.parameters.values()]


def test_nonlinear_file_with_a_malformed_provenance_is_refused(nl_file, tmp_path):
    """A 'data' entry that is neither null nor {file, sha256}: ModelError naming the file and
    the entry."""
    from gripkit.errors import ModelError

    m = identify(load(nl_file), "narx", input="u", output="y", degree=1, lags=1)
    m.save(tmp_path / "m.json")
    doc = json.loads((tmp_path / "m.json").read_text(encoding="utf-8"))
    doc["data"] = "rec.csv"
    (tmp_path / "bad.json").write_text(json.dumps(doc), encoding="utf-8")
    with pytest.raises(ModelError, match=r"narx model file '.*bad\.json': the entry 'data' must "
                                         r"be null or"):
        load_model(tmp_path / "bad.json")


@pytest.mark.parametrize("method, options", [
    ("narx", dict(degree=1, lags=2)),
    ("hw", dict(nb=2, nf=2, nk=1)),
])
def test_nonlinear_several_records_and_memory_data(files, method, options):
    """NARX and HW of several files: the names joined, no hash (as the linear models); of data
    built in memory: no provenance, the units of the trajectory ('V', 'N')."""
    m = identify([load(p) for p in files], method, input="u", output="y", **options)
    assert (m.data_file, m.data_hash) == ("run1.csv, run2.parquet", None)
    assert (m.input_unit, m.output_unit) == ("V", "N")
    m = identify(_record(3), method, input="u", output="y", **options)
    assert (m.data_file, m.data_hash) == (None, None)
    assert (m.input_unit, m.output_unit) == ("V", "N")


def test_prandtl_ishlinskii_inverse_keeps_the_provenance(nl_file):
    """The inverse of an identified Prandtl–Ishlinskii model is derived from the same data: it
    keeps their file and hash, its units swapped."""
    m = identify(load(nl_file), "hysteresis", input="u", output="y", model="prandtl-ishlinskii",
                 operators=4)
    inv = m.invert()
    assert (inv.data_file, inv.data_hash) == (m.data_file, m.data_hash) != (None, None)
    assert (inv.input_unit, inv.output_unit) == ("m", "V")
