"""Nonlinear system identification: polynomial NARX by forward regression with the
error reduction ratio (:func:`~gripkit.sysid.narx`, :mod:`.narx`); Hammerstein, Wiener and
Hammerstein–Wiener models (:func:`~gripkit.sysid.hammerstein_wiener`, :mod:`.hammerstein_wiener`);
hysteresis, generic Bouc-Wen and Prandtl–Ishlinskii with its inverse
(:func:`~gripkit.sysid.hysteresis`, :mod:`.hysteresis`); polynomial nonlinear state space
(:func:`~gripkit.sysid.nlss`, :mod:`.nlss`).

The public names are those of :mod:`gripkit.sysid`; import them from there.
"""

__all__ = []  # the names are exported by gripkit.sysid
