"""Linear black-box identification: ARX, ARMAX and OE (polynomial models), subspace (N4SID,
MOESP, CVA) and PEM state-space models, transfer functions (tfest), frequency responses (FRF),
recursive least squares, structure search and validation. Every identified model is a
:class:`~gripkit.sysid.linear.linear_model.LinearModel` or a
:class:`~gripkit.sysid.linear.polynomial.PolynomialModel`, both on the protocol of
:mod:`gripkit.sysid.model_protocol`.

The public names are those of :mod:`gripkit.sysid`; import them from there.
"""

__all__ = []  # the names are exported by gripkit.sysid
