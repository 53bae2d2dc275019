"""``gripkit export c --kind kalman`` (issue 27): the generated steady-state Kalman filter step
``NAME_kf_step``, compiled with ``gcc -std=c99 -O2 -Wall -Wextra -Werror`` and run through the
generated harness on a recorded input and output, gives the filtered states of
``KalmanFilter(model, steady_state=True)`` to 1e-12 relative, with the model's own innovation
gain K and with the gains of given noise covariances Q, R (``--noise``); names from the model
file reach the C code only as safe comments; bad options are refused in one line."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

from gripkit.cli import main
from gripkit.errors import DataError, ModelError
from gripkit.estimation import KalmanFilter
from gripkit.export import kalman_c_harness, kalman_c_sources
from gripkit.export.c_kalman import load_noise
from gripkit.lti import StateSpace
from gripkit.sysid import LinearModel

from test_c_export import FLAGS, GCC, needs_gcc, ss_model

K_INNOV = np.array([[0.3, 0.0], [0.1, 0.2], [0.0, 0.4], [0.2, -0.1]])
LAMBDA = np.array([[0.02, 0.005], [0.005, 0.05]])
Q = np.diag([1e-3, 2e-3, 5e-4, 1e-3])
R = np.array([[0.04, 0.01], [0.01, 0.09]])


def innovation_model() -> LinearModel:
    """The export test's 2×2 order-4 model with offsets, in innovation form (K, Λ)."""
    m = ss_model()
    return LinearModel(m.system, "n4sid", K=K_INNOV, noise_covariance=LAMBDA,
                       u_offset=m.u_offset, y_offset=m.y_offset)


def recorded(m, N=500, seed=27):
    """Inputs around the offsets and the model's outputs with noise (SI)."""
    rng = np.random.default_rng(seed)
    u = np.asarray(m.u_offset) + rng.standard_normal((N, 2))
    y = m.simulate(u - np.asarray(m.u_offset)) + np.asarray(m.y_offset)
    return u, y + 0.05 * rng.standard_normal(y.shape)


def build_and_run(tmp_path, files, name, u, y):
    for fname, text in files.items():
        (tmp_path / fname).write_text(text)
    (tmp_path / "harness.c").write_text(kalman_c_harness(name))
    exe = tmp_path / "harness"
    res = subprocess.run([GCC, *FLAGS, "-o", str(exe), str(tmp_path / "harness.c"),
                          str(tmp_path / f"{name}.c"), "-lm"], capture_output=True, text=True)
    assert res.returncode == 0, res.stderr
    inp = tmp_path / "uy.txt"
    np.savetxt(inp, np.column_stack([u, y]), fmt="%.17g", delimiter=",")
    out = subprocess.run([str(exe), str(inp)], capture_output=True, text=True, check=True).stdout
    return np.loadtxt(out.splitlines(), delimiter=",", ndmin=2)


@needs_gcc
@pytest.mark.parametrize("noise", ["innovation form", "Q, R"])
def test_the_c_filter_gives_the_python_filters_states(tmp_path, noise):
    m = innovation_model()
    u, y = recorded(m)
    kw = {} if noise == "innovation form" else {"Q": Q, "R": R}
    x_c = build_and_run(tmp_path, kalman_c_sources(m, "gkf", **kw), "gkf", u, y)
    x_py = KalmanFilter(m, steady_state=True, **kw).run_arrays(u, y).x
    assert x_c.shape == x_py.shape == (500, 4)
    np.testing.assert_allclose(x_c, x_py, rtol=1e-12, atol=1e-12 * np.max(np.abs(x_py)))
    assert np.max(np.abs(x_py)) > 0.5  # the states do move


@needs_gcc
def test_the_c_filter_carries_no_subnormal_state(tmp_path):
    """A record whose readings go to exact zeros after 200 samples (a sensor at rest, offsets
    removed): x_p decays, and the C filter carries entries below 1e-280 as zero, as the Python
    filter does; after 12 000 samples no state is subnormal and both are the same."""
    m = innovation_model()
    u, y = recorded(m, N=12_000)
    u[200:], y[200:] = np.asarray(m.u_offset), np.asarray(m.y_offset)
    x_c = build_and_run(tmp_path, kalman_c_sources(m, "gkz"), "gkz", u, y)
    x_py = KalmanFilter(m, steady_state=True).run_arrays(u, y).x
    tiny = np.finfo(np.float64).tiny
    assert not np.any((x_c[-1] != 0) & (np.abs(x_c[-1]) < tiny))
    assert np.array_equal(x_c[-1], x_py[-1]) and np.all(np.abs(x_py[-1]) < 1e-270)


@needs_gcc
def test_the_cli_writes_the_filter_with_the_noise_files_covariances(tmp_path, capsys):
    p = tmp_path / "grip.json"
    innovation_model().save(p)
    noise = tmp_path / "noise.json"
    noise.write_text(json.dumps({"Q": Q.tolist(), "R": 0.05}))
    out = tmp_path / "c"
    assert main(["export", "c", str(p), "--kind", "kalman", "--noise", str(noise), "--out",
                 str(out), "--name", "grip_kf", "--json"]) == 0
    res = json.loads(capsys.readouterr().out)
    assert res["kind"] == "kalman" and res["warnings"] == []
    files = {q.name: q.read_text() for q in out.iterdir()}
    assert sorted(files) == ["grip_kf.c", "grip_kf.h"]
    h = files["grip_kf.h"]
    assert "#define GRIP_KF_NX 4" in h and "grip_kf_kf_step(grip_kf_kf_state *s" in h
    assert "Riccati solution of the given Q, R" in h
    m = innovation_model()
    u, y = recorded(m, 200, 3)
    x_c = build_and_run(tmp_path, files, "grip_kf", u, y)
    x_py = KalmanFilter(m, Q=Q, R=0.05 * np.eye(2), steady_state=True).run_arrays(u, y).x
    np.testing.assert_allclose(x_c, x_py, rtol=1e-12, atol=1e-12 * np.max(np.abs(x_py)))


def test_file_strings_reach_the_filter_code_only_as_safe_comments():
    sys = StateSpace([[0.5]], [[1.0]], [[1.0]], dt=0.1, inputs=["a*/ int evil; /*"],
                     outputs=["b??/\nx"])
    m = LinearModel(sys, "n4sid", K=[[0.2]])
    text = "".join(kalman_c_sources(m, "safe").values())
    assert text.count("*/") == text.count("/*") and "??" not in text and "\\" not in text
    assert "u[0]: a__ int evil; __ [-]" in text and "y[0]: b____x [-]" in text


def test_bad_models_and_options_are_refused(tmp_path, capsys):
    with pytest.raises(ModelError, match="no innovation gain K"):
        kalman_c_sources(ss_model(), "grip")  # an output-error model: no K, no Q/R given
    sys = StateSpace(np.zeros((0, 0)), np.zeros((0, 1)), np.zeros((1, 0)), [[2.5]], dt=0.01)
    with pytest.raises(ModelError, match="needs states and inputs"):
        kalman_c_sources(LinearModel(sys, "n4sid"), "gain")
    p = tmp_path / "grip.json"
    innovation_model().save(p)
    bad = tmp_path / "noise.json"
    bad.write_text(json.dumps({"Q": [[1.0]], "R": 0.1}))
    with pytest.raises(DataError, match="Q in .* must be a finite 4×4 matrix"):
        load_noise(bad, 4, 2)
    for args, phrase in (
            (["--noise", str(bad)], "error: DataError: --noise: Q in"),
            (["--kind", "pid"], "error: ConfigError: controller file"),
            (["--float32"], "error: ArgumentError: --float32: the Kalman filter is exported"),
            (["--noise", str(tmp_path / "none.json")], "error: PathError: --noise: cannot read")):
        kind = [] if "--kind" in args else ["--kind", "kalman"]
        assert main(["export", "c", str(p), "--out", str(tmp_path / "o"), *kind, *args]) != 0
        err = capsys.readouterr().err
        assert err.startswith(phrase) and err.count("\n") == 1, err


def with_dropouts(y):
    """``y`` with whole samples missing (10, 200–202) and single outputs (0 on 50–59, 1 at
    100, 0 at 300)."""
    y = y.copy()
    y[10] = y[200:203] = np.nan
    y[50:60, 0] = y[100, 1] = y[300, 0] = np.nan
    return y


@needs_gcc
@pytest.mark.parametrize("noise", ["innovation form", "Q, R"])
def test_the_c_filter_updates_with_the_measured_outputs_as_python_does(tmp_path, noise):
    """NaN dropouts (whole samples and single outputs): the C step uses the Python filter's
    gains of each pattern of missing outputs (none measured: the time update), so its states
    equal KalmanFilter(steady_state=True)'s to 1e-12 and none is NaN (a NaN used to reach
    every later state); a partly measured sample is updated (the next state differs from that
    of the time update)."""
    from gripkit.errors import DataWarning

    m = innovation_model()
    u, y0 = recorded(m)
    y = with_dropouts(y0)
    kw = {} if noise == "innovation form" else {"Q": Q, "R": R}
    files = kalman_c_sources(m, "gkm", **kw)
    assert "KFX[4][4][2]" in files["gkm.c"] and "isnan(y[i])" in files["gkm.c"]
    x_c = build_and_run(tmp_path, files, "gkm", u, y)
    with pytest.warns(DataWarning):
        x_py = KalmanFilter(m, steady_state=True, **kw).run_arrays(u, y).x
    assert not np.isnan(x_c).any()
    np.testing.assert_allclose(x_c, x_py, rtol=1e-12, atol=1e-12 * np.max(np.abs(x_py)))
    y_whole = y.copy()
    y_whole[50] = np.nan  # sample 50 with no output at all instead of one
    with pytest.warns(DataWarning):
        x_time = KalmanFilter(m, steady_state=True, **kw).run_arrays(u, y_whole).x
    assert np.max(np.abs(x_time[51] - x_py[51])) > 1e-3  # via x_p (K_f = 0 in innovation form)


@needs_gcc
def test_more_than_four_outputs_get_the_time_update_on_a_dropout(tmp_path):
    """Five outputs (2^5 patterns: no tables): a sample with any missing output gets the time
    update only in C, which is the Python filter's step on that sample with every output
    missing (to 1e-12); the header says so."""
    from gripkit.errors import DataWarning

    rng = np.random.default_rng(5)
    A = np.array([[0.9, 0.1], [0.0, 0.8]])
    sys = StateSpace(A, [[1.0], [0.5]], rng.standard_normal((5, 2)), np.zeros((5, 1)), dt=0.01)
    m = LinearModel(sys, "n4sid", K=0.1 * rng.standard_normal((2, 5)))
    u = rng.standard_normal((80, 1))
    y = m.simulate(u) + 0.05 * rng.standard_normal((80, 5))
    y[7, 2] = y[30:33] = y[40, 4] = np.nan
    files = kalman_c_sources(m, "g5")
    assert "KFX" not in files["g5.c"] and "time update only" in files["g5.h"]
    x_c = build_and_run(tmp_path, files, "g5", u, y)
    y_all = y.copy()
    y_all[np.isnan(y).any(axis=1)] = np.nan
    with pytest.warns(DataWarning):
        x_py = KalmanFilter(m, steady_state=True).run_arrays(u, y_all).x
    np.testing.assert_allclose(x_c, x_py, rtol=1e-12, atol=1e-12 * np.max(np.abs(x_py)))
    assert np.max(np.abs(x_py)) > 0.1
