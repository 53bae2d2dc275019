"""Physical (grey-box) identification: any ODE model's parameters by simulation-error
minimisation (:mod:`.greybox`), modal parameters of a free vibration, second-order step
responses, and the Bouc-Wen hysteresis of a piezo actuator.

The public names are those of :mod:`gripkit.sysid`; import them from there.
"""

__all__ = []  # the names are exported by gripkit.sysid
