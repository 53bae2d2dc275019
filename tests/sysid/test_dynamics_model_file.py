"""Dynamics model files (``result.save`` / :func:`gripkit.sysid.load_dynamics_model`, schema
``gripkit.dynamics-model``) and ``gripkit identify dynamics --out/--report``: the loaded model
predicts the original's torques, an edited file warns, another schema is refused; the CLI writes
both files. The chain is the DLR/HIT finger of the zoo written as URDF (as in
test_identify_dynamics.py), the data noisy inverse-dynamics torques with friction."""

import hashlib
import json
import warnings

import numpy as np
import pytest
from test_identify_dynamics import fourier_states, torques

from gripkit.cli import main
from gripkit.errors import DataWarning, ModelError
from gripkit.multibody import from_urdf, to_urdf
from gripkit.sysid import identify_dynamics, load_dynamics_model


@pytest.fixture(scope="module")
def finger_urdf(tmp_path_factory):
    from gripkit import zoo

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return (to_urdf(zoo.build("dlr-hit-finger").chain(),
                        tmp_path_factory.mktemp("dyn") / "finger.urdf"))


@pytest.fixture(scope="module")
def fit(finger_urdf):
    chain = from_urdf(finger_urdf)
    rng = np.random.default_rng(3)
    q, qd, qdd = fourier_states(3000, 1000.0, rng)
    res = identify_dynamics(chain, q, qd, qdd, torques(chain, q, qd, qdd, rng))
    return res.replace(urdf_text=finger_urdf.read_text(), data_file="log.csv", data_hash="0" * 64)


@pytest.fixture
def saved(fit, tmp_path):
    path = tmp_path / "model.json"
    fit.save(path)
    return path


def test_round_trip_predicts_the_same_torques(fit, saved):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an untouched file loads without a warning
        m = load_dynamics_model(saved)
    rng = np.random.default_rng(11)
    q, qd, qdd = (rng.uniform(-2, 2, (200, 3)) for _ in range(3))
    np.testing.assert_allclose(m.predict(q, qd, qdd), fit.predict(q, qd, qdd), rtol=0, atol=1e-12)
    assert m.base_parameters == fit.base_parameters
    assert m.base_parameters_std == fit.base_parameters_std
    assert m.friction == fit.friction
    np.testing.assert_array_equal(m.covariance, fit.covariance)
    assert m.consistency.consistent == fit.consistency.consistent
    assert (m.data_file, m.data_hash) == ("log.csv", "0" * 64)
    doc = json.loads(saved.read_text())
    assert doc["schema"] == "gripkit.dynamics-model" and doc["schema_version"] == 1
    assert doc["urdf"]["sha256"] == hashlib.sha256(doc["urdf"]["text"].encode()).hexdigest()
    assert doc["joints"] == list(fit.chain.coordinate_names)
    assert doc["gravity"] == list(fit.chain.gravity_vector)
    # saving the loaded model writes the same content
    m.save(saved.with_name("again.json"))
    assert (json.loads(saved.with_name("again.json").read_text())["content_sha256"]
            == doc["content_sha256"])


def test_result_without_urdf_text_writes_its_chain(fit, tmp_path):
    """A result from a chain built in Python saves the chain written as URDF (self-contained)."""
    path = tmp_path / "m.json"
    fit.replace(urdf_text=None).save(path)
    m = load_dynamics_model(path)
    rng = np.random.default_rng(5)
    q, qd, qdd = (rng.uniform(-2, 2, (50, 3)) for _ in range(3))
    np.testing.assert_allclose(m.predict(q, qd, qdd), fit.predict(q, qd, qdd), rtol=0, atol=1e-12)


def test_tampered_file_warns(saved):
    doc = json.loads(saved.read_text())
    doc["parameters"]["values"][0] *= 1.5
    saved.write_text(json.dumps(doc))
    with pytest.warns(DataWarning, match="its content differs from what gripkit wrote"):
        m = load_dynamics_model(saved)
    assert m.theta[0] == doc["parameters"]["values"][0]


def test_file_without_digest_warns(saved):
    """The content digest removed: gripkit has written it in every dynamics model file (schema
    version 1 had it from the start), so its absence is one DataWarning naming the file (edited or
    written by another program; the hint saves it again), and the file loads with the parameters
    as they stand."""
    doc = json.loads(saved.read_text())
    del doc["content_sha256"]
    doc["parameters"]["values"][0] *= 1.5
    saved.write_text(json.dumps(doc))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        m = load_dynamics_model(saved)
    caught = [w for w in caught if issubclass(w.category, DataWarning)]
    assert len(caught) == 1
    message = str(caught[0].message)
    assert "content_sha256 is missing" in message and str(saved) in message
    assert "load_dynamics_model(path).save(path)" in message
    assert list(m.theta) == doc["parameters"]["values"]


@pytest.mark.parametrize("change, phrase", [
    ({"schema": "gripkit.linear-model"}, "expected schema 'gripkit.dynamics-model'"),
    ({"schema_version": 2}, "schema_version")])
def test_other_schema_or_newer_version_refused(saved, change, phrase):
    doc = json.loads(saved.read_text())
    doc.update(change)
    saved.write_text(json.dumps(doc))
    with pytest.raises(ModelError, match=phrase):
        load_dynamics_model(saved)


def test_linear_model_file_refused(tmp_path):
    from gripkit.lti import StateSpace
    from gripkit.sysid.linear.linear_model import LinearModel

    path = tmp_path / "lin.json"
    LinearModel(StateSpace([[0.5]], [[1.0]], [[1.0]], dt=0.1), "n4sid").save(path)
    with pytest.raises(ModelError, match="found 'gripkit.linear-model'"):
        load_dynamics_model(path)


def test_cli_out_and_report(finger_urdf, tmp_path, capsys):
    chain = from_urdf(finger_urdf)
    rng = np.random.default_rng(0)
    q, qd, qdd = fourier_states(8000, 1000.0, rng, f0=0.2)
    tau = torques(chain, q, qd, qdd, rng)
    log = tmp_path / "log.csv"
    cols = np.column_stack([np.arange(q.shape[0]) / 1000.0, q, tau])
    np.savetxt(log, cols, delimiter=",", header="t,p0,p1,p2,e0,e1,e2", comments="")
    out, rep = tmp_path / "new" / "finger.json", tmp_path / "rep"
    code = main(["identify", "dynamics", str(finger_urdf), str(log), "--position", "p0,p1,p2",
                 "--effort", "e0,e1,e2", "--out", str(out), "--report", str(rep), "--json"])
    cap = capsys.readouterr()
    assert code == 0, cap.err
    printed = json.loads(cap.out)
    doc = json.loads(out.read_text())
    assert doc["data"] == {"file": "log.csv",
                           "sha256": hashlib.sha256(log.read_bytes()).hexdigest()}
    assert doc["urdf"]["text"] == finger_urdf.read_text()
    m = load_dynamics_model(out)
    assert m.base_parameters == pytest.approx(printed["base_parameters"], rel=1e-12)
    html = (rep / "index.html").read_text()
    for header in ("<th>base parameter</th><th>value</th><th>σ</th><th>unit</th>",
                   "<th>joint</th><th>coulomb</th>",
                   "<th>residual RMS</th>", "condition number"):
        assert header in html, header
    verdict = m.consistency.message()
    assert ("physically consistent" in verdict or "physically inconsistent" in verdict)
    assert verdict.split(";")[0].split("(")[0] in html
    assert html.count("data:image/png;base64,") == 4  # three joints' efforts and the residuals
