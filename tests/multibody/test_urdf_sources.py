"""What ``from_urdf`` reads (API audit): XML text as str (a byte-order mark first is still XML),
bytes decoded as their XML declaration says, a path; and what it refuses: any document that
declares a DTD (internal, external, with entities: XXE, billion laughs), in one line that says
why, before anything is expanded or fetched."""

import errno
import os
import time

import numpy as np
import pytest

from gripkit.errors import ModelError, PathError
from gripkit.multibody import from_urdf

ARM = ('<robot name="r"><link name="base"/><link name="l1"><inertial><origin xyz="0 0 0.05"/>'
       '<mass value="{mass}"/><inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" '
       'iyz="0"/></inertial></link><joint name="j1" type="revolute"><origin xyz="{xyz}"/>'
       '<parent link="base"/><child link="l1"/><axis xyz="1 0 0"/><limit lower="-1" upper="1" '
       'effort="1" velocity="1"/></joint></robot>')
PLAIN = ARM.format(mass="0.1", xyz="0 0 0.3")
REFUSED = r"declares a DTD .*: gripkit reads no DTDs or entities"


def _gravity(chain):
    """The gravity torque at q = 0.5 rad: 0.1 kg at 0.05 m from the x axis, m g r sin q."""
    return float(chain.gravity(np.array([0.5]))[0])


def test_str_bytes_bom_and_path_read_the_same_chain(tmp_path):
    want = 0.1 * 9.81 * 0.05 * np.sin(0.5)
    p = tmp_path / "arm.urdf"
    p.write_text(PLAIN)
    sources = [PLAIN, "\ufeff  " + PLAIN, PLAIN.encode(), bytearray(PLAIN.encode()),
               ('<?xml version="1.0" encoding="UTF-16"?>' + PLAIN).encode("utf-16"), p, str(p)]
    for src in sources:
        assert abs(_gravity(from_urdf(src))) == pytest.approx(want, rel=1e-12)


def test_a_bytes_error_names_no_garbled_file():
    with pytest.raises(ModelError, match=r"^expected a <robot> root element, found <model>$"):
        from_urdf(b"<model/>")


def test_a_long_string_that_is_neither_xml_nor_a_file_gets_a_short_message():
    with pytest.raises(ModelError, match=r"source: neither an existing file nor XML text") as exc:
        from_urdf("robot " * 70)
    assert len(str(exc.value)) < 200


@pytest.mark.parametrize("dtd", [
    '<!DOCTYPE robot [<!ENTITY m "0.1">]>',
    '<!DOCTYPE robot SYSTEM "{dtd}">',
    '<!DOCTYPE robot [<!ENTITY % ext SYSTEM "{dtd}"> %ext;]>',
    '<!DOCTYPE robot [<!ENTITY m SYSTEM "file://{secret}">]>',
], ids=["internal", "external", "parameter", "xxe"])
def test_any_dtd_is_refused_before_it_is_read(tmp_path, dtd):
    secret, ext = tmp_path / "secret.txt", tmp_path / "x.dtd"
    secret.write_text("0.5")
    ext.write_text('<!ENTITY m "0.7">')
    text = dtd.format(dtd=ext, secret=secret) + ARM.format(mass="&m;", xyz="0 0 0.3")
    with pytest.raises(ModelError, match=REFUSED) as exc:
        from_urdf(text)
    assert "\n" not in str(exc.value) and "0.5" not in str(exc.value)
    f = tmp_path / "r.urdf"
    f.write_text(text)
    with pytest.raises(ModelError, match=r"^URDF file 'r.urdf' declares a DTD"):
        from_urdf(f)
    with pytest.raises(ModelError, match=REFUSED):
        from_urdf(text.encode())


def test_billion_laughs_is_refused_at_once():
    lol = '<!DOCTYPE robot [<!ENTITY a "aaaaaaaaaa">' + "".join(
        f'<!ENTITY {b} "{("&" + a + ";") * 10}">' for a, b in zip("abcdefgh", "bcdefghi")) + "]>"
    t0 = time.perf_counter()
    with pytest.raises(ModelError, match=REFUSED):
        from_urdf(lol + ARM.format(mass="0.1", xyz="&i;"))
    assert time.perf_counter() - t0 < 1.0


@pytest.mark.skipif(not hasattr(os, "geteuid") or os.geteuid() == 0,
                    reason="runs as root (or on a system without Unix file permissions): root "
                           "may read a file whatever its permissions, so a file without read "
                           "permission cannot be made here")
def test_a_file_without_read_permission_is_a_path_error_naming_it(tmp_path):
    """chmod 000: a PathError naming the file and the OS's reason, not a raw PermissionError."""
    p = tmp_path / "arm.urdf"
    p.write_text(PLAIN)
    p.chmod(0)
    try:
        with pytest.raises(PathError, match=r"URDF file '.*arm.urdf' cannot be read "
                                             r"\(Permission denied\)"):
            from_urdf(p)
    finally:
        p.chmod(0o600)


def test_an_unreadable_file_is_a_path_error_naming_it(tmp_path, monkeypatch):
    """The same refusal where the OS refuses the read (simulated, so that it runs as root too):
    a PathError with the file's path, the OS's reason and the hint to check permissions."""
    p = tmp_path / "arm.urdf"
    p.write_text(PLAIN)

    def refused(self):
        raise PermissionError(errno.EACCES, "Permission denied", str(self))

    monkeypatch.setattr(type(p), "read_bytes", refused)
    with pytest.raises(PathError, match=r"URDF file '.*arm.urdf' cannot be read \(Permission "
                                         r"denied\)") as e:
        from_urdf(str(p))
    assert "check its permissions" in e.value.hint
