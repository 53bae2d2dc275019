"""Friction identification from constant-velocity points (gripkit.sysid.rigid_body.friction):
fit_stribeck recovers the parameters of a synthetic Stribeck curve with a cubic term (eq 6.5 of
``002_ddea254371185ad3.txt`` plus c·v³) within three of its standard deviations, and refuses
data it cannot identify."""

import numpy as np
import pytest

from gripkit.errors import DataError, UnidentifiableError
from gripkit.models.friction import Stribeck
from gripkit.sysid.rigid_body.friction import fit_stribeck


def test_fit_stribeck_recovers_synthetic_parameters_within_3_sigma():
    truth = dict(fc=0.2, fs=0.36, vs=0.3, delta=2.0, sigma=0.04, cubic=0.002)
    rng = np.random.default_rng(4)
    v = np.concatenate([-np.geomspace(0.05, 5, 60), np.geomspace(0.05, 5, 60)])
    s = Stribeck(truth["fc"], truth["fs"], truth["vs"], truth["delta"], truth["sigma"])
    f = s(v) + truth["cubic"] * v ** 3 + rng.normal(0, 0.005, v.size)
    fit = fit_stribeck(v, f, fixed=dict(delta=2.0))
    for k in ("fc", "fs", "vs", "sigma", "cubic"):
        assert abs(fit.values[k] - truth[k]) < 3 * fit.std[k], k
    with pytest.raises(DataError, match="zero velocity"):
        fit_stribeck(np.r_[v, 0.0], np.r_[f, 0.3])
    with pytest.raises(UnidentifiableError):
        # data only far above v_s: the Stribeck part is undetermined
        vv = np.r_[-np.linspace(3, 5, 20), np.linspace(3, 5, 20)]
        fit_stribeck(vv, np.sign(vv) * 0.2 + 0.04 * vv, fixed=dict(cubic=0.0))
