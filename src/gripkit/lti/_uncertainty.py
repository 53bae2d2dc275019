"""Parameter covariance carried by a linear system, and its first-order propagation.

A system ``S(θ)`` built from uncertain parameters θ (covariance Σ) carries, next to its nominal
arrays (``A, B, C, D`` or ``num, den``), their *tangents* ∂(array)/∂θ_i. Any quantity q(S) then
has the linearised covariance

    cov q ≈ J Σ Jᵀ,   J_i = ∂q/∂θ_i = Dq(S)[∂S/∂θ_i],

which is what MATLAB's ``idss``/``idpoly`` report as one-sigma bands. Exact derivatives are used
for poles and frequency responses; representation changes (c2d, d2c, ss↔tf, interconnections)
push the tangents through by central differences with step h = ε^{1/3}·scale, whose relative
error O(ε^{2/3}) ≈ 4e-11 is far below any σ worth reporting.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ModelError

__all__ = ["Uncertainty", "complex_covariance"]

_EPS = np.finfo(float).eps


@dataclass(frozen=True, eq=False)
class Uncertainty:
    """Covariance of parameters θ and the tangents of a system's arrays with respect to them.

    Parameters
    ----------
    names
        Parameter names, length k.
    covariance
        Σ, shape (k, k), symmetric positive semi-definite.
    tangents
        One array per system array (``(dA, dB, dC, dD)`` for a state space, ``(dnum, dden)`` for a
        transfer function), each of shape (k, \\*array.shape): ∂array/∂θ_i.

    Examples
    --------
    >>> import numpy as np
    >>> u = Uncertainty(("a",), [[0.01]], (np.ones((1, 1, 1)),))
    >>> float(u.std[0])
    0.1
    """

    names: tuple[str, ...]
    covariance: np.ndarray
    tangents: tuple[np.ndarray, ...]

    def __post_init__(self):
        names = tuple(self.names)
        k = len(names)
        if len(set(names)) != k:
            raise ModelError("uncertainty: parameter names must be distinct, found "
                             + ", ".join(sorted({n for n in names if names.count(n) > 1})))
        cov = np.array(self.covariance, dtype=np.float64)
        if cov.shape != (k, k):
            raise ModelError(f"covariance: expected shape ({k}, {k}) (one row per parameter), "
                             f"found {cov.shape}")
        if not np.isfinite(cov).all():
            raise ModelError("covariance has non-finite entries")
        scale = max(float(np.abs(cov).max()) if k else 0.0, np.finfo(float).tiny)
        # symmetric up to rounding of a product J Σ Jᵀ: k ε relative
        if np.abs(cov - cov.T).max() > 100 * k * _EPS * scale:
            raise ModelError("covariance: expected a symmetric matrix, found an asymmetric one")
        cov = 0.5 * (cov + cov.T)
        if k and np.linalg.eigvalsh(cov).min() < -100 * k * _EPS * scale:
            raise ModelError(f"covariance: expected positive semi-definite, found an eigenvalue "
                             f"{np.linalg.eigvalsh(cov).min():.3g}")
        tangents = []
        for t in self.tangents:
            t = np.array(t, dtype=np.float64)
            if t.shape[:1] != (k,):
                raise ModelError(f"tangents: expected a leading axis of {k} (one per parameter), "
                                 f"found shape {t.shape}")
            if not np.isfinite(t).all():
                raise ModelError("tangents have non-finite entries")
            t.flags.writeable = False
            tangents.append(t)
        cov.flags.writeable = False
        object.__setattr__(self, "names", names)
        object.__setattr__(self, "covariance", cov)
        object.__setattr__(self, "tangents", tuple(tangents))

    @property
    def n_params(self) -> int:
        return len(self.names)

    @property
    def std(self) -> np.ndarray:
        """One-sigma of each parameter, √diag Σ."""
        return np.sqrt(np.clip(np.diag(self.covariance), 0.0, None))

    def _check_shapes(self, arrays) -> None:
        if len(arrays) != len(self.tangents):
            raise ModelError(f"uncertainty: expected {len(arrays)} tangent arrays, found "
                             f"{len(self.tangents)}")
        for a, t in zip(arrays, self.tangents):
            if t.shape[1:] != a.shape:
                raise ModelError(f"uncertainty: tangent shape {t.shape[1:]} does not match its "
                                 f"array {a.shape}")

    def draws(self, n: int, rng) -> np.ndarray:
        """``n`` parameter deviations δθ ~ N(0, Σ), shape (n, k) (Σ may be singular).

        Examples
        --------
        >>> import numpy as np
        >>> u = Uncertainty(("a", "b"), np.diag([1.0, 0.0]), (np.zeros((2, 1)),))
        >>> d = u.draws(1000, np.random.default_rng(0))
        >>> d.shape, float(np.abs(d[:, 1]).max())
        ((1000, 2), 0.0)
        """
        w, V = np.linalg.eigh(self.covariance)
        L = V * np.sqrt(np.clip(w, 0.0, None))
        return rng.standard_normal((int(n), self.n_params)) @ L.T


def complex_covariance(J: np.ndarray, cov: np.ndarray) -> np.ndarray:
    """Covariance of (Re q, Im q) for a complex quantity q with ∂q/∂θ = J.

    ``J`` has shape (k, \\*shape); the result has shape (\\*shape, 2, 2):
    ``[[Re J], [Im J]] Σ [[Re J], [Im J]]ᵀ``.

    Examples
    --------
    >>> import numpy as np
    >>> complex_covariance(np.array([[1 + 2j]]), np.array([[4.0]]))[0]
    array([[ 4.,  8.],
           [ 8., 16.]])
    """
    J = np.asarray(J)
    k = J.shape[0]
    R = np.stack([J.real, J.imag], axis=-1).reshape(k, -1)  # (k, prod(shape)*2)
    shape = J.shape[1:]
    R = R.reshape((k,) + shape + (2,))
    return np.einsum("i...a,ij,j...b->...ab", R, cov, R)


def merge(uncertainties) -> tuple[tuple[str, ...], np.ndarray]:
    """Names and block-diagonal covariance of independent systems' parameters (names that
    collide get a ``'<position>.'`` prefix)."""
    present = [(i, u) for i, u in enumerate(uncertainties) if u is not None]
    all_names = [n for _, u in present for n in u.names]
    clash = len(set(all_names)) != len(all_names)
    names = [f"{i + 1}.{n}" if clash else n for i, u in present for n in u.names]
    k = len(names)
    cov = np.zeros((k, k))
    o = 0
    for _, u in present:
        q = u.n_params
        cov[o:o + q, o:o + q] = u.covariance
        o += q
    return tuple(names), cov


def push(fn, arrays_list, uncertainties):
    """``fn(*arrays)`` (a tuple of arrays) and the Uncertainty of its result.

    ``fn`` takes the arrays of all input systems, flattened in order; ``arrays_list[i]`` is the
    tuple of arrays of input system i and ``uncertainties[i]`` its
    Uncertainty or None. The result's tangents are central differences of ``fn`` along each
    parameter's tangent, with h = ε^{1/3}·max(1, ‖arrays‖_max)/‖tangent‖_max.
    """
    def call(arrays_list):
        return fn(*[a for arrs in arrays_list for a in arrs])

    out = tuple(np.asarray(o) for o in call(arrays_list))
    if all(u is None for u in uncertainties):
        return out, None
    names, cov = merge(uncertainties)
    k = len(names)
    tangents = [np.zeros((k,) + o.shape) for o in out]
    col = 0
    for i, (arrs, u) in enumerate(zip(arrays_list, uncertainties)):
        if u is None:
            continue
        scale = max([1.0] + [float(np.abs(a).max()) for a in arrs if np.size(a)])
        for j in range(u.n_params):
            tj = [t[j] for t in u.tangents]
            tn = max([0.0] + [float(np.abs(t).max()) for t in tj if t.size])
            if tn > 0:
                h = _EPS ** (1 / 3) * scale / tn
                args_p, args_m = list(arrays_list), list(arrays_list)
                args_p[i] = tuple(a + h * t for a, t in zip(arrs, tj))
                args_m[i] = tuple(a - h * t for a, t in zip(arrs, tj))
                op, om = call(args_p), call(args_m)
                for q in range(len(out)):
                    tangents[q][col] = (np.asarray(op[q]) - np.asarray(om[q])) / (2 * h)
            col += 1
    return out, Uncertainty(names, cov, tuple(tangents))
