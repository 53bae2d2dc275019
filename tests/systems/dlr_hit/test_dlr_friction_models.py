"""The recovered Appendix G friction tables and the finger's friction (``002_ddea254371185ad3.txt``
ch. 6); the generic friction models: tests/models/test_friction.py."""

import math

import numpy as np
import pytest

from gripkit.sysid.rigid_body.friction import fit_stribeck
from gripkit.systems.dlr_hit.parameters import dlr_hit_table
from gripkit.systems.dlr_hit.parameters import thesis_finger_parameters

DEG = math.pi / 180


def test_appendix_g_tables_recovered():
    """Both tables: breakpoints strictly increasing (checked on load), 121 + 122 = 243 pairs =
    486 extracted numbers; the distal one spans −291.9…271.3 °/s, the base one −242.6…227.0 °/s;
    friction opposes motion (sign of v) everywhere."""
    d, b = dlr_hit_table("distal"), dlr_hit_table("base")
    assert d.velocity.size + b.velocity.size == 243
    assert (d.velocity[0] / DEG, d.velocity[-1] / DEG) == pytest.approx((-291.9, 271.3))
    assert (b.velocity[0] / DEG, b.velocity[-1] / DEG) == pytest.approx((-242.6, 227.0))
    for t in (d, b):
        assert np.all(np.diff(t.velocity) > 0)
        assert np.all(np.sign(t.friction) == np.sign(t.velocity))
    # spot values as printed in Appendix G
    assert d(-291.9 * DEG) == pytest.approx(-0.5855)
    assert b(227.0 * DEG) == pytest.approx(0.7558)


def test_stribeck_defaults_are_the_fits_of_the_tables():
    """The zoo's Stribeck option parameters are fit_stribeck's estimates on Appendix G's tables
    (F_s = 0.36 N·m, v_s = 0.1 rad/s, δ = 2 fixed), within their standard deviations."""
    p = thesis_finger_parameters().value
    for table, name in ((dlr_hit_table("distal"), "distal"), (dlr_hit_table("base"), "base1")):
        fit = fit_stribeck(table.velocity, table.values, fixed=dict(fs=0.36, vs=0.1, delta=2.0))
        assert abs(fit.values["fc"] - p(f"fc_{name}")) < fit.std["fc"]
        assert abs(fit.values["cubic"] - p(f"cubic_{name}")) < fit.std["cubic"]
        assert abs(fit.values["sigma"] - p(f"visc_{name}")) < fit.std["sigma"]
        assert fit.rms < 0.06


def test_harmonic_drive_ripple_in_the_finger():
    """§3.2.2: friction varying sinusoidally with the output position. With ripple_amp = 0.03 N·m
    and 200 periods per revolution, the distal friction of a constant-PWM run deviates from the
    table by 0.03·sin(200·p)·sign(v)."""
    from gripkit.systems.dlr_hit.parameters import finger

    f = finger(check=False, ripple_amp=0.03, g_x=0.0, g_y=-9.81, g_z=0.0)
    tr = f.simulate(np.tile([0.0, 0.0, 3000.0], (300, 1)), dt=1e-3, x0=f.state(q=(0.0, 0.0, 0.1)))
    moving = tr["distal_vel"] > 0
    p = tr["prox"][moving]
    expected = f.tables[2](tr["distal_vel"][moving]) + 0.03 * np.sin(200 * p)
    np.testing.assert_allclose(tr["fric_distal"][moving], expected, atol=1e-12)
