"""Bad input to ``gripkit identify dynamics`` and ``gripkit excitation fourier``: every case gives
one ``error:`` line naming the class and the culprit (URDF element, option, column), no
traceback."""

import numpy as np
import pytest
from corpus import assert_user_error

LINK = ('<link name="{}"><inertial><mass value="0.1"/><inertia ixx="1e-4" iyy="1e-4" '
        'izz="1e-4"/></inertial></link>')
JOINT = ('<joint name="{}" type="revolute"><parent link="{}"/><child link="{}"/><axis xyz="0 0 1"/>'
         '<limit lower="-1" upper="1" effort="1" velocity="2"/></joint>')


def _arm(body_extra="", links=("base", "l1", "l2")):
    parts = ['<robot name="arm">', '<link name="base"/>']
    parts += [LINK.format(n) for n in links[1:]]
    parts += [JOINT.format(f"j{k}", links[k], links[k + 1]) for k in range(len(links) - 1)]
    return "".join(parts) + body_extra + "</robot>"


@pytest.fixture
def urdf(tmp_path):
    p = tmp_path / "arm.urdf"
    p.write_text(_arm())
    return p


def _log(tmp_path, n=4000, fs=1000.0, move=(True, True), nan_at=None, times=None):
    t = np.arange(n) / fs if times is None else times
    cols = {"t": t}
    for j, mv in enumerate(move):
        cols[f"p{j}"] = 0.5 * np.sin(2 * np.pi * 0.5 * (j + 1) * t) if mv else np.zeros(n)
        cols[f"e{j}"] = np.cos(t * (j + 1))
    if nan_at is not None:
        cols["e1"][nan_at] = np.nan
    p = tmp_path / "log.csv"
    np.savetxt(p, np.column_stack(list(cols.values())), delimiter=",", header=",".join(cols),
               comments="")
    return p


OK = ["--position", "p0,p1", "--effort", "e0,e1"]


@pytest.mark.parametrize("xml, phrase", [
    ("<robot><link name='a'></robot>", "not well-formed"),
    ("<model/>", "expected a <robot> root element, found <model>"),
    (_arm(links=("base", "l1")).replace('<link name="l1"><inertial>',
                                        '<link name="l1"><x>').replace(
        "</inertial></link>", "</x></link>"), "link 'l1', moved by joint 'j0', has no <inertial>"),
    (_arm().replace('type="revolute"', 'type="planar"', 1), "joint 'j0' has type 'planar'"),
    (_arm(JOINT.format("jx", "base", "l2")), "link 'l2' is the child of joints 'j1' and 'jx'"),
    (_arm().replace('velocity="2"', 'velocity="fast"', 1), "joint 'j0' <limit>: velocity='fast' "
                                                           "is not a number"),
    ('<!DOCTYPE robot [<!ENTITY m SYSTEM "file:///etc/hostname">]>' + _arm(),
     "URDF file 'bad.urdf' declares a DTD (<!DOCTYPE robot>): gripkit reads no DTDs"),
])
def test_bad_urdf(cli, tmp_path, xml, phrase):
    p = tmp_path / "bad.urdf"
    p.write_text(xml)
    assert_user_error(cli("identify", "dynamics", p, _log(tmp_path), *OK), "ModelError", phrase)
    assert_user_error(cli("excitation", "fourier", p, "--out", tmp_path / "x.csv"), "ModelError",
                      phrase)


def test_missing_urdf(cli, tmp_path):
    assert_user_error(cli("identify", "dynamics", tmp_path / "none.urdf", _log(tmp_path), *OK),
                      "ModelError", "does not exist")


@pytest.mark.parametrize("args, kind, phrase", [
    (["--position", "p0", "--effort", "e0,e1"], "ConfigError", "--position: 1 column(s) ['p0'] for "
                                                               "the 2 actuated joints j0, j1"),
    (["--position", "p0,p1", "--effort", "e0,e1", "--velocity", "v0"], "ConfigError",
     "--velocity: 1 column(s)"),
    (OK + ["--gravity", "0,0"], "ConfigError", "--gravity: expected three comma-separated numbers"),
    (OK + ["--effort-scale", "0"], "DataError", "--effort-scale: expected a finite "
                                                "positive factor, found 0.0"),
    (OK + ["--friction", "lugre"], "DataError", "friction: expected one of none, coulomb-viscous"),
    (OK + ["--cutoff", "900"], "DataError", "cutoff 900 Hz must lie between 0 and the Nyquist "
                                            "frequency 500 Hz"),
])
def test_bad_options(cli, urdf, tmp_path, args, kind, phrase):
    assert_user_error(cli("identify", "dynamics", urdf, _log(tmp_path), *args), kind, phrase)


def test_bad_logs(cli, urdf, tmp_path):
    assert_user_error(cli("identify", "dynamics", urdf, _log(tmp_path, n=300), *OK), "DataError",
                      "too few")
    assert_user_error(cli("identify", "dynamics", urdf, _log(tmp_path, move=(True, False)), *OK),
                      "UnidentifiableError", "joint(s) j1 never move")
    assert_user_error(cli("identify", "dynamics", urdf, _log(tmp_path, nan_at=100), *OK),
                      "DataError", "e1")


def test_bad_excitation_options(cli, urdf, tmp_path):
    assert_user_error(cli("excitation", "fourier", urdf, "--out", tmp_path / "x.csv", "--f0", "0"),
                      "DataError", "need f0 > 0")
    assert_user_error(cli("excitation", "fourier", urdf, "--out", tmp_path / "x.csv",
                          "--velocity-limit", "-1"),
                      "DataError", "velocity_limits: expected positive limits")
