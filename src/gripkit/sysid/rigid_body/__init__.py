"""Rigid-body identification: multi-joint inverse dynamics (IDIM-LS on the base parameters, the
model file, the physical-consistency projection, the report), friction (breakaway, constant
velocity, Stribeck, IDIM friction), the motor, and the Fourier excitation trajectory designed for
them.

The public names are those of :mod:`gripkit.sysid`; import them from there.
"""

__all__ = []  # the names are exported by gripkit.sysid
