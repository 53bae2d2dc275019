"""The command line's messages in the user's terms (an audit of its output): a constant column
named with its value and unit, parameter names that the model has, significance statements that
match their numbers, export hints that name the model family and the CLI's option, units in the
printed summaries. Each case builds a small synthetic record in tmp_path."""

import json
import re

import numpy as np
import pytest

from gripkit.cli import main


def run(capsys, *args):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def _record(path, u, y, dt=0.01, header="time [s],current [A],force [N]", delimiter=","):
    t = np.arange(len(u)) * dt
    np.savetxt(path, np.column_stack([t, u, y]), delimiter=delimiter, header=header, comments="")
    return path


def _arx_data(n=400, seed=0):
    """y(t) = 1.5 y(t-1) - 0.7 y(t-2) + 0.5 u(t-1) + 0.3 u(t-2) + e: an ARX [2 2 1] plant."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal(n)
    y = np.zeros(n)
    for k in range(2, n):
        y[k] = 1.5 * y[k - 1] - 0.7 * y[k - 2] + 0.5 * u[k - 1] + 0.3 * u[k - 2]
    return u, y + 0.01 * rng.standard_normal(n)


@pytest.mark.parametrize("method", ["arx", "armax", "oe", "rls", "narx", "hw", "ss", "frf",
                                    "tf"])
def test_constant_input_is_named_with_its_value_and_unit(capsys, tmp_path, method):
    """current = 1 A throughout: the message names the column and gives 1 A (the mean that
    detrending takes off added back), not 'input u ... 0'; ss, frf and tf (whose data are checked
    before detrending) give the same message."""
    _, y = _arx_data()
    path = _record(tmp_path / "const.csv", np.ones(400), y)
    orders = ["--poles", "2", "--zeros", "0"] if method == "tf" else []
    code, out, err = run(capsys, "identify", method, path, "--input", "current",
                         "--output", "force", *orders)
    assert code != 0 and out == ""
    assert "error: UnidentifiableError: input column 'current' is constant (1 A for all 400 " \
           "samples)" in err


def test_constant_output_is_named_with_its_value_and_unit(capsys, tmp_path):
    u, _ = _arx_data()
    path = _record(tmp_path / "const.csv", u, np.full(400, -2.5))
    code, _, err = run(capsys, "identify", "arx", path, "--input", "current", "--output", "force")
    assert code != 0
    assert "output column 'force' is constant (-2.5 N for all 400 samples)" in err


def _two_sines(n=2000, dt=0.01):
    """A sum of two sines: persistently exciting of order 4 only (Ljung 1999, §13.2)."""
    t = np.arange(n) * dt
    return np.sin(2 * np.pi * 1.3 * t) + 0.5 * np.sin(2 * np.pi * 3.1 * t)


@pytest.mark.parametrize("method,orders,label", [
    ("armax", ("--na", 6, "--nb", 6), "ARMAX [6 6 1 1]"),
    ("oe", ("--nf", 6, "--nb", 6), "OE [6 6 1]")])
def test_poor_excitation_names_the_model_not_its_start(capsys, tmp_path, method, orders, label):
    """Two sines cannot determine 6 B coefficients: the message names the model's structure and
    the input column, not parameters of the internal start fit (ARMAX's long ARX has b1 … b39)."""
    u = _two_sines()
    y = np.convolve(u, [0.0, 0.5, 0.3])[:u.size] + 0.01 * np.random.default_rng(1).standard_normal(
        u.size)
    path = _record(tmp_path / "sines.csv", u, y)
    code, _, err = run(capsys, "identify", method, path, "--input", "current", "--output", "force",
                       *orders)
    assert code != 0
    assert f"UnidentifiableError: {label} (6 B coefficients): input column 'current' is not " \
           f"persistently exciting of order 6" in err
    assert "b39" not in err and "b7" not in err


def test_armax_start_failure_names_the_model_and_the_stage(capsys, tmp_path):
    """One sine excites order 2: ARMAX [2 2 1 1] passes the order check but its Hannan-Rissanen
    start (a long ARX [15 15 1]) is not determined; the message says so, in the model's terms."""
    t = np.arange(2000) * 0.01
    u = np.sin(2 * np.pi * 1.3 * t)
    y = np.convolve(u, [0.0, 0.5, 0.3])[:u.size] + 0.01 * np.random.default_rng(2).standard_normal(
        u.size)
    path = _record(tmp_path / "sine.csv", u, y)
    code, _, err = run(capsys, "identify", "armax", path, "--input", "current", "--output",
                       "force")
    assert code != 0
    assert "ARMAX [2 2 1 1]: the data do not determine the start values: the long ARX " \
           "[15 15 1]" in err
    assert "b15" not in err


def test_growing_oscillation_is_called_growing_not_undamped(capsys, tmp_path):
    """x = e^{+σt} cos(2π·10 t), ζ = -0.005, over 1 s: the envelope ends at e^{0.005·2π·10} =
    136.9 % of its start. ζ lies far below 0 (by many σ): the message says that it grows and is
    negative, not that it 'does not differ from 0'."""
    t = np.arange(0.0, 1.0, 1e-3)
    zeta, wn = -0.005, 2 * np.pi * 10
    x = np.exp(-zeta * wn * t) * np.cos(wn * np.sqrt(1 - zeta**2) * t)
    x += 1e-4 * np.random.default_rng(3).standard_normal(t.size)
    path = tmp_path / "grow.csv"
    np.savetxt(path, np.column_stack([t, x]), delimiter=",", header="time [s],position [um]",
               comments="")
    code, _, err = run(capsys, "identify", "modal", path, "--signal", "position")
    assert code != 0
    m = re.search(r"IdentificationError: free vibration: the envelope grows \(to ([\d.]+) % of its "
                  r"start\): the fitted damping ratio ζ = (-[\d.e-]+) ± ([\d.e+-]+) ", err)
    assert m, err
    assert float(m[1]) == pytest.approx(136.9, abs=0.5)
    assert float(m[2]) == pytest.approx(zeta, rel=0.01) and float(m[3]) < 0.01 * abs(zeta)
    assert "is negative" in err and "does not differ" not in err


@pytest.mark.parametrize("method,family", [
    ("arx", "the ARX model carries no innovation gain K"),
    ("oe", "the OE model has no noise model (an output-error model")])
def test_kalman_export_without_k_names_the_family_and_the_noise_option(capsys, tmp_path, method,
                                                                       family):
    """An ARX is no output-error model: the message names the family, the sizes of Q and R
    (the [2 2 1] model has 2 states, 1 output) and the CLI's option --noise, not the Python call."""
    u, y = _arx_data()
    data = _record(tmp_path / "d.csv", u, y)
    model = tmp_path / f"{method}.json"
    assert run(capsys, "identify", method, data, "--input", "current", "--output", "force",
               "--out", model)[0] == 0
    code, _, err = run(capsys, "export", "c", model, "--kind", "kalman", "--out", tmp_path / "c")
    assert code != 0
    assert f"error: ModelError: export c --kind kalman: {family}" in err
    assert "noise covariances Q (2×2) and R (1×1); give them in a JSON file: --noise" in err
    assert "KalmanFilter(" not in err


def _two_channel_record(path):
    u, y = _arx_data()
    rng = np.random.default_rng(5)
    t = np.arange(u.size) * 0.01
    np.savetxt(path, np.column_stack([t, u, rng.standard_normal(u.size), y, y + 0.1 * u]),
               delimiter=",", header="time [s],current [A],voltage [V],force [N],force2 [N]",
               comments="")
    return path


@pytest.mark.parametrize("method,ins,outs,found", [
    ("oe", "current,voltage", "force", "2 input(s) 'current', 'voltage' and 1 output(s) 'force'"),
    ("narx", "current,voltage", "force", "2 input(s) 'current', 'voltage'"),
    ("armax", "current", "force,force2", "1 input(s) 'current' and 2 output(s) 'force', 'force2'"),
    ("hysteresis", "current", "force,force2", "2 output(s) 'force', 'force2'")])
def test_single_channel_family_given_two_columns(capsys, tmp_path, method, ins, outs, found):
    """A family of one input and one output says so, with the columns given (not the internal
    'IOData.u1: the SISO view', not "no column 'force,force2'")."""
    path = _two_channel_record(tmp_path / "two.csv")
    code, _, err = run(capsys, "identify", method, path, "--input", ins, "--output", outs)
    assert code != 0
    assert f"error: ArgumentError: identify {method}: this family takes one input and one " \
           f"output column, found" in err and found in err
    assert "the families that take several: ss, frf, tf, arx, nlss" in err
    assert "SISO view" not in err and "no column" not in err


def _good(path, n=300):
    u, y = _arx_data(n)
    return _record(path, u, y)


def test_nan_in_a_second_record_or_the_validation_file_names_that_file(capsys, tmp_path):
    good = _good(tmp_path / "good.csv")
    u, y = _arx_data(300, seed=1)
    y[50] = np.nan
    bad = _record(tmp_path / "second.csv", u, y)
    expected = "error: DataError: second.csv: column 'force' has 1 NaN values (first at t=0.5 s)"
    for args in ((good, bad), (good, "--validate", bad)):
        code, _, err = run(capsys, "identify", "arx", *args, "--input", "current",
                           "--output", "force")
        assert code != 0 and expected in err, err


def test_text_cell_is_located_by_the_file_line_counting_the_header_and_comments(capsys, tmp_path):
    """Data row 50 (0-based) lies on line 53: the header is line 1 and a comment line (skipped
    by the reader) comes before it."""
    lines = ["# logged by a test", "time [s],current [A],force [N]"]
    lines += [f"{0.01 * k:.2f},1.0,{'abc' if k == 50 else k}" for k in range(100)]
    path = tmp_path / "text.csv"
    path.write_text("\n".join(lines) + "\n")
    code, _, err = run(capsys, "identify", "arx", path, "--input", "current", "--output", "force")
    assert code != 0
    assert "column 'force' mixes numbers and text: line 53 of text.csv holds 'abc'" in err


def test_undecodable_byte_is_named_at_its_offset_in_the_file(capsys, tmp_path):
    """A Latin-1 'µ' (byte 0xb5) at offset 31 of the file (the end of the header line), which the
    decoder's own message put at offset 10 (its place in the field 'force [N] µ')."""
    path = tmp_path / "latin1.csv"
    path.write_bytes(b"time [s],current [A],force [N] \xb5\n0.0,1.0,2.0\n0.01,2.0,3.0\n")
    code, _, err = run(capsys, "identify", "arx", path, "--input", "current", "--output", "force")
    assert code != 0
    assert "error: DataError: latin1.csv: not UTF-8 text: byte 0xb5 at offset 31 (line 1)" in err


def test_tab_separated_file_named_csv_is_read(capsys, tmp_path):
    """A tab-separated file named .csv reads as a TSV: the same model as the comma file."""
    u, y = _arx_data()
    tab = _record(tmp_path / "tab.csv", u, y, header="time [s]\tcurrent [A]\tforce [N]",
                  delimiter="\t")
    comma = _record(tmp_path / "comma.csv", u, y)
    fits = []
    for path in (tab, comma):
        code, out, err = run(capsys, "identify", "arx", path, "--input", "current", "--output",
                             "force", "--json")
        assert code == 0, err
        fits.append(json.loads(out)["theta"])
    assert fits[0] == fits[1]
    assert fits[0] == pytest.approx([-1.5, 0.7, 0.5, 0.3], abs=0.01)  # _arx_data's plant


@pytest.mark.parametrize("body,phrase", [
    ('<link name="base"/><link name="l1"><inertial><mass value="abc"/></inertial></link>'
     '<joint name="j" type="revolute"><parent link="base"/><child link="l1"/>'
     '<axis xyz="0 0 1"/></joint>', "link 'l1' <mass>: value='abc' is not a number"),
    ('<link name="base"', "the URDF is not well-formed XML")])
def test_bad_urdf_names_the_file(capsys, tmp_path, body, phrase):
    urdf = tmp_path / "finger.urdf"
    urdf.write_text(f'<robot name="x">{body}</robot>' if body.endswith(">") else
                    f'<robot name="x">{body}')
    u, y = _arx_data(100)
    log = tmp_path / "log.csv"
    np.savetxt(log, np.column_stack([np.arange(100) * 0.01, u, y]), delimiter=",",
               header="time [s],pos0 [rad],tau0 [N*m]", comments="")
    code, _, err = run(capsys, "identify", "dynamics", urdf, log, "--position", "pos0",
                       "--effort", "tau0")
    assert code != 0
    assert f"error: ModelError: URDF file 'finger.urdf': {phrase}" in err


def _friction_log(path, J=2e-3, Fv=0.01, Fc=0.02, n=4000, dt=1e-3):
    """q = 0.5 sin(2π·1.5 t) + 0.3 sin(2π·4 t) rad driven by τ = J q̈ + Fv q̇ + Fc sign(q̇)."""
    t = np.arange(n) * dt
    w1, w2 = 2 * np.pi * 1.5, 2 * np.pi * 4.0
    q = 0.5 * np.sin(w1 * t) + 0.3 * np.sin(w2 * t)
    qd = 0.5 * w1 * np.cos(w1 * t) + 0.3 * w2 * np.cos(w2 * t)
    qdd = -0.5 * w1**2 * np.sin(w1 * t) - 0.3 * w2**2 * np.sin(w2 * t)
    tau = J * qdd + Fv * qd + Fc * np.sign(qd)
    np.savetxt(path, np.column_stack([t, q, tau]), delimiter=",",
               header="time [s],q [rad],tau [N*m]", comments="")
    return path


@pytest.mark.parametrize("scale", ["-1", "0"])
def test_non_positive_effort_scale_is_refused(capsys, tmp_path, scale):
    """-1 printed units '(-1 N*s^2)/m' and a negative inertia, with no warning: refused now."""
    path = _friction_log(tmp_path / "f.csv")
    code, out, err = run(capsys, "identify", "friction", path, "--position", "q", "--effort",
                         "tau", "--effort-scale", scale)
    assert code != 0 and out == ""
    assert f"error: DataError: --effort-scale: expected a finite positive factor, found " \
           f"{float(scale)!r}" in err
    assert "negate that column in the file" in err


@pytest.mark.parametrize("method", ["arx", "armax", "oe", "rls"])
def test_parameter_table_and_loss_carry_units(capsys, tmp_path, method):
    """current [A] → force [N]: the b coefficients in N/A, a, c, f dimensionless ('1'), the loss
    V_N and the FPE (mean squared errors of the output) in N^2 (RLS: no FPE)."""
    u, y = _arx_data()
    path = _record(tmp_path / "d.csv", u, y)
    code, out, err = run(capsys, "identify", method, path, "--input", "current", "--output",
                         "force")
    assert code == 0, err
    rows = {cells[0]: cells for cells in
            ([c.strip() for c in line.split("│")[1:-1]] for line in out.splitlines()
             if line.startswith("│"))}
    assert rows["b1"][3] == "N/A" and rows["b2"][3] == "N/A"
    other = "a1" if method != "oe" else "f1"
    assert rows[other][3] == "1"
    if method == "rls":
        assert re.search(r"loss V_N of the a-priori errors \(eq 29\) = [\d.e-]+ N\^2$", out,
                         re.M), out
        return
    assert re.search(r"loss V_N \(eq 29\) = [\d.e-]+ N\^2 .*FPE = [\d.e-]+ N\^2", out, re.S), out


def test_transfer_function_coefficients_carry_units(capsys, tmp_path):
    """G(s) = (n1 s + n0)/(s² + d1 s + d0) from current [A] to force [N]: n1 in N/(A*s), n0 in
    N/(A*s^2), d1 in 1/s, d0 in 1/s^2, the monic 1 without a unit."""
    u, y = _arx_data()
    path = _record(tmp_path / "d.csv", u, y)
    code, out, err = run(capsys, "identify", "tf", path, "--input", "current", "--output",
                         "force", "--poles", 2, "--zeros", 1)
    assert code == 0, err
    assert re.search(r"num: [\d.e+-]+±[\d.e+-]+ N/\(A\*s\), [\d.e+-]+±[\d.e+-]+ N/\(A\*s\^2\)$",
                     out, re.M), out
    assert re.search(r"den: 1±0, [\d.e+-]+±[\d.e+-]+ 1/s, [\d.e+-]+±[\d.e+-]+ 1/s\^2$", out,
                     re.M), out


def test_rls_without_sigma_says_why(capsys, tmp_path):
    """λ = 0.5 keeps 1/(1 − λ) = 2 effective samples, fewer than the 4 parameters of ARX [2 2 1]:
    σ̂² = V/(w₁ − p) is undefined; the summary and the JSON say so, and that λ > 1 − 1/4 = 0.75
    gives σ (λ = 0.8: 5 effective samples, σ shown)."""
    u, y = _arx_data()
    path = _record(tmp_path / "d.csv", u, y)
    args = ("identify", "rls", path, "--input", "current", "--output", "force", "--forgetting")
    code, out, err = run(capsys, *args, 0.5)
    assert code == 0, err
    assert "σ —: the forgetting factor λ = 0.5 keeps about 2 effective samples" in \
        " ".join(out.split())
    assert "choose --forgetting above 0.75 for σ" in " ".join(out.split())
    code, out, _ = run(capsys, *args, 0.5, "--json")
    d = json.loads(out)
    assert d["theta_std_final"] is None and "not more than the 4 parameters" in d["theta_std_note"]
    code, out, _ = run(capsys, *args, 0.8, "--json")
    d = json.loads(out)
    assert len(d["theta_std_final"]) == 4 and "theta_std_note" not in d
