"""Units of `gripkit identify friction`'s parameters (issue 25, "rough edges": they printed as
'(35.1507*1)*s^2/1'): inertia effort·s²/position, viscous effort·s/position, Coulomb and offset
in effort units; a unitless side drops out; an effort scale leads the effort unit. The command
prints the units of :func:`gripkit.sysid.rigid_body.friction.idim_units`, tested here."""

from gripkit.sysid.rigid_body.friction import idim_units
from gripkit.units import same_dimension


def test_units_of_a_joint_in_rad_with_a_torque():
    u = idim_units("rad", "N*m")
    assert u == {"inertia": "(N*m*s^2)/rad", "viscous": "(N*m*s)/rad", "coulomb": "N*m",
                 "offset": "N*m"}
    assert same_dimension(u["inertia"], "kg*m^2")   # rad is dimensionless: J in kg·m²


def test_unitless_columns_and_a_scale_read_plainly():
    assert idim_units("1", "1", 35.1507) == {"inertia": "35.1507*s^2", "viscous": "35.1507*s",
                                             "coulomb": "35.1507", "offset": "35.1507"}
    assert idim_units("m", "A", 0.5)["viscous"] == "(0.5 A*s)/m"
    assert idim_units("m", "N")["inertia"] == "(N*s^2)/m" and same_dimension("(N*s^2)/m", "kg")
