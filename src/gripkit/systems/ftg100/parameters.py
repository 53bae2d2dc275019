"""The FemtoTools FT-G100 microgripper (seed ``003_abd62b560633beaf.txt``) in the zoo: the seed's
identified values and the factories of the zoo's models (the models and their parameter tables
with provenance are in :mod:`gripkit.systems.ftg100.model`)."""

from __future__ import annotations

from .model import FTG100Actuated, FTG100Coupled, FTG100Plant, FTG100Sensing, plant_parameters

__all__ = ["PAPER_VALUES", "actuated_model", "sensing_model", "coupled_model", "plant_model",
           "calibrated_plant_model"]

#: The seed's identified values (SI) with their section.
PAPER_VALUES = {"M_a": (1.37e-6, "§III-B"), "K_fa": (1.3e-3, "§III-B"), "k0": (1043.0, "§III-B"),
                "M_b": (0.5e-6, "§III-D"), "K_fb": (0.71e-3, "§III-D")}


def actuated_model(**values) -> FTG100Actuated:
    """Zoo ``ftg100-actuated``: eqs 8-10 at the seed's values (M_a, K_fa, k0 free)."""
    return FTG100Actuated(**values)


def sensing_model(**values) -> FTG100Sensing:
    """Zoo ``ftg100-sensing``: eqs 14-17 at the seed's values (M_b, K_fb free)."""
    return FTG100Sensing(**values)


def coupled_model(**values) -> FTG100Coupled:
    """Zoo ``ftg100-coupled``: eq 18 (actuated and sensing subsystems through k_k, readout r)."""
    return FTG100Coupled(**values)


def plant_model(**values) -> FTG100Plant:
    """Zoo ``ftg100-plant``: the nonlinear plant with eq 5's force as printed and the linear
    suspensions of eqs 4 and 8-10 (its small-signal model at 70 V grasped is eq 9/10, 0.82 % from
    eq 10's gain), V² actuation, contact with the ball after the 20 µm gap (100 µm opening − 80 µm
    ball: the seed's "20 µm at 70 V" read as the travel to the ball; derivation of both readings in
    :mod:`gripkit.systems.ftg100.model`)."""
    return FTG100Plant(**values)


def calibrated_plant_model(**values) -> FTG100Plant:
    """Zoo ``ftg100-plant-calibrated``: the other reading of the seed's 20 µm at 70 V (the free
    tip's displacement): the default plant with the comb-drive force factor fitted to it (κ = 0.4601
    × eq 5 with the linear suspensions, ``plant_parameters(force_factor='static-70V')``), which puts
    its small-signal gain at 70 V 53.6 % below eq 10 (reported by ``zoo check``). ``values`` replace
    parameters before the fit."""
    check = values.pop("check", True)
    return FTG100Plant(plant_parameters(force_factor="static-70V", **values), check=check)
