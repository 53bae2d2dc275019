"""Issue 11 §2 items 12-15 ("Everywhere"): every CLI command and the Python entry points answer bad
input with one clear line naming the argument and what is accepted, never "unexpected …".

* 12: usage mistakes (unknown option, a value that is not a number, a missing option), junk and
  non-UTF-8 TOML files, folders and files where the other is expected, permission and other OS
  errors, bad numbers in model descriptions and options — each a gripkit user error; "unexpected"
  stays for bugs (the last test shows it still does).
* 13: ``io.load(12345)``, ``identify(..., banana=3)``, ``simulate``, ``zoo.build``, ``arx``,
  ``rls``, ``batch.sweep``: :class:`ArgumentError` (a ``TypeError``) naming the argument and
  listing what is accepted.
* 14: ``gripkit --version``.
* 15: ``gripkit identify step --method lm|trf``.
"""

from __future__ import annotations

import errno
import pathlib
from importlib import metadata

import numpy as np
import pytest

import gripkit
import gripkit.io  # the fixtures save and load with it
from gripkit.errors import (ArgumentError, ConfigError, DataError, IdentificationError, ModelError,
                            ParameterError, PathError)
from corpus import assert_user_error


MSD = (pathlib.Path(__file__).resolve().parents[2] / "examples"
       / "mass_spring_damper_step.toml").read_text()

SWEEP = """
[sweep]
name = "msd"
scenario = "step-response"
model = "mass-spring-damper"
samples = 2
seed = 1

[parameters]
k = { grid = [1.0, 4.0] }

[scenario]
duration = 10.0
fs = 50.0
amplitude = 1.0
"""

#: bytes that are not UTF-8 (a binary file given where a TOML file is expected)
JUNK = b"\xff\xfe\x00\x81junk\x80"


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Good and bad input files: an ARX record (y = 1.5y₋₁ − 0.7y₋₂ + u₋₁ + 0.5u₋₂), a model
    description, a sweep file, a binary "TOML", a folder and a plain file."""
    d = tmp_path_factory.mktemp("everywhere")
    rng = np.random.default_rng(3)
    u = rng.standard_normal(400)
    y = np.zeros(400)
    for k in range(2, 400):
        y[k] = 1.5 * y[k - 1] - 0.7 * y[k - 2] + u[k - 1] + 0.5 * u[k - 2]
    y += 0.01 * rng.standard_normal(400)
    gripkit.io.save(gripkit.Trajectory.uniform(dt=0.01, u=u, y=y), d / "io.csv")
    (d / "msd.toml").write_text(MSD)
    (d / "sweep.toml").write_text(SWEEP)
    (d / "junk.toml").write_bytes(JUNK)
    (d / "junk.csv").write_bytes(JUNK)
    (d / "folder").mkdir()
    (d / "plain").write_text("a plain file, not a folder\n")
    return d


def desc(tmp_path, old: str, new: str) -> pathlib.Path:
    assert old in MSD
    p = tmp_path / "bad.toml"
    p.write_text(MSD.replace(old, new))
    return p


def arx_args(path, *extra):
    return ("identify", "arx", path, "--input", "u", "--output", "y", "--na", 2, "--nb", 2, "--nk",
            1, *extra)


# ---------------------------------------------------------------------------------------------- 12
# usage mistakes: typer/click's NoSuchOption, BadParameter, MissingParameter, UsageError

@pytest.mark.parametrize("args, phrase", [
    (("--bogus",), "no such option: --bogus"),
    (("nosuchcmd",), "no such command 'nosuchcmd'"),
    (("zoo", "show"), "missing argument 'name'"),
    (("zoo", "list", "--bogus"), "see 'gripkit zoo list --help'"),
    (("zoo", "discretize", "ftg100-actuated", "--fs", "abc"), "invalid value for '--fs'"),
    (("zoo", "check", "ftg100-sensing", "--json", "--nope"), "no such option: --nope"),
    (("demo", "--quick", "--bogus"), "see 'gripkit demo --help'"),
    (("simulate", "msd.toml", "--out"), "option '--out' requires an argument"),
    (("identify", "modal", "io.csv", "--signal", "y", "--start", "soon"),
     "invalid value for '--start'"),
    (("identify", "bouc-wen", "io.csv", "--input", "u", "--output", "y", "--burn-in", "1.5"),
     "'--burn-in'"),
    (("identify", "friction", "io.csv", "--position", "y"), "missing option '--effort'"),
    (("identify", "rls", "io.csv", "--input", "u", "--output", "y", "--na", 2, "--nb", 2, "--nk", 1,
      "--forgetting", "high"), "invalid value for '--forgetting'"),
    (("identify", "search", "io.csv", "--input", "u", "--output", "y", "--top", "ten"), "'--top'"),
    # (the orders have the library's defaults, gripkit.sysid.checks.LINEAR_ORDERS, so a missing
    # option is a column: --output)
    (("identify", "armax", "io.csv", "--input", "u", "--na", 2, "--nb", 2, "--nk", 1),
     "missing option '--output'"),
    (("identify", "oe", "io.csv", "--input", "u", "--output", "y", "--nb", 2, "--nf", "x", "--nk",
      1), "'--nf'"),
    (("identify", "step", "io.csv", "--input", "u", "--output", "y", "--fs", "fast"), "'--fs'"),
    (("sweep", "sweep.toml", "--workers", "abc"), "invalid value for '--workers'"),
])
def test_usage_mistakes_are_one_line_usage_errors(cli, files, monkeypatch, args, phrase):
    monkeypatch.chdir(files)
    res = cli(*args)
    assert_user_error(res, "UsageError", phrase)
    assert res.code == 2 and res.out == ""


def test_unknown_option_names_the_command_help(cli, files):
    res = cli(*arx_args(files / "io.csv", "--bogus"))
    # click may add its guesses here
    assert_user_error(res, "UsageError", "no such option: --bogus")
    assert res.error_lines[0].endswith("see 'gripkit identify arx --help'")
    # no --output (not --nk: the orders are optional since they take gripkit.sysid.identify's
    # defaults, gripkit.sysid.checks.LINEAR_ORDERS; tests/cli/test_identify_default_orders.py)
    res = cli("identify", "arx", files / "io.csv", "--input", "u")
    assert_user_error(res, "UsageError", "missing option '--output'")
    res = (cli("identify", "arx", files / "io.csv", "--input", "u", "--output", "y", "--na", "two",
               "--nb", 2, "--nk", 1))
    assert_user_error(res, "UsageError", "invalid value for '--na'")


def test_group_without_a_command_prints_its_help(cli):
    for args in ((), ("identify",), ("zoo",)):
        res = cli(*args)
        assert (res.code == 0 and res.error_lines == []
                and "Usage: gripkit" in res.out + res.err), args


# junk, folders and unreadable TOML files (sweep files and model descriptions, via read_toml)

@pytest.mark.parametrize("command", ["simulate", "sweep"])
def test_binary_toml_is_a_config_error(cli, files, command):
    res = cli(command, files / "junk.toml")
    assert_user_error(res, "ConfigError", "is not UTF-8 text (byte 0xff at offset 0")


@pytest.mark.parametrize("command", ["simulate", "sweep"])
def test_folder_given_as_toml_is_a_config_error(cli, files, command):
    assert_user_error(cli(command, files / "folder"), "ConfigError",
                      "is a folder, expected a .toml file")
    assert_user_error(cli(command, ""), "ConfigError", "'.' is a folder")


def test_unreadable_toml_is_a_config_error(cli, files, monkeypatch):
    def denied(self):
        raise PermissionError(errno.EACCES, "Permission denied", str(self))

    monkeypatch.setattr(pathlib.Path, "read_bytes", denied)
    assert_user_error(cli("simulate", files / "msd.toml"), "ConfigError",
                      "cannot be read: permission denied")
    assert_user_error(cli("sweep", files / "sweep.toml"), "ConfigError",
                      "cannot be read: permission denied")


def test_toml_errors_in_the_python_api(files):
    from gripkit.batch import SweepSpec
    from gripkit.description import load_description

    with pytest.raises(ConfigError, match="model description .* is not UTF-8 text"):
        load_description(files / "junk.toml")
    with pytest.raises(ConfigError, match="sweep file .* is a folder"):
        SweepSpec.from_toml(files / "folder")
    with pytest.raises(ArgumentError, match="model description must be a file path"):
        load_description(42)


def test_toml_with_a_byte_order_mark_is_read(tmp_path):
    from gripkit.description import load_description

    p = tmp_path / "bom.toml"
    p.write_bytes(b"\xef\xbb\xbf" + MSD.encode())
    assert load_description(p).inputs.n == 500  # fs 1000 Hz × 0.5 s


# output paths: checked before any work (IsADirectoryError, NotADirectoryError, bad suffix)

def test_simulate_out_folder_refused_before_the_model_is_loaded(cli, files, monkeypatch):
    import gripkit.description as description

    monkeypatch.setattr(description, "load_description", lambda *a,
                        **k: pytest.fail("work started"))
    res = cli("simulate", files / "msd.toml", "--out", files / "folder")
    assert_user_error(res, "PathError", "--out")
    assert "is a folder, expected a file" in res.err and not any((files / "folder").iterdir())


@pytest.mark.parametrize("out, phrase", [
    ("plain/x.parquet", "'plain' is not a folder"),
    ("plain/deeper/x.csv", "'plain' is not a folder"),
    ("x.banana", "cannot tell the format from the suffix '.banana'"),
    ("", "'.' is a folder, expected a file"),
])
def test_simulate_bad_out_paths(cli, files, monkeypatch, out, phrase):
    monkeypatch.chdir(files)
    assert_user_error(cli("simulate", "msd.toml", "--out", out), "PathError", phrase)


def test_description_output_file_checked_before_simulating(cli, tmp_path, files):
    p = desc(tmp_path, "duration = 0.5", 'duration = 0.5\n[output]\nfile = '
                                         f'"{files / "plain" / "x.parquet"}"')
    assert_user_error(cli("simulate", p), "PathError", "[output] file of bad.toml")


def test_rls_trajectory_path_checked_before_the_data(cli, files, monkeypatch):
    import gripkit.cli.identify_common as cmd  # the identify commands read their data there

    monkeypatch.setattr(cmd, "load_data", lambda *a, **k: pytest.fail("work started"))
    base = ("identify", "rls", files / "io.csv", "--input", "u", "--output", "y", "--na", 2, "--nb",
            2, "--nk", 1)
    assert_user_error(cli(*base, "--trajectory", files / "plain" / "t.parquet"), "PathError",
                      "is not a folder")
    assert_user_error(cli(*base, "--trajectory", files / "folder"), "PathError", "--trajectory")
    assert_user_error(cli(*base, "--trajectory", files / "t.txt.gz"), "PathError", "suffix '.gz'")


@pytest.mark.parametrize("command", [("sweep", "sweep.toml"),
                                     ("demo", "--quick", "--section", "tsfm")])
def test_output_folder_options(cli, files, monkeypatch, command):
    monkeypatch.chdir(files)
    assert_user_error(cli(*command, "--out", "plain"), "PathError", "--out 'plain' is a file, "
                                                                    "expected a folder")
    assert_user_error(cli(*command, "--out", "plain/sub"), "PathError", "'plain' is not a folder")


# operating-system errors that reach main(): translated generically as a last resort

@pytest.mark.parametrize("exc, phrase", [
    (FileNotFoundError(errno.ENOENT, "No such file or directory", "gone.csv"),
     "'gone.csv' not found"),
    (IsADirectoryError(errno.EISDIR, "Is a directory", "out"), "'out' is a folder, "
                                                               "expected a file"),
    (NotADirectoryError(errno.ENOTDIR, "Not a directory", "plain/x"),
     "part of this path is a file"),
    (PermissionError(errno.EACCES, "Permission denied", "r.parquet"),
     "permission denied on 'r.parquet'"),
    (FileExistsError(errno.EEXIST, "File exists", "plain"), "'plain' already exists"),
    (OSError(errno.ENOSPC, "No space left on device", "big.h5"), "no space left on device "
                                                                 "('big.h5'); free disk"),
])
def test_os_errors_become_path_errors(cli, files, monkeypatch, exc, phrase):
    """`simulate` whose save fails with each OS error (the checks before the work passed)."""
    import gripkit.io

    def fail(*a, **k):
        raise exc

    monkeypatch.setattr(gripkit.io, "save", fail)
    res = cli("simulate", files / "msd.toml", "--out", files / "r.parquet")
    assert_user_error(res, "PathError", phrase)
    assert isinstance(PathError("x"), OSError)


def test_undecodable_text_anywhere_is_a_data_error(cli, files, monkeypatch):
    import gripkit.cli.identify_common as cmd  # the identify commands read their data there

    def fail(*a, **k):
        b"\x93quoted\x94".decode("utf-8")

    monkeypatch.setattr(cmd, "load_data", fail)
    assert_user_error(cli(*arx_args(files / "io.csv")), "DataError", "not UTF-8 text (byte "
                                                                     "0x93 at offset 0")


def test_a_bug_is_still_reported_as_unexpected(cli, files, monkeypatch):
    """The catch-all stays for bugs: one line, 'unexpected', the exception's class, a pointer to
    --debug."""
    import gripkit.cli.identify_common as cmd  # the identify commands read their data there

    monkeypatch.setattr(cmd, "load_data", lambda *a, **k: 1 / 0)
    res = cli(*arx_args(files / "io.csv"))
    assert res.code == 1 and len(res.error_lines) == 1 and "Traceback" not in res.err
    assert res.error_lines[0].startswith("error: unexpected ZeroDivisionError: division by zero")
    assert "--debug" in res.error_lines[0]
    res = cli("--debug", *arx_args(files / "io.csv"))
    assert "Traceback" in res.err and "ZeroDivisionError" in res.err


# junk data files and folders for every identify command

@pytest.mark.parametrize("command", [
    ("arx", "--input", "u", "--output", "y", "--na", 2, "--nb", 2, "--nk", 1),
    ("armax", "--input", "u", "--output", "y", "--na", 2, "--nb", 2, "--nc", 1, "--nk", 1),
    ("oe", "--input", "u", "--output", "y", "--nb", 2, "--nf", 2, "--nk", 1),
    ("rls", "--input", "u", "--output", "y", "--na", 2, "--nb", 2, "--nk", 1),
    ("search", "--input", "u", "--output", "y"),
    ("step", "--input", "u", "--output", "y"),
    ("modal", "--signal", "y"),
    ("bouc-wen", "--input", "u", "--output", "y"),
    ("friction", "--position", "y", "--effort", "u"),
])
def test_identify_commands_refuse_folders_and_junk(cli, files, command):
    name, *opts = command
    assert_user_error(cli("identify", name, files / "folder", *opts), "DataError",
                      "is a folder, expected a data file")
    assert_user_error(cli("identify", name, files / "junk.csv", *opts), "DataError",
                      "not a readable CSV file")


def test_validation_record_that_is_a_folder(cli, files):
    res = cli(*arx_args(files / "io.csv", "--validate", files / "folder"))
    assert_user_error(res, "DataError", "is a folder")


# bad numbers and types in model descriptions (ValueError/TypeError before)

@pytest.mark.parametrize("old, new, phrase", [
    ('kind = "step"\ninitial = 0.0\nfinal = 0.1\ntime = 0.1',
     'kind = "steps"\nlevels = ["a", '
     '1]\ndurations = [0.1, 0.1]', "levels[0] must be a number, found 'a'"),
    ('kind = "step"\ninitial = 0.0\nfinal = 0.1\ntime = 0.1',
     'kind = "steps"\nlevels = [0, 1]\ndurations = [-0.1, 0.1]', "durations must be positive"),
    ('kind = "step"\ninitial = 0.0\nfinal = 0.1\ntime = 0.1',
     'kind = "file"\npath = 3\ncolumn = "u"', "'path' must be a string, found 3"),
    ('k = "20 N/m"', "k = [1, 2]", "parameter 'k': expected a number (in 'N/m') or a "
                                   "string with its unit"),
    ('k = "20 N/m"', "k = true", "found bool true"),
    ('type = "mass-spring-damper"', 'type = ["a"]', "[model] type must be a string"),
    ("duration = 0.5", 'duration = 0.5\n[output]\nfile = 5', "[output] file must be a string"),
    ("fs = 1000", "fs = 1e300", "duration / dt = 5e+299 samples; expected 1 to 50 million"),
    ('[inputs.F]\nkind = "step"\ninitial = 0.0\nfinal = 0.1\ntime = 0.1', "[inputs]\nF = 3",
     "inputs.F must be a table"),
])
def test_description_bad_numbers_and_types(cli, tmp_path, old, new, phrase):
    res = cli("simulate", desc(tmp_path, old, new))
    assert_user_error(res, "ConfigError", phrase)
    assert len(res.error_lines[0]) < 400  # the 1e300 case once printed a 300-digit integer


def test_description_section_that_is_not_a_table(cli, tmp_path):
    p = tmp_path / "bad.toml"
    p.write_text("model = 3\n[parameters]" + MSD.split("[parameters]", 1)[1])
    assert_user_error(cli("simulate", p), "ConfigError", "'model' must be a table")


def test_modal_start_must_be_finite(cli, files):
    res = cli("identify", "modal", files / "io.csv", "--signal", "y", "--start", "nan")
    assert_user_error(res, "DataError", "--start: expected the release time in s (a finite "
                                        "number), found nan")


def test_zoo_commands_name_the_models(cli):
    for args in (("zoo", "show", "nope"), ("zoo", "check", "nope"),
                 ("zoo", "discretize", "nope", "--fs", 1000)):
        assert_user_error(cli(*args), "ModelError", "no zoo model 'nope'; available: "
                                                    "amadeus-finger-force")
    assert_user_error(cli("zoo", "discretize", "tsfm-left", "--fs", 1000), "ModelError",
                      "discretize works on: ftg100")


def test_sweep_scheduler_that_is_not_an_address(cli, files, tmp_path):
    res = (cli("sweep", files / "sweep.toml", "--backend", "dask", "--scheduler", "garbage",
               "--out", tmp_path / "s"))
    assert_user_error(res, "ConfigError", "dask")


def test_sweep_workers_and_demo_section(cli, files, tmp_path):
    assert_user_error(cli("sweep", files / "sweep.toml", "--workers", -3, "--out", tmp_path / "s"),
                      "ConfigError", "workers: expected a positive number")
    assert_user_error(cli("demo", "--section", "nope", "--out", tmp_path / "r"), "ConfigError",
                      "available: amadeus-identification")


# ---------------------------------------------------------------------------------------------- 13

@pytest.fixture(scope="module")
def traj(files):
    return gripkit.io.load(files / "io.csv")


def test_load_refuses_a_non_path():
    with pytest.raises(ArgumentError, match=r"load\(\): path must be a file path \(str or "
                                            r"pathlib.Path\), found int 12345"):
        gripkit.io.load(12345)
    with pytest.raises(TypeError):  # an ArgumentError is a TypeError, as Python's own
        gripkit.io.load(None)


def test_load_unknown_keyword_and_wrong_types(files):
    with pytest.raises(ArgumentError, match=r"unknown keyword 'colums'; load accepts path, "
                                            r"columns, time, fs"):
        gripkit.io.load(files / "io.csv", colums=["u"])
    with pytest.raises(ArgumentError, match="units must be a mapping"):
        gripkit.io.load(files / "io.csv", units=["mN"])
    with pytest.raises(ArgumentError, match="fs must be a sampling rate in Hz"):
        gripkit.io.load(files / "io.csv", fs="fast")


def test_save_refuses_wrong_types(traj, tmp_path):
    with pytest.raises(ArgumentError, match=r"save\(\): path must be a file path"):
        gripkit.io.save(traj, 3)
    with pytest.raises(ArgumentError, match="tr must be a gripkit Trajectory, found str"):
        gripkit.io.save("trajectory", tmp_path / "x.csv")


@pytest.mark.parametrize("method, options, phrase", [
    ("arx", {"banana": 3}, "for method 'arx', no other options"),
    ("armax", {"banana": 3}, "for method 'armax', maxiter, tol"),
    ("oe", {"banana": 3, "kiwi": 1}, "unknown keywords 'banana', 'kiwi'"),
    ("rls", {"lambda_": 0.9}, "forgetting, p0, theta0, windup, max_trace, store"),
    ("search", {"crit": "aic"}, "criterion, progress"),
])
def test_identify_unknown_keyword(traj, method, options, phrase):
    from gripkit.sysid import identify

    with pytest.raises(ArgumentError,
                       match=r"identify\(method='" + method + r"'\): unknown keyword") as info:
        identify(traj, method, input="u", output="y", **options)
    msg = str(info.value)
    assert (phrase in msg
            and "identify accepts data, method, inputs, outputs, input, output, na, nb, nk, nc, "
            "nf, detrend" in msg)


def test_identify_wrong_types_and_missing_arguments(traj):
    from gripkit.sysid import identify

    with pytest.raises(ArgumentError, match="input must be a column name .str., found int "
                                            "3; columns: u, y"):
        identify(traj, "arx", input=3, output="y")
    with pytest.raises(ArgumentError, match="missing a required argument: 'outputs' .or its "
                                            "alias 'output'.; identify accepts data, method"):
        identify(traj, "arx", input="u")
    with pytest.raises(ArgumentError, match="inputs= and its alias input= both given "
                                            r"\(inputs='u', input='y'\); give the column"):
        identify(traj, "arx", inputs="u", input="y", output="y")
    with pytest.raises(ArgumentError, match="outputs= and its alias output= both given"):
        identify(traj, "arx", inputs="u", outputs="y", output="y")
    with pytest.raises(DataError, match="method: expected one of arx, armax, oe, rls, search"):
        identify(traj, ["arx"], input="u", output="y")


def test_identify_known_options_still_work(traj):
    """The per-method options pass through: RLS with λ = 1 and OE with few iterations fit the
    simulated plant y = 1.5y₋₁ − 0.7y₋₂ + u₋₁ + 0.5u₋₂ (noise σ = 0.01)."""
    from gripkit.sysid import identify

    r = identify(traj, "rls", input="u", output="y", na=2, nb=2, nk=1, forgetting=1.0, p0=1e4)
    np.testing.assert_allclose(r.theta_final, [-1.5, 0.7, 1.0, 0.5], atol=0.02)
    m = identify(traj, "arx", input="u", output="y", na=2, nb=2, nk=1)
    np.testing.assert_allclose(m.A, [1.0, -1.5, 0.7], atol=0.01)
    # inputs=/outputs= (the documented names) and their aliases input=/output=: the same fit
    for kw in ({"inputs": "u", "outputs": "y"}, {"inputs": "u", "output": "y"}):
        same = identify(traj, "arx", na=2, nb=2, nk=1, **kw)
        assert np.array_equal(same.A, m.A) and np.array_equal(same.B, m.B)
        assert (same.input_name, same.output_name) == ("u", "y")


@pytest.mark.parametrize("fn, args", [("arx", (2, 2, 1)), ("armax", (2, 2, 1, 1)),
                                      ("oe", (2, 2, 1))])
def test_polynomial_fits_refuse_unknown_metadata_before_fitting(traj, fn, args):
    import gripkit.sysid as sysid

    with pytest.raises(ArgumentError, match=rf"{fn}\(\): unknown keyword 'banana'; "
                                            rf"{fn} accepts u, y") as info:
        getattr(sysid, fn)(traj["u"], traj["y"], *args, banana=3)
    assert "the metadata input_name, output_name" in str(info.value)


def test_rls_and_search_unknown_keyword(traj):
    from gripkit.sysid import rls, structure_search

    with pytest.raises(ArgumentError, match=r"rls\(\): unknown keyword 'lam'; rls accepts u, y, "
                                            r"na, nb, nk, forgetting"):
        rls(traj["u"], traj["y"], 2, 2, 1, lam=0.99)
    with pytest.raises(ArgumentError, match="criterion"):
        structure_search(traj["u"], traj["y"], critrion="aic")


def test_simulate_entry_point():
    from gripkit.models import MassSpringDamper
    from gripkit.sim import simulate

    m = MassSpringDamper(m=1.0, b=1.0, k=1.0)
    u = np.ones(10)
    with pytest.raises(ArgumentError, match=r"unknown keyword 'banana'; accepted: dt, x0, "
                                            r"params, substeps"):
        simulate(m, u, dt=0.1, banana=3)
    with pytest.raises(ArgumentError, match="model must be a gripkit model .gripkit.sim.Model., "
                                            "found str 'nope'"):
        simulate("nope", u, dt=0.1)
    with pytest.raises(ArgumentError, match="u: expected numbers"):
        simulate(m, "abc", dt=0.1)
    with pytest.raises(ArgumentError, match="dt: expected a sample time in seconds .a "
                                            "number., found str"):
        simulate(m, u, dt="0.1")
    with pytest.raises(ArgumentError, match="missing a required argument: 'u'; simulate accepts "
                                            "model, u, \\*\\*kwargs"):
        simulate(m)
    # a right call still gives the right numbers: the exact (zero-order hold) unit-step response of
    # m = b = k = 1 (ζ = 0.5, ω_n = 1 rad/s), x = 1 − e^{−ζt}(cos ω_d t + ζ/ω_d sin ω_d t), to
    # rounding
    tr = simulate(m, np.ones(20000), dt=1e-3)
    wd = np.sqrt(0.75)
    ref = 1 - np.exp(-0.5 * tr.t) * (np.cos(wd * tr.t) + 0.5 / wd * np.sin(wd * tr.t))
    np.testing.assert_allclose(tr["x"], ref, rtol=0, atol=1e-11)


def test_zoo_build_and_get():
    from gripkit import zoo

    with pytest.raises(ModelError, match="no zoo model 'nope'; available: "
                                         "amadeus-finger-force, amadeus-hand"):
        zoo.build("nope")
    with pytest.raises(ArgumentError, match="zoo model name: expected a str, found "
                                            "int 3; available: "):
        zoo.build(3)
    with pytest.raises(ArgumentError, match=r"zoo.build\('tsfm-left'\): unknown keyword 'banana'; "
                                            r"accepted: as_printed, check"):
        zoo.build("tsfm-left", banana=3)
    with pytest.raises(ArgumentError, match=r"zoo.build\(.amadeus-finger-force.\): unknown keyword "
                                            r".gain.; accepted: force_scale"):
        zoo.build("amadeus-finger-force", gain=2)


def test_batch_sweep_unknown_keyword(files):
    from gripkit.batch import sweep

    with pytest.raises(ArgumentError, match=r"sweep\(\): unknown keyword 'worker'; sweep accepts "
                                            r"spec, backend, workers"):
        sweep(files / "sweep.toml", worker=2)


def test_parameter_value_of_the_wrong_type():
    from gripkit.models import MassSpringDamper

    ps = MassSpringDamper().parameters
    with pytest.raises(ParameterError, match="parameter 'k': expected a number .in 'N/m'. or a "
                                             "string with its unit, found list"):
        ps.replace(k=[1, 2])
    assert ps.replace(k="2 kN/m").value("k") == 2000.0


# ---------------------------------------------------------------------------------------------- 14

def test_version(cli):
    res = cli("--version")
    assert res.code == 0 and res.err == ""
    assert res.out.strip() == f"gripkit {metadata.version('gripkit')}"


def test_version_without_package_metadata(cli, monkeypatch):
    def missing(name):
        raise metadata.PackageNotFoundError(name)

    monkeypatch.setattr(metadata, "version", missing)
    res = cli("--version")
    assert res.code == 0 and res.out.strip() == f"gripkit {gripkit.__version__}"


# ---------------------------------------------------------------------------------------------- 15

@pytest.fixture(scope="module")
def step_file(tmp_path_factory):
    from gripkit.systems.ftg100.identification import step_experiment

    path = tmp_path_factory.mktemp("step") / "step.csv"
    gripkit.io.save(step_experiment(duration=0.05, seed=4), path)
    return path


def test_identify_step_method_trf(cli, step_file):
    """`--method trf` on the simulated FT-G100 step (003_abd62b560633beaf.txt §III-B, eq 9:
    f_n = 1757.2 Hz, ζ = 0.04299, gain 0.18887 µm/V) recovers the seed's values within 3σ, and
    agrees with the default Levenberg-Marquardt to a small fraction of σ (the same minimum)."""
    fits = {}
    for method in ("trf", "lm"):
        res = (cli("identify", "step", step_file, "--input", "V_in", "--output", "x_a", "--method",
                   method, "--json"))
        assert res.code == 0, res.err
        fits[method] = d = res.json()
        assert d["method"] == method
        assert abs(d["natural_frequency_hz"] - 1757.2) < 3 * d["natural_frequency_hz_std"]
        assert abs(d["damping_ratio"] - 0.04299) < 3 * d["damping_ratio_std"]
        assert abs(d["gain"] - 0.18887e-6) < 3 * d["gain_std"]
    for key in ("gain", "natural_frequency_hz", "damping_ratio"):
        assert abs(fits["trf"][key] - fits["lm"][key]) < 0.05 * fits["lm"][key + "_std"], key


def test_identify_step_method_validated_before_the_data(cli, tmp_path):
    res = (cli("identify", "step", tmp_path / "missing.csv", "--input", "u", "--output", "y",
               "--method", "newton"))
    assert_user_error(res, "DataError", "--method: expected one of lm, trf, found 'newton'")


def test_identify_step_api_method(step_file):
    from gripkit.sysid.physical.step_response import identify_step

    tr = gripkit.io.load(step_file)
    with pytest.raises(DataError, match="method: expected one of lm, trf, found 'dogbox'"):
        identify_step(tr, input="V_in", output="x_a", method="dogbox")
    with pytest.raises(ArgumentError, match="unknown keyword 'methd'"):
        identify_step(tr, input="V_in", output="x_a", methd="trf")


def test_identify_step_hint_names_the_cli_option(cli, step_file, monkeypatch):
    """When Levenberg-Marquardt leaves the bounds, the hint tells both API and CLI users what to
    do."""
    import gripkit.sysid.physical.step_response as sr

    def out_of_bounds(*a, **k):
        raise IdentificationError("Levenberg-Marquardt converged outside the bounds: zeta = -0.1",
                                  hint="use method='trf' to enforce the bounds")

    monkeypatch.setattr(sr, "fit", out_of_bounds)
    res = cli("identify", "step", step_file, "--input", "V_in", "--output", "x_a")
    assert_user_error(res, "IdentificationError", "use method='trf' (CLI: --method trf)")


def test_debug_is_accepted_after_the_command(cli):
    """The one-line errors say "run with --debug": appending it to the command works."""
    res = cli("zoo", "show", "no-such-model", "--debug")
    assert res.code == 1 and "UsageError" not in res.err
