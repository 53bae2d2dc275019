"""Batch identification over a folder of logs: one row per file, failures recorded."""

import sys

import cloudpickle
import numpy as np
import pytest

from gripkit import Trajectory
from gripkit.batch import identify_many
from gripkit.io import save
from gripkit.models import MassSpringDamper
from gripkit.sysid.physical.greybox import fit

cloudpickle.register_pickle_by_value(sys.modules[__name__])

K_TRUE = [100.0, 110.0, 120.0, 130.0, 140.0]  # five "fingers" with different stiffness


def msd_identifier(tr, **options):
    res = fit(MassSpringDamper(m=2e-6, b=1e-3, k=100.0), tr, progress=False)
    return {"params": dict(zip(res.free, res.theta)), "std": dict(zip(res.free, res.std)),
            "fit_percent": float(res.fit_percent[0])}


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    d = tmp_path_factory.mktemp("logs")
    rng = np.random.default_rng(0)
    u = np.where((np.arange(1200) // 300) % 2 == 0, 1e-4, 0.0)
    for i, k in enumerate(K_TRUE):
        y = MassSpringDamper(m=1.8e-6, b=7e-4, k=k).simulate(u, dt=5e-5)["x"]
        y = y + 0.01 * y.std() * rng.standard_normal(y.size)
        save(Trajectory.uniform(dt=5e-05, F=u, x=y, units={"F": "N", "x": "m"}),
             d / f"finger{i}.parquet")
    bad = np.array(y)
    bad[10] = np.nan
    save_bad = d / "finger_broken.csv"
    save_bad.write_text("t,F,x\n" + "\n".join(f"{j / 20000},{u[j]},{bad[j]}" for j in range(1200)))
    return d


@pytest.mark.parametrize("backend", ["in-process", "process"])
def test_one_row_per_file_with_uncertainty(folder, backend):
    table = identify_many(folder, msd_identifier, backend=backend, workers=2, progress=False)
    files = [str(f).rsplit("/", 1)[-1] for f in table["file"]]
    assert files == ["finger0.parquet", "finger1.parquet", "finger2.parquet", "finger3.parquet",
                     "finger4.parquet", "finger_broken.csv"]
    ok = table["error"] == None  # noqa: E711
    assert ok.tolist() == [True] * 5 + [False]
    assert "NaN" in table["error"][5]
    np.testing.assert_allclose(table["k"][:5], K_TRUE, rtol=3e-3)
    assert (np.abs(table["k"][:5] - K_TRUE) < 4 * table["k_std"][:5]).all()
    assert (table["fit_percent"][:5] > 95).all()


def test_no_files(tmp_path):
    with pytest.raises(Exception, match="no data files"):
        identify_many(tmp_path / "*.csv", msd_identifier, backend="in-process", progress=False)
