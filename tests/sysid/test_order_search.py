"""The state-space order search (identify 'ss' with order='LO:HI'): it widens past the edge of
its range when the best order sits there, it ranks the refined models it returns by the focus
criterion, and PEM shows its progress on stderr when asked (and only then)."""

import warnings

import numpy as np
import pytest
from scipy import signal

from gripkit import Trajectory
from gripkit.errors import GripkitWarning
from gripkit.progress import track
from gripkit.sysid import identify
from gripkit.sysid.linear import identify_mimo

# a 4th-order system: two modes, |z| = 0.95 at 0.3 rad/sample and |z| = 0.8 at 1.2 rad/sample
POLES = [0.95 * np.exp(1j * 0.3), 0.95 * np.exp(-1j * 0.3), 0.8 * np.exp(1j * 1.2),
         0.8 * np.exp(-1j * 1.2)]
DEN = np.real(np.poly(POLES))


def _record(seed: int, n: int = 3000) -> Trajectory:
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = signal.lfilter([0, 0.5, 0.3, -0.2, 0.1], DEN, u) + 0.01 * rng.standard_normal(n)
    return Trajectory.uniform(dt=0.01, u=u, y=y)


@pytest.mark.parametrize("validate", [False, True])
def test_search_widens_past_the_edge_to_the_true_order(validate):
    """Range 1:3 for a 4th-order system: the best order sits on the edge 3, so the search goes on
    to 4 and 5 (WIDEN_STEPS at most) and returns order 4, with no edge warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", GripkitWarning)
        m = identify(_record(1), "ss", input="u", output="y", order="1:3", refine=False,
                     validate=_record(2) if validate else None)
    assert m.order == 4
    orders = sorted(r["order"] for r in m.info["search"])
    assert orders == [1, 2, 3, 4, 5] and "(1:3 widened)" in m.info["order_selection"]
    poles = sorted(np.abs(m.system.poles()))
    assert poles == pytest.approx([0.8, 0.8, 0.95, 0.95], abs=0.01)


def test_search_still_on_the_edge_after_widening_says_so(monkeypatch):
    monkeypatch.setattr(identify_mimo, "WIDEN_STEPS", 0)
    with pytest.warns(GripkitWarning, match=r"order search: the best order 3 lies on the edge of "
                                            r"the searched range 1:3"):
        identify(_record(1), "ss", input="u", output="y", order="1:3", refine=False)


def test_search_ranks_the_refined_models_by_the_focus():
    """The best REFINE_TOP orders are refined; the returned model is the first row, and its
    refined simulation fit on the validation record is the best of the refined rows."""
    m = identify(_record(3), "ss", input="u", output="y", order="3:5", validate=_record(4))
    rows = m.info["search"]
    refined = [r for r in rows if "refined_percent" in r]
    assert len(refined) == identify_mimo.REFINE_TOP and rows[:3] == refined
    assert rows[0]["order"] == m.order == 4
    best = max(r["refined_percent"] for r in refined)
    assert rows[0]["refined_percent"] >= best - identify_mimo.FOCUS_TIE
    assert m.structure.startswith("pem-") and rows[0]["refined_percent"] > 99.0


def test_pem_progress_on_stderr_only_when_asked(capsys):
    from gripkit.sysid.linear.pem_ss import pem

    start = identify(_record(5), "ss", input="u", output="y", order=4, refine=False)
    tr = _record(5)
    u = (tr["u"] - start.u_offset[0])[:, None]
    y = (tr["y"] - start.y_offset[0])[:, None]
    quiet = pem(start, u=u, y=y, max_iterations=10)
    assert capsys.readouterr().err == ""
    loud = pem(start, u=u, y=y, max_iterations=10, progress=True)
    err = capsys.readouterr().err
    it = loud.info["pem"]["iterations"]
    # without a terminal: a line per 10 % of max_iterations (iterations 1, 2, ... as they
    # finish; the one that stops the loop is told by the closing line)
    bar = [line.strip() for line in err.splitlines() if line.startswith("  PEM")]
    assert bar[0].startswith("PEM (innovation form): 1/10 (10 %") and 1 <= len(bar) < it
    assert bar == [f"PEM (innovation form): {i}/10 ({10 * i} %" + b.split("%", 1)[1]
                   for i, b in enumerate(bar, 1)]
    assert f"PEM (innovation form): converged after {it} iteration(s) of at most 10" in err
    np.testing.assert_array_equal(quiet.system.A, loud.system.A)  # progress changes nothing


def test_progress_api_without_a_terminal(capsys):
    """gripkit.progress.track on a non-TTY stderr: one line per 10 %, with the count."""
    assert list(track(range(20), description="work")) == list(range(20))
    lines = capsys.readouterr().err.splitlines()
    assert len(lines) == 10 and lines[0].strip().startswith("work: 2/20 (10 %")
    assert list(track(range(5), description="quiet", enabled=False)) == list(range(5))
    assert capsys.readouterr().err == ""


def test_armax_and_oe_pem_progress_when_asked(capsys):
    """The polynomial PEM (ARMAX, OE) shows its iterations on stderr with progress=True, and the
    result is the same as without."""
    from gripkit.sysid import armax, oe

    rng = np.random.default_rng(6)
    u = rng.standard_normal(2000)
    e = 0.1 * rng.standard_normal(2000)
    y = signal.lfilter([0, 0.4], [1, -0.7], u) + signal.lfilter([1, 0.5], [1, -0.7], e)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # 5 iterations may stop short of convergence
        quiet = armax(u, y, 1, 1, 1, 1, maxiter=5)
        assert capsys.readouterr().err == ""
        loud = armax(u, y, 1, 1, 1, 1, maxiter=5, progress=True)
        oe(u, y, 1, 1, 1, maxiter=5, progress=True)
    err = capsys.readouterr().err
    assert "PEM ARMAX [1 1 1 1]: 1/5 (20 %" in err and "PEM OE [1 1 1]: 1/5 (20 %" in err
    np.testing.assert_array_equal(quiet.theta, loud.theta)
    # the model: a1 = −0.7, b1 = 0.4, c1 = 0.5 within 4σ
    assert np.all(np.abs(loud.theta - [-0.7, 0.4, 0.5]) < 4 * loud.theta_std)


def test_arx_structure_search_widens_past_the_edge():
    """identify 'search' over na 1:3 for an ARX system with na = 4 (the 4th-order A above, nb = 2,
    nk = 1): the best na sits on the edge 3, the range grows to 4 and 5, and the search returns
    [4 2 1] without an edge warning; one warning says that the search went past the asked
    range, and how far."""
    rng = np.random.default_rng(7)
    u = rng.standard_normal(4000)
    y = signal.lfilter([0, 0.5, 0.3], DEN, u) + signal.lfilter([1.0], DEN,
                                                                0.05 * rng.standard_normal(4000))
    tr = Trajectory.uniform(dt=0.01, u=u, y=y)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        res = identify(tr, "search", input="u", output="y", na="1:3", nb="1:3", nk="1:2",
                       progress=False)
    said = [str(w.message) for w in caught if issubclass(w.category, GripkitWarning)]
    assert said == ["structure search: the best structure sat on the edge of the asked ranges, "
                    "so the search went past it: na to 1:5 (asked 1:3)"]
    best = res.best
    assert (best.na, best.nb, best.nk) == (4, 2, 1)
    assert sorted({c.na for c in res.candidates}) == [1, 2, 3, 4, 5]


def test_arx_structure_search_says_when_the_data_cannot_tell_the_delay_apart():
    """One sine drives the input: u(t − k) for any k is a combination of u(t − 1) and u(t − 2),
    so [na 2 nk] fits the same for every nk. The search says so (AccuracyWarning) and names the
    tied delays; a white-noise input gives no such warning."""
    from gripkit.errors import AccuracyWarning

    n = 2000
    t = np.arange(n) * 0.01
    u = np.sin(2 * np.pi * 1.3 * t)
    noise = 1e-3 * np.random.default_rng(2).standard_normal(n)
    y = signal.lfilter([0, 0.5, 0.3], [1.0, -0.9], u) + noise
    tr = Trajectory.uniform(dt=0.01, u=u, y=y)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        identify(tr, "search", input="u", output="y", na="1:2", nb="2", nk="1:3", progress=False)
    ties = [str(w.message) for w in caught if issubclass(w.category, AccuracyWarning)
            and "cannot tell the delay apart" in str(w.message)]
    assert len(ties) == 1 and "nk = 1, 2, 3" in ties[0]
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        identify(_record(4), "search", input="u", output="y", na="1:2", nb="2", nk="1:3",
                 progress=False)
    assert not [w for w in caught if "cannot tell the delay apart" in str(w.message)]
