"""The four reference systems of the seeds, one package each, built on the generic layers:

- :mod:`gripkit.systems.amadeus` — AMADEUS hydraulic three-finger subsea hand
(``000_8f66dcc7ab06470c.txt``);
- :mod:`gripkit.systems.tsfm` — two-smart-fingers piezoelectric microgripper
(``001_0b92a7da96e7aa46.txt``);
- :mod:`gripkit.systems.dlr_hit` — DLR/HIT Hand II modular finger (``002_ddea254371185ad3.txt``);
- :mod:`gripkit.systems.ftg100` — FemtoTools FT-G100 MEMS microgripper
(``003_abd62b560633beaf.txt``).

Each package holds the system's parameters with provenance, its models, estimators, controllers,
identification procedures and its demo section. :mod:`gripkit.zoo` lists their reference models.
"""

__all__ = ["amadeus", "dlr_hit", "ftg100", "tsfm"]
