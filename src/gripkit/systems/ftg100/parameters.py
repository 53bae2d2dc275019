"""The FemtoTools FT-G100 microgripper (seed ``003_abd62b560633beaf.txt``): every number the
seed gives for it, with provenance, in one place. The dimensions and materials
(:func:`ftg100_geometry`), the model parameters at the seed's values (:func:`ftg100_parameters`),
the nonlinear plant's own entries (:func:`plant_table`), the readout sensitivity, the static
statement at 70 V, eqs 10 and 17 as printed, and the identified values as a table
(:data:`PAPER_VALUES`, read from :func:`ftg100_parameters`). The models that use them and the
zoo's factories are in :mod:`gripkit.systems.ftg100.model`."""

from __future__ import annotations

from ...params import Parameter, ParameterSet

__all__ = ["SEED", "R_SENSITIVITY", "DT", "SEED_EQ10", "SEED_EQ17", "STATIC_70V", "ftg100_geometry",
           "ftg100_parameters", "plant_table", "PAPER_VALUES"]

SEED = "003_abd62b560633beaf.txt"
_S = SEED + ", "
#: Readout sensitivity r of eq 18 as gripkit reads it: 50 µN/V (the seed prints "50 N/Volts").
R_SENSITIVITY = 50e-6

#: The sample interval of the seed's discrete models, eqs 10, 17 and 18: 20 kHz.
DT = 5e-05

# Eq 10 and eq 17 as printed (seed units: V -> µm for eq 10, µN -> µm for eq 17), at DT.
SEED_EQ10 = dict(A=[[1.6621, -0.9536], [1.0, 0.0]], B=[[0.25], [0.0]], C=[[0.1104, 0.1086]],
                 dt=DT, input="V_in", input_unit="V", output="x_a", output_unit="um",
                 source=_S + "eq 10")
SEED_EQ17 = dict(A=[[1.142174, -0.947527], [1.0, 0.0]], B=[[0.5], [0.0]], C=[[0.132080, 0.129656]],
                 dt=DT, input="F_c", input_unit="uN", output="x_b", output_unit="um",
                 source=_S + "eq 17")

#: The seed's static statement (§III-A, after Fig. 4): 70 V "allows a displacement of 20 µm in
#: static mode at the tip of the actuated arm". Read as the free tip's displacement it is what
#: ``force_factor='static-70V'`` calibrates to; read as the 100 − 80 µm gap to the ball it is the
#: plant's ``gap`` (module docstring).
STATIC_70V = (70.0, 20e-6)


def ftg100_geometry() -> ParameterSet:
    """The FT-G100 dimensions and materials the seed gives (§III-A, III-C, Fig. 2, Fig. 6)."""
    um = 1e-6
    P = Parameter
    return ParameterSet([
        P("E", 190e9, "Pa", "Young's modulus of the silicon beams", (0, None),
          source=_S + "§III-A, after eq 4", display_unit="GPa"),
        P("h", 50 * um, "m", "structure (beam and finger) thickness", (0, None),
          source=_S + "§III-A, after eq 4", display_unit="um"),
        P("w", 8 * um, "m", "suspension beam width", (0, None),
          source=_S + "§III-A, after eq 4", display_unit="um"),
        P("L1", 1830 * um, "m", "actuator suspension beam length", (0, None),
          source=_S + "§III-A, after eq 4", display_unit="um"),
        P("L2", 870 * um, "m", "sensor suspension beam length", (0, None),
          source=_S + "§III-C, after eq 15", display_unit="um"),
        P("H", 5300 * um, "m", "arm length dimension of eqs 3/12", (0, None),
          source=_S + "§III-A, after eq 3", display_unit="um"),
        P("l", 300 * um, "m", "hinge dimension of eqs 3/12 (hinge at l/2 from the clamp)",
          (0, None),
          source=_S + "§III-A, after eq 3", display_unit="um"),
        P("a", 950 * um, "m", "actuated-arm lever dimension of eq 3", (0, None),
          source=_S + "§III-A, after eq 3", display_unit="um"),
        P("b", 700 * um, "m", "sensing-arm lever dimension of eq 12", (0, None),
          source=_S + "§III-C, after eq 15", display_unit="um"),
        P("N_a", 1300.0, "1", "electrode pairs of the lateral comb drive", (1, None),
          source=_S + "§III-A, after eq 5"),
        P("eps", 8.85e-12, "F/m", "permittivity of the comb gaps (air)", (0, None),
          source=_S + "§III-A, after eq 5", display_unit="pF/m"),
        P("g", 6 * um, "m", "gap between comb fingers", (0, None),
          source=_S + "§III-A, after eq 5", display_unit="um"),
        P("V_max", 200.0, "V", "maximum actuation voltage (full close)", (0, None),
          source=_S + "§II-A"),
        P("opening", 100 * um, "m", "initial opening between the arm tips", (0, None),
          source=_S + "§II-A", display_unit="um"),
        P("resolution", 50e-9, "N", "force sensor resolution", (0, None),
          source=_S + "§II-A", display_unit="uN"),
        P("force_range", 140e-6, "N", "largest force of the static sensor characteristic",
          (0, None),
          source=_S + "§III-D, Fig. 10", display_unit="uN"),
        P("k2_measured", 6.48, "N/m", "sensing-arm stiffness measured from Fig. 10", (0, None),
          source=_S + "§III-D, Fig. 10"),
        P("x_a70", 20e-6, "m", "static tip displacement at 70 V (free arm)", (0, None),
          source=_S + "§III-A, after Fig. 4", display_unit="um"),
    ], "ftg100-geometry")


def ftg100_parameters() -> ParameterSet:
    """Every FT-G100 model parameter at the seed's values (SI), with provenance.

    Stated values are used as printed (D_a = 4.7, K_sa = 25.4 N/m, ...); the consistency checks of
    the models compare them with what eqs 3, 4, 12, 13, 16 give from the dimensions.
    """
    P = Parameter
    return ParameterSet([
        P("M_a", 1.37e-6, "kg", "total (effective) mass of the actuated subsystem", (1e-12, 1e-3),
          source=_S + "§III-B, LM estimate", display_unit="mg"),
        P("K_fa", 1.3e-3, "N*s/m", "damping factor of the actuated subsystem", (0, 1.0),
          source=_S + "§III-B, LM estimate (printed unit mNs²/m read as mN·s/m)",
          display_unit="mN*s/m"),
        P("k0", 1043.0, "N/m", "stiffness of the grasped object (80 µm glass ball)", (0, 1e7),
          source=_S + "§III-B, LM estimate"),
        P("K_sa", 25.4, "N/m", "actuator suspension stiffness (two pairs of clamped-clamped beams)",
          (0, None), source=_S + "§III-A, eq 4 value stated after Fig. 7"),
        P("D_a", 4.7, "1", "actuated-arm amplification x_a/x_ea", (0, None),
          source=_S + "§III-A, eq 3 value stated after Fig. 7"),
        P("k2", 6.45, "N/m", "sensing-arm tip stiffness K_sb/D_b²", (0, None),
          source=_S + "§III-C, eq 16"),
        P("N_a", 1300.0, "1", "electrode pairs of the lateral comb drive", (1, None),
          source=_S + "§III-A, after eq 5"),
        P("eps", 8.85e-12, "F/m", "permittivity of the comb gaps (air)", (0, None),
          source=_S + "§III-A, after eq 5", display_unit="pF/m"),
        P("h", 50e-6, "m", "comb-finger thickness", (0, None),
          source=_S + "§III-A, after eq 4", display_unit="um"),
        P("g", 6e-6, "m", "gap between comb fingers", (0, None),
          source=_S + "§III-A, after eq 5", display_unit="um"),
        P("V0", 70.0, "V", "operating voltage V_in0 of the linearisation", (0, 200),
          source=_S + "§III-A, before eq 8"),
        P("M_b", 0.5e-6, "kg", "total mass of the sensing subsystem", (1e-12, 1e-3),
          source=_S + "§III-D, LM estimate", display_unit="mg"),
        P("K_fb", 0.71e-3, "N*s/m", "damping factor of the sensing subsystem", (0, 1.0),
          source=_S + "§III-D, LM estimate (printed unit mNs²/m read as mN·s/m)",
          display_unit="mN*s/m"),
        P("K_sb", 235.36, "N/m", "sensor suspension stiffness", (0, None),
          source=_S + "§III-C, eq 13 value stated"),
        P("D_b", 6.05, "1", "sensing-arm amplification x_b/x_eb", (0, None),
          source=_S + "§III-C, eq 12 value stated"),
        P("x_off", 0.0, "m", "output offset (sensor zero) of a displacement record", (-1e-3, 1e-3),
          source="measurement offset, not in the seed", display_unit="um"),
        P("r", R_SENSITIVITY, "N/V", "readout sensitivity (force per output volt)", (0, None),
          source=_S + "eq 18, printed '50 N/Volts', read as 50 µN/V (see module docstring)",
          display_unit="uN/V"),
    ], "ftg100")


def plant_table() -> ParameterSet:
    """The entries of :class:`~gripkit.systems.ftg100.model.FTG100Plant` that the linear models do
    not have and that are not computed (K3_a and c_e are, in
    :func:`~gripkit.systems.ftg100.model.plant_parameters`)."""
    P = Parameter
    return ParameterSet([
        P("K3_b", 0.0, "N/m**3", "cubic stiffening of the sensor suspension", (0, None),
          source=_S + "Fig. 10 (linear sensor up to 140 µN)"),
        P("c0", 0.0, "N*s/m", "viscous damping of the object contact", (0, None),
          source="assumed: the seed models the object as a pure spring (§III-E)"),
        P("gap", 20e-6, "m", "free gap between the actuated tip and the object", (0, None),
          source=_S + "§II-A opening 100 µm − 80 µm glass ball", display_unit="um"),
        P("V_max", 200.0, "V", "actuation voltage limit", (0, None), source=_S + "§II-A"),
    ], "ftg100-plant-own")


#: The seed's identified values (SI) with their section, as :func:`ftg100_parameters` holds them
PAPER_VALUES = {p.name: (p.value, p.source.split(", ")[1]) for p in ftg100_parameters().values()
                if p.name in ("M_a", "K_fa", "k0", "M_b", "K_fb")}
