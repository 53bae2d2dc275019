"""Report figures a reader can scan: labelled axes, enough log ticks, markers and lines that do
not hide each other."""

import pytest

from gripkit.report.plots import bode, log_ticks, pole_zero_map, subplots
from gripkit.sysid import PolynomialModel


def _visible_labels(ax, axis):
    ax.figure.canvas.draw()
    lo, hi = sorted(axis.get_view_interval())
    return ([t for t, v in zip(axis.get_ticklabels(),
                               axis.get_majorticklocs()) if t.get_text() and lo <= v <= hi])


@pytest.mark.parametrize("span", [(3.0, 20.0), (0.2, 100.0), (1e-3, 1e5)])
def test_log_ticks_label_at_least_three_ticks(span):
    fig, ax = subplots()
    ax.loglog(span, span)
    log_ticks(ax)
    assert len(_visible_labels(ax, ax.xaxis)) >= 3
    assert len(_visible_labels(ax, ax.yaxis)) >= 3


def _model(a1, a2, b2):
    return (PolynomialModel.from_coefficients([1.0, a1, a2], [0.0, 0.0, b2, -0.8 * b2], nk=2,
                                              dt=0.005))


def test_bode_draws_the_reference_under_the_estimates_and_labels_log_ticks():
    fig = bode({"true plant": _model(-1.87, 0.90, 5.0), "estimate": _model(-1.87, 0.90, 5.0),
                "other": _model(-1.5, 0.6, 4.0)}, reference="true plant")
    am, ap = fig.axes
    lines = {ln.get_label(): ln for ln in am.get_lines()}
    ref, est, other = lines["true plant"], lines["estimate"], lines["other"]
    assert ref.get_zorder() < est.get_zorder() and ref.get_linewidth() > 2 * est.get_linewidth()
    assert est.get_linestyle() != other.get_linestyle() and est.get_color() != other.get_color()
    assert len(_visible_labels(ap, ap.xaxis)) >= 3
    assert am.get_ylabel() and ap.get_ylabel() and ap.get_xlabel()


def test_pole_zero_map_gives_each_model_its_own_marker_and_size():
    p, z = [0.9 + 0.1j, 0.9 - 0.1j], [1.17]
    fig = pole_zero_map({"a": (p, z), "b": (p, z), "c": (p, z)})
    ax = fig.axes[0]
    # not the unit circle
    shown = [ln for ln in ax.get_lines() if not ln.get_label().startswith("_")]
    marks = [(ln.get_marker(), ln.get_markersize()) for ln in shown]
    assert len(marks) == 6 and len(set(marks)) == 6
    poles = [m for ln, m in zip(shown, marks) if ln.get_label().endswith("poles")]
    assert len({m[0] for m in poles}) == 3 and len({m[1] for m in poles}) == 3
    assert ax.get_xlabel() and ax.get_ylabel()
