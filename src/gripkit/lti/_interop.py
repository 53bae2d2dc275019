"""Systems from python-control and scipy.signal objects, and from gripkit's older linear types."""

from __future__ import annotations

import numpy as np

from ..errors import ModelError
from ._pycontrol import control_module
from ._system import LinearSystem, StateSpace, TransferFunction

__all__ = ["from_control", "from_scipy", "as_system"]


def _control_dt(dt):
    if dt is None or dt is True:
        raise ModelError(f"the python-control system has an unspecified time base (dt={dt!r})",
                         hint="give it dt=0 (continuous) or a sample time in s")
    return None if dt == 0 else float(dt)


def from_control(sys, *, input_units=None, output_units=None) -> LinearSystem:
    """A gripkit system from a ``control.StateSpace`` or ``control.TransferFunction``, keeping
    input, output (and state) names; python-control has no units, give them here if wanted.

    Examples
    --------
    >>> import control
    >>> from gripkit.lti import from_control
    >>> g = from_control(control.tf([1.0], [1.0, 1.0], inputs="V", outputs="x"), output_units="m")
    >>> g.inputs, g.outputs, g.output_units
    (('V',), ('x',), ('m',))
    """
    ct = control_module()
    kw = dict(inputs=tuple(sys.input_labels), outputs=tuple(sys.output_labels),
              input_units=input_units, output_units=output_units)
    if isinstance(sys, ct.StateSpace):
        return StateSpace(np.asarray(sys.A), np.asarray(sys.B), np.asarray(sys.C),
                          np.asarray(sys.D),
                          dt=_control_dt(sys.dt), states=tuple(sys.state_labels), **kw)
    if isinstance(sys, ct.TransferFunction):
        p, m = sys.noutputs, sys.ninputs
        num = [[np.asarray(sys.num_array[i, j] if hasattr(sys, "num_array") else sys.num[i][j],
                           dtype=float)
                for j in range(m)] for i in range(p)]
        den = [[np.asarray(sys.den_array[i, j] if hasattr(sys, "den_array") else sys.den[i][j],
                           dtype=float)
                for j in range(m)] for i in range(p)]
        return TransferFunction(num, den, dt=_control_dt(sys.dt), **kw)
    raise ModelError(f"from_control: expected a control.StateSpace or control.TransferFunction, "
                     f"found {type(sys).__name__}")


def from_scipy(sys, **signals) -> LinearSystem:
    """A gripkit system from a ``scipy.signal`` LTI object (``lti``/``dlti``: state space,
    transfer function or zeros-poles-gain). ``signals``: names and units.

    Examples
    --------
    >>> from scipy import signal
    >>> from gripkit.lti import from_scipy
    >>> from_scipy(signal.dlti([1.0], [1.0, -0.5], dt=0.1)).dt
    0.1
    """
    from scipy import signal

    if not isinstance(sys, (signal.lti, signal.dlti)):
        raise ModelError("from_scipy: expected a scipy.signal lti/dlti, found "
                         f"{type(sys).__name__}")
    dt = getattr(sys, "dt", None)
    if isinstance(sys, (signal.StateSpace,)):
        return StateSpace(sys.A, sys.B, sys.C, sys.D, dt=dt, **signals)
    tf = sys.to_tf() if not isinstance(sys, signal.TransferFunction) else sys
    num = np.atleast_2d(tf.num)
    if num.shape[0] == 1:
        return TransferFunction(num[0], tf.den, dt=dt, **signals)
    return TransferFunction([[row] for row in num], [[tf.den] for _ in num], dt=dt, **signals)


def as_system(obj, **signals) -> LinearSystem:
    """Any linear model gripkit meets, as a :class:`LinearSystem`.

    Accepts a LinearSystem (returned as is), an object whose ``system`` attribute is one (an
    identified model: :class:`gripkit.sysid.LinearModel`, :class:`gripkit.sysid.PolynomialModel`,
    also as :func:`gripkit.sysid.load_model` reads them) or whose ``lti`` attribute is one (a
    :class:`gripkit.control.DiscretePlant`),
    a python-control or scipy.signal system, an object with ``A``, ``B``, ``dt`` coefficient
    arrays in powers of q⁻¹ (``y = B/(A F) u`` when it has ``F``; its ``input_name``/
    ``output_name``/units are kept), or a tuple ``(A, B, dt)`` of q⁻¹ polynomials. ``signals``
    override names and units.

    Examples
    --------
    >>> from gripkit.lti import as_system
    >>> g = as_system(([1.0, -0.5], [0.0, 1.0], 0.01))
    >>> type(g).__name__, g.dt, g.den_zinv().tolist()
    ('TransferFunction', 0.01, [1.0, -0.5])
    """
    for view in ("system", "lti"):  # an identified model (LinearModel, PolynomialModel); a plant
        if not isinstance(obj, LinearSystem) and isinstance(getattr(obj, view, None), LinearSystem):
            obj = getattr(obj, view)
    if isinstance(obj, LinearSystem):
        return obj.replace(**signals) if signals else obj
    if isinstance(obj, tuple) and len(obj) == 3:
        return TransferFunction.from_polynomials(obj[0], obj[1], dt=float(obj[2]), **signals)
    mod = type(obj).__module__.split(".")[0]
    if mod == "control":
        g = from_control(obj)
        return g.replace(**signals) if signals else g
    if mod == "scipy":
        return from_scipy(obj, **signals)
    if all(hasattr(obj, k) for k in ("A", "B", "dt")):
        kw = {}
        for src, dst in (("input_name", "inputs"), ("output_name", "outputs"),
                         ("input_unit", "input_units"),
                         ("output_unit", "output_units")):
            if getattr(obj, src, None):
                kw[dst] = getattr(obj, src)
        kw.update(signals)
        return (TransferFunction.from_polynomials(obj.A, obj.B, F=getattr(obj, "F", None),
                                                  dt=float(obj.dt), **kw))
    raise ModelError(f"as_system: cannot read a linear system from {type(obj).__name__}",
                     hint="give a gripkit.lti system, a python-control or scipy.signal "
                          "system, a polynomial "
                          "model (A, B, dt), or a tuple (A, B, dt)")
