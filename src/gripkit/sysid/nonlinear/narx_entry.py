"""The one NARX entry point, :func:`narx`: ``basis`` chooses the polynomial NARX
(:mod:`.narx`, ``y(t) = Σ θ_k · terms_k(t)``) or the rational NARX (:mod:`.narx_rational`,
``y(t) = N(φ(t))/D(φ(t))``, Billings & Zhu 1991). The rational model extends the polynomial one
(its model class, regressors and kernels), so this entry sits above both and the imports run one
way.
"""

from __future__ import annotations

from ...errors import ArgumentError
from .narx import NARXModel, checked_arguments, polynomial_narx

__all__ = ["narx", "BASES"]

#: the NARX bases
BASES = ("polynomial", "rational")


def narx(u, y=None, *, degree: int = 2, lags: int | None = 2, ylags: int | None = None,
         ulags: int | None = None, terms="auto", dt: float | None = None, validate=None,
         direct: bool = False, prune: bool = True, refine: str | None = None,
         forgetting: float = 1.0, max_iter: int = 50, progress: bool = False,
         basis: str = "polynomial", den_degree: int | None = None) -> NARXModel:
    """NARX model of ``y`` driven by ``u`` (1-D arrays of equal length), or of several records:
    ``narx([(u1, y1), (u2, y2), …])`` (each record's first ``max_lag`` samples are its own
    past; one regression over all of them, σ from all).

    ``basis``: ``"polynomial"`` (default; every other argument as
    :func:`~gripkit.sysid.nonlinear.narx.polynomial_narx` describes it: degree, lags, terms by
    FROLS with BIC or the validation fit, pruning, ``refine="simulation"``, ``forgetting``) or
    ``"rational"``: ``y(t) = N(φ)/D(φ) + e(t)`` with ``N`` of degree ``degree`` and
    ``D = 1 + Σ d_j q_j(φ)`` of degree ``den_degree`` (default ``degree``), a
    :class:`~gripkit.sysid.nonlinear.narx_rational.RationalNARXModel`
    (:func:`~gripkit.sysid.nonlinear.narx_rational.rational_narx`; not with ``forgetting``).
    """
    if basis not in BASES:
        raise ArgumentError(f"narx: basis must be one of {', '.join(map(repr, BASES))}, found "
                            f"{basis!r}", hint="basis='rational' fits y = N(φ)/D(φ)")
    if den_degree is not None and basis != "rational":
        raise ArgumentError(f"narx: den_degree = {den_degree!r} is the degree of a rational "
                            f"model's denominator, but basis = {basis!r}",
                            hint="give basis='rational' or leave den_degree out")
    if basis == "polynomial":
        return polynomial_narx(u, y, degree=degree, lags=lags, ylags=ylags, ulags=ulags,
                               terms=terms, dt=dt, validate=validate, direct=direct, prune=prune,
                               refine=refine, forgetting=forgetting, max_iter=max_iter,
                               progress=progress)
    from .narx_rational import rational_narx  # its kernels compile for basis='rational' only

    records, _, degree, ly, lu, max_iter = checked_arguments(
        u, y, degree=degree, lags=lags, ylags=ylags, ulags=ulags, dt=dt, direct=direct,
        refine=refine, max_iter=max_iter)
    if forgetting != 1.0:
        raise ArgumentError(f"narx: forgetting = {forgetting!r} applies to the polynomial "
                            "least squares, not to basis='rational'",
                            hint="forgetting=1 with basis='rational'")
    return rational_narx(records, ylags=ly, ulags=lu, degree=degree, den_degree=den_degree,
                         direct=direct, terms=terms, dt=dt, validate=validate, prune=prune,
                         refine=refine, max_iter=max_iter, progress=progress)
