"""State-space defaults that never lose (issue 25): identify_ss returns the PEM model only when it
scores at least as well as its subspace start by the ``focus`` criterion (free-run fit by
default, one-step fit with ``focus='prediction'``), says when PEM did not converge, and the
command line prints the order-search table."""

import warnings

import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.cli import main
from gripkit.errors import AccuracyWarning, DataError
from gripkit.sysid.linear import identify_mimo
from gripkit.sysid.linear.identify_mimo import focus_score, identify_ss, mimo_data


def _record(seed, n=3000):
    """A second-order plant (poles 0.9 ± 0.2j) with coloured output noise."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = np.zeros(n)
    for t in range(2, n):
        y[t] = 1.8 * y[t - 1] - 0.85 * y[t - 2] + 0.3 * u[t - 1] + 0.1 * u[t - 2]
    v = np.convolve(rng.standard_normal(n), [1.0, 0.7], "same") * 0.05
    return Trajectory.uniform(dt=0.01, u=u, y=y + v)


def test_a_refinement_that_scores_lower_is_not_returned(monkeypatch):
    """PEM replaced by a step that damages the model: the subspace model comes back, with a
    warning giving both free-run fits."""
    tr = _record(0)

    def bad_pem(model, u=None, y=None, form="innovation", max_iterations=50,  # both forms
                progress=False):
        ss = model.system
        worse = model.replace(system=ss.replace(A=0.9 * ss.A), structure=f"pem-{form}",
                              info={**model.info, "pem": {"converged": True}})
        return worse

    import gripkit.sysid.linear.pem_ss as pem_ss

    monkeypatch.setattr(pem_ss, "pem", bad_pem)
    with pytest.warns(AccuracyWarning, match="lowered the mean simulation fit on the "
                                             "estimation data"):
        model, _ = identify_ss(tr, input="u", output="y", order=2)
    assert model.structure == "n4sid" and model.info["covariance"]["replicates"] == 100
    fo = model.info["focus"]
    assert fo["kept"] == "subspace" and fo["subspace_percent"] > fo["refined_percent"]
    d = mimo_data(tr, "u", "y")
    assert focus_score(model, "simulation", d) == pytest.approx(fo["subspace_percent"], rel=1e-12)


@pytest.mark.parametrize("focus", ["simulation", "prediction"])
def test_the_returned_model_never_scores_below_its_start(focus):
    tr, val = _record(1), _record(2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", AccuracyWarning)
        model, _ = identify_ss(tr, input="u", output="y", order=2, focus=focus, validate=val)
        start, _ = identify_ss(tr, input="u", output="y", order=2, refine=False, validate=val)
    vd = identify_mimo.validation_data(val, mimo_data(tr, "u", "y"))
    assert focus_score(model, focus, vd) >= focus_score(start, focus, vd) - identify_mimo.FOCUS_TIE
    assert model.info["focus"]["data"] == "validation"
    assert np.allclose(sorted(np.abs(model.system.poles())), [np.hypot(0.9, 0.2)] * 2, atol=0.01)


def test_pem_that_does_not_converge_says_so():
    with pytest.warns(AccuracyWarning, match=r"PEM refinement \(pem-innovation\) stopped after 1 "
                                             r"iterations without converging"):
        identify_ss(_record(3), input="u", output="y", order=4, max_iterations=1)
    with pytest.raises(DataError, match="focus: expected one of simulation, prediction"):
        identify_ss(_record(3), input="u", output="y", order=2, focus="both")


def test_the_search_table_is_in_the_text_output(tmp_path, capsys):
    from gripkit.io import save

    save(_record(4), tmp_path / "est.csv")
    save(_record(5), tmp_path / "val.csv")
    code = main(["identify", "ss", str(tmp_path / "est.csv"), "--input", "u", "--output", "y",
                 "--order", "1:4", "--validate", str(tmp_path / "val.csv")])
    out = capsys.readouterr()
    assert code == 0, out.err
    assert "order search, subspace models ranked by validation_fit; the best refined by PEM " \
        "and ranked first by their simulation fit (refined %)" in out.out
    rows = ([ln.split() for ln in out.out.splitlines() if ln.strip()[:1].isdigit()
             and len(ln.split()) >= 3])
    assert sorted(int(r[0]) for r in rows[:4]) == [1, 2, 3, 4]
    assert "focus simulation (validation data)" in out.out


def test_an_innovation_refinement_that_loses_falls_back_to_output_error(monkeypatch):
    """With focus='simulation', PEM in output-error form (which minimises the free-run error
    itself) is tried when the innovation form loses; it is returned, with its covariance."""
    import gripkit.sysid.linear.pem_ss as pem_ss

    real = pem_ss.pem

    def pem(model, u=None, y=None, form="innovation", max_iterations=50, progress=False):
        m = real(model, u=u, y=y, form=form, max_iterations=max_iterations)
        if form == "innovation":  # damaged: scores lower than the subspace start
            m = m.replace(system=m.system.replace(A=0.9 * m.system.A))
        return m

    monkeypatch.setattr(pem_ss, "pem", pem)
    with pytest.warns(AccuracyWarning, match=r"the pem-oe refinement \(.*\) is returned"):
        model, _ = identify_ss(_record(6), input="u", output="y", order=2)
    assert model.structure == "pem-oe" and model.info["focus"]["kept"] == "pem-oe"
    assert model.system.uncertainty is not None


def test_pem_on_an_order_the_data_do_not_support_returns_the_subspace_model():
    """A periodic band-limited record (the CLI tests' multisine) and the default order (9 here,
    for a second-order plant): JᵀJ at PEM's optimum is so ill-conditioned that its computed
    inverse is indefinite (an eigenvalue of −2e4), which used to stop identify ss with a
    ModelError about the covariance. Now PEM reports the undetermined directions and the
    subspace model comes back with a warning saying why. Its bootstrap σ fails as well (the
    replicates' data support at most 6 states, or their 9 states do not map onto the model's):
    after 10 failed replicates it stops, and the model comes without covariance, with a
    warning saying so."""
    from gripkit.excitation import periodic_multisine
    from gripkit.lti import TransferFunction

    ex = periodic_multisine(0.05, 5.0, 400, 5, dt=0.05, amplitude=1.0)
    y = TransferFunction([2.0, 4.0], [1.0, 0.8, 4.0]).c2d(0.05).simulate(ex.u)[:, 0]
    y = y + 0.01 * np.random.default_rng(0).standard_normal(y.size)
    tr = Trajectory.uniform(dt=0.05, v=ex.u, x=y)
    with pytest.warns(AccuracyWarning, match="PEM refinement of the order-9 n4sid model failed .*"
                                             "the data do not determine the model") as caught:
        model, _ = identify_ss(tr, input="v", output="x")
    assert model.structure == "n4sid"
    assert any(str(w.message).startswith("bootstrap σ of the n4sid (order 9, horizon 22) model: "
                                         "10 of the 10 replicates tried (of 100) could not be "
                                         "refitted") for w in caught)
    assert model.system.uncertainty is None and "covariance" not in model.info
