"""Long work is estimated before it starts (issue 22, item 13): ``excitation fourier`` on a
1000-joint URDF or with ``--restarts 1000000`` is refused at once with the estimate, the limit and
how to go on; a design estimated above 10 s shows its progress; ``--seed -1`` is a usage error."""

from __future__ import annotations

import math
import time

import pytest
from corpus import assert_user_error

from gripkit.sysid.rigid_body import fourier_trajectory as ft
from gripkit.errors import ConfigError, DataError
from gripkit.sysid import fourier_trajectory
from gripkit.multibody import from_urdf

LINK = ('<link name="l{}"><inertial><origin xyz="0.05 0 0"/><mass value="0.1"/>'
        '<inertia ixx="1e-4" iyy="2e-4" izz="3e-4" ixy="0" ixz="0" iyz="0"/></inertial></link>')
JOINT = ('<joint name="j{0}" type="revolute"><parent link="{1}"/><child link="l{2}"/>'
         '<origin xyz="0.1 0 0" rpy="{3} 0 0"/><axis xyz="0 0 1"/>'
         '<limit lower="-1" upper="1" effort="1" velocity="2"/></joint>')


def _urdf(path, m: int):
    """A serial chain of ``m`` revolute joints, alternate axes turned by 90°."""
    parts = ['<robot name="arm">', '<link name="base"/>']
    parts += [LINK.format(k) for k in range(1, m + 1)]
    parts += [JOINT.format(k, "base" if k == 0 else f"l{k}", k + 1, 1.5708 * (k % 2))
              for k in range(m)]
    path.write_text("".join(parts) + "</robot>")
    return path


def test_seed_minus_one_is_a_usage_error(cli, tmp_path):
    urdf = _urdf(tmp_path / "a.urdf", 2)
    res = cli("excitation", "fourier", urdf, "--seed", -1, "--out", tmp_path / "x.csv")
    assert_user_error(res, "UsageError", "Invalid value for '--seed'")
    res = cli("excitation", "fourier", urdf, "--restarts", -2, "--out", tmp_path / "x.csv")
    assert_user_error(res, "UsageError", "Invalid value for '--restarts'")
    chain = from_urdf(tmp_path / "a.urdf")
    with pytest.raises(DataError, match=r"seed: expected an integer >= 0, found -1; the seed of"):
        fourier_trajectory(chain, seed=-1)
    with pytest.raises(DataError, match=r"restarts: expected an integer >= 0, found 1.5"):
        fourier_trajectory(chain, restarts=1.5)


def test_a_million_restarts_are_refused_at_once(cli, tmp_path):
    t0 = time.perf_counter()
    res = cli("excitation", "fourier", _urdf(tmp_path / "a.urdf", 2), "--restarts", 1000000,
              "--out", tmp_path / "x.csv")
    # 1 000 001 starts × (200 iterations × 22 + 1) evaluations × 400·24² flops ≈ 1e15 flops:
    # at least 2.8 h even at 1e11 flop/s
    assert_user_error(res, "ConfigError",
                      "excitation design of arm (2 joints, 20 coefficients, 1,000,001 starts): "
                      "an estimated 1e+15 floating-point operations take at least 2.82 h")
    assert "above the time limit of 30 min" in res.err and "--time-limit" in res.err
    assert time.perf_counter() - t0 < 30 and not (tmp_path / "x.csv").exists()


def test_a_thousand_joints_are_refused_at_once(cli, tmp_path):
    t0 = time.perf_counter()
    big = _urdf(tmp_path / "big.urdf", 1000)
    res = cli("excitation", "fourier", big, "--out", tmp_path / "x.csv")
    assert_user_error(res, "ConfigError",
                      "excitation design of arm (1000 joints, 10000 coefficients, 1 start): ")
    assert "above the" in res.err  # memory (70 GB) or, on a machine with more, the time limit
    assert time.perf_counter() - t0 < 60


def test_memory_estimate_against_the_limit(tmp_path, monkeypatch):
    """100 joints: the regressor over one period (20 000 rows × 1200 columns) and the base QR
    (50·100 rows × 1000 columns), three copies of 8 bytes: 0.696 GB, above a limit of 0.5 GB."""
    monkeypatch.setattr(ft, "_memory_room", lambda: 5 * 10**8)
    chain = from_urdf(_urdf(tmp_path / "a.urdf", 100))
    with pytest.raises(ConfigError, match=r"needs an estimated 0.696 GB of memory, above the limit "
                                          r"of 0.5 GB \(half the machine's memory\); design a sub"):
        fourier_trajectory(chain)


def test_measured_estimate_against_a_small_limit(tmp_path):
    """2 joints pass the operation count (1e9 flops: 0.01 s at 1e11 flop/s) and are refused on
    the measured time of one evaluation × 4401 evaluations."""
    chain = from_urdf(_urdf(tmp_path / "a.urdf", 2))
    with pytest.raises(ConfigError, match=r"1 start\): up to 4,401 evaluations of .* each "
                                          r"\(measured\) take up to .*, above the time limit "
                                          r"of 50 ms"):
        fourier_trajectory(chain, time_limit=0.05)
    for bad in (0, -1.0, math.nan, "soon"):
        with pytest.raises(DataError, match=r"time_limit \(CLI --time-limit\): expected seconds"):
            fourier_trajectory(chain, time_limit=bad)


def test_long_design_shows_progress(tmp_path, monkeypatch, capsys):
    monkeypatch.setattr(ft, "_SHOW_PROGRESS_S", 0.0)
    monkeypatch.setattr(ft, "_PROGRESS_EVERY_S", 0.0)
    chain = from_urdf(_urdf(tmp_path / "a.urdf", 2))
    quiet = fourier_trajectory(chain, restarts=1, max_iterations=20)
    err = capsys.readouterr().err
    assert "excitation design: up to 882 evaluations of" in err  # 2 × (20 × 22 + 1)
    assert "excitation design: starts: 2/2 (100 %" in err
    assert "excitation design: start 2/2, iteration 1 of at most 20, condition number" in err
    # the estimate and the progress change nothing of the design
    monkeypatch.setattr(ft, "_SHOW_PROGRESS_S", 1e9)
    again = fourier_trajectory(chain, restarts=1, max_iterations=20)
    assert (again.a == quiet.a).all() and again.condition_number == quiet.condition_number
    assert capsys.readouterr().err == ""
