"""The one rank decision rule, and the reciprocal screw systems it decides.

Every rank in pinmob is decided here, on a dimensionless matrix (twists
``[v / L; w]``, wrenches ``[f L; tau]``, joint rates per L), by an SVD with a
tolerance relative to a reference scale: a singular value counts when it is
above ``rtol * reference``. The reference is the matrix's largest singular value
unless the caller names another one: 1 for a matrix built from orthonormal
bases (whose natural scale is 1, and which must have rank 0 when it is zero),
or the largest singular value of the whole matrix a block was cut from (so that
a block is judged with its parent's threshold). Every decision returns its
singular values and tolerance, and how clearly the rank was decided
(:attr:`RankDecision.margin`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pinmob.exceptions import ArgumentError
from pinmob.screw.algebra import Array, twist_scaling, wrench_scaling

#: Default relative tolerance on singular values for rank decisions.
RTOL = 1e-6
#: The smallest tolerance allowed: below it round-off decides (double precision leaves singular values
#: of these matrices about 1e-15 of the largest; on the built-in models the answers first change at 1e-13).
RTOL_MIN = 1e-10
#: A decision whose singular values come within this factor of the tolerance is ambiguous (:func:`ambiguity`).
AMBIGUOUS_MARGIN = 10.0

try:  # numpy >= 2: the gufuncs behind np.linalg.svd (full U and V, reduced, values only)
    from numpy.linalg import _umath_linalg

    _SVD_F: Any = _umath_linalg.svd_f
    _SVD_S: Any = _umath_linalg.svd_s
    _SVD_N: Any = _umath_linalg.svd
except (ImportError, AttributeError):  # older numpy names them by shape: use np.linalg.svd
    _SVD_F = _SVD_S = _SVD_N = None


def check_rtol(rtol: object, name: str = "rtol") -> float:
    """A validated relative rank tolerance: a finite real number with ``RTOL_MIN <= rtol < 1``.

    Singular values below ``rtol * sigma_max`` count as zero, so ``rtol`` below
    :data:`RTOL_MIN` (1e-10) would let round-off decide (3-PUU-flat turned 1H at
    1e-16) and ``rtol >= 1`` would drop real motions.

    Args:
        rtol: the tolerance to check (dimensionless).
        name: the parameter's name in the message and the error's ``parameter`` (the CLI words it ``--rtol``).

    Raises:
        ArgumentError: not a real number, not finite, or outside [1e-10, 1).
    """
    if isinstance(rtol, bool) or not isinstance(rtol, (int, float, np.integer, np.floating)):
        raise ArgumentError(
            f"{name} must be a number in [{RTOL_MIN:g}, 1), got {rtol!r} ({type(rtol).__name__})", name, rtol
        )
    value = float(rtol)
    if not (np.isfinite(value) and RTOL_MIN <= value < 1.0):
        raise ArgumentError(
            f"{name} must be a finite number in [{RTOL_MIN:g}, 1), e.g. {RTOL:g} (below {RTOL_MIN:g} round-off "
            f"decides the ranks); got {rtol!r}",
            name,
            rtol,
        )
    return value


def svd(a: Array, full_matrices: bool = True) -> tuple[Array, Array, Array]:
    """``U, s, V^T`` of a small non-empty (m, n) float matrix (or a stack (..., m, n)): LAPACK's ``dgesdd``.

    Called straight through numpy's own LAPACK gufunc, the one ``np.linalg.svd``
    calls: the same routine and results, without ``np.linalg.svd``'s per-call
    argument handling, which costs as much as the SVD of a 6 x 6 matrix. Falls
    back to ``np.linalg.svd`` (which raises ``LinAlgError``) when LAPACK does not
    converge, and on numpy versions without that gufunc.
    """
    gufunc = _SVD_F if full_matrices else _SVD_S
    if gufunc is not None:
        u, s, vt = gufunc(a)
        if _converged(s):
            return u, s, vt
    return tuple(np.linalg.svd(a, full_matrices=full_matrices))  # type: ignore[return-value]


def _converged(s: Array) -> bool:
    """LAPACK converged: no NaN among the singular values (the gufuncs fill a failed matrix with NaN)."""
    return bool(s.ndim == 1 and (s.size == 0 or s[0] == s[0])) or (s.ndim > 1 and not np.isnan(s).any())


def singular_values(a: Array) -> Array:
    """Singular values of a float matrix (or a stack (..., m, n)), descending (``dgesdd`` without vectors)."""
    if _SVD_N is not None:
        s = _SVD_N(a)
        if _converged(s):
            return np.asarray(s, dtype=np.float64)
    return np.asarray(np.linalg.svd(a, compute_uv=False), dtype=np.float64)


@dataclass(frozen=True)
class RankDecision:
    """Outcome of a unit-invariant rank decision.

    Attributes:
        rank: number of singular values above ``tolerance``.
        singular_values: all singular values, descending.
        tolerance: absolute threshold used, ``rtol * reference``.
        row_space: (rank, n) orthonormal basis of the row space.
        null_space: (n - rank, n) orthonormal basis of the null space.
    """

    rank: int
    singular_values: Array
    tolerance: float
    row_space: Array
    null_space: Array

    @property
    def margin(self) -> float:
        """How clearly the rank is decided: ``min(sigma_rank / tol, tol / sigma_(rank+1))`` (inf when clear-cut).

        Below about 10 a small change of ``rtol``, of the units or of the
        configuration's round-off would change the rank.
        """
        s, tol = self.singular_values, self.tolerance
        if tol <= 0:
            return float("inf")
        kept = s[self.rank - 1] / tol if self.rank > 0 else np.inf
        dropped = tol / s[self.rank] if self.rank < s.size and s[self.rank] > 0 else np.inf
        return float(min(kept, dropped))


def ambiguity(singular_values: Array, tolerance: float, rank: int) -> tuple[float, float] | None:
    """``(sigma_rank, sigma_(rank+1))`` when either lies within :data:`AMBIGUOUS_MARGIN` of the tolerance, else None.

    The two singular values either side of the tolerance: the last one counted (0 for rank 0) and the
    first one dropped (0 when none is). Within that factor there is no clear gap: a change of ``rtol``,
    of the geometry's accuracy or of the configuration's closure would change the rank.
    """
    s = np.asarray(singular_values, float)
    if tolerance <= 0 or s.size == 0:
        return None
    kept = float(s[rank - 1]) if rank > 0 else 0.0
    dropped = float(s[rank]) if rank < s.size else 0.0
    close = (kept > 0 and kept < AMBIGUOUS_MARGIN * tolerance) or dropped * AMBIGUOUS_MARGIN > tolerance
    return (kept, dropped) if close else None


def rank_rule(
    singular_values: Array, rtol: float, *, reference: float | None = None, at_least: float = 0.0
) -> tuple[int, float]:
    """The one rank rule: ``(rank, tolerance)`` of descending singular values (see :func:`decide_rank`).

    The tolerance is ``rtol * max(at_least, reference)`` (reference: the largest
    singular value unless given); the rank counts the singular values above it
    (0 when they are all zero). Every rank in pinmob is decided by this function,
    on singular values from one SVD (:func:`decide_rank`) or from a batch of them.
    """
    smax = float(singular_values[0]) if singular_values.size else 0.0
    tol = rtol * max(at_least, smax if reference is None else float(reference))
    return (int(np.count_nonzero(singular_values > tol)) if smax > 0 else 0), tol


def rank_rule_rows(singular_values: Array, rtol: float) -> NDArray[np.int64]:
    """:func:`rank_rule` of each row of (N, m) descending singular values (the reference: each row's largest)."""
    s = np.asarray(singular_values, float)
    if s.shape[-1] == 0:
        return np.zeros(s.shape[:-1], np.int64)
    top = s[..., :1]
    return np.where(top[..., 0] > 0, np.count_nonzero(s > rtol * top, axis=-1), 0).astype(np.int64)


def decision(
    singular_values: Array, vt: Array, rtol: float, *, reference: float | None = None, at_least: float = 0.0
) -> RankDecision:
    """The :class:`RankDecision` from an SVD already computed (``s`` descending, ``V^T`` (n, n)), by :func:`rank_rule`."""
    rank, tol = rank_rule(singular_values, rtol, reference=reference, at_least=at_least)
    return RankDecision(rank, singular_values, tol, vt[:rank], vt[rank:])


def decide_rank(
    matrix: ArrayLike,
    rtol: float = RTOL,
    n: int | None = None,
    *,
    reference: float | None = None,
    at_least: float = 0.0,
) -> RankDecision:
    """SVD of a dimensionless (m, n) matrix; singular values above ``rtol * max(at_least, reference)`` count.

    Args:
        matrix: (m, n) dimensionless matrix.
        rtol: relative tolerance.
        n: number of columns when the matrix is empty (m = 0).
        reference: the scale the tolerance is relative to; default the largest
            singular value (see the module docstring for the other choices).
        at_least: a floor under the reference: 1 for a matrix built from
            orthonormal bases, whose natural scale is 1 and which must have rank
            0 when it is zero.

    An empty matrix (m = 0) has rank 0 and the whole space as null space. A
    matrix with at least as many rows as columns gets the reduced SVD (its
    ``V^T`` is the full one, bit for bit; ``U`` is not used).
    """
    a = np.asarray(matrix, float)
    if a.ndim != 2:
        raise ValueError(f"expected a 2-D matrix, got shape {a.shape}")
    if a.size == 0:
        cols = a.shape[1] if n is None else n
        return RankDecision(0, np.zeros(0), 0.0, np.zeros((0, cols)), np.eye(cols))
    _, s, vt = svd(a, full_matrices=a.shape[0] < a.shape[1])
    return decision(s, vt, rtol, reference=reference, at_least=at_least)


def decide_ranks(
    matrices: Sequence[ArrayLike], rtol: float = RTOL, n: int | None = None, *, at_least: float = 0.0
) -> list[RankDecision]:
    """:func:`decide_rank` of each matrix, with one batched SVD per shape (the same bits as one call each).

    Args:
        matrices: dimensionless (m_i, n) matrices, e.g. every limb's transposed joint screws.
        rtol: relative tolerance (each matrix's reference is its own largest singular value).
        n: number of columns of the empty ones.
        at_least: a floor under each reference (1 for matrices built from orthonormal bases, see
            :func:`decide_rank`).
    """
    arrays = [np.asarray(m, float) for m in matrices]
    out: list[RankDecision | None] = [None] * len(arrays)
    shapes: dict[tuple[int, ...], list[int]] = {}
    for i, a in enumerate(arrays):
        if a.ndim != 2:
            raise ValueError(f"expected 2-D matrices, got shape {a.shape}")
        if a.size == 0:
            out[i] = decide_rank(a, rtol, n)
        else:
            shapes.setdefault(a.shape, []).append(i)
    for (rows, cols), which in shapes.items():
        _, s, vt = svd(np.stack([arrays[i] for i in which]), full_matrices=rows < cols)
        for k, i in enumerate(which):
            out[i] = decision(s[k], vt[k], rtol, at_least=at_least)
    return out  # type: ignore[return-value]


def reciprocal_wrenches(twists: ArrayLike, length: float, rtol: float = RTOL) -> tuple[Array, RankDecision]:
    """Basis of the wrenches reciprocal to every twist given.

    Solves ``W^T T = 0`` on the dimensionless matrices: the null space of
    ``(D_t T)^T`` where ``D_t = diag(1/L, 1/L, 1/L, 1, 1, 1)``, mapped back by
    ``f = f_hat / L``.

    Args:
        twists: (6, k) twists ``[v; w]`` [m/s, rad/s per unit joint rate].
        length: characteristic length L [m].
        rtol: relative tolerance on the singular values.

    Returns:
        (6, 6 - rank) wrenches ``[f; tau]`` (orthonormal when dimensionless),
        and the rank decision on the twists.
    """
    t = np.asarray(twists, float).reshape(6, -1)
    dec = decide_rank((twist_scaling(length)[:, None] * t).T, rtol, n=6)
    w_hat = dec.null_space.T
    return w_hat / wrench_scaling(length)[:, None], dec


def reciprocal_twists(wrenches: ArrayLike, length: float, rtol: float = RTOL) -> tuple[Array, RankDecision]:
    """Basis of the twists reciprocal to every wrench given (dual of :func:`reciprocal_wrenches`).

    Returns:
        (6, 6 - rank) twists ``[v; w]`` and the rank decision on the wrenches.
    """
    w = np.asarray(wrenches, float).reshape(6, -1)
    dec = decide_rank((wrench_scaling(length)[:, None] * w).T, rtol, n=6)
    return dec.null_space.T / twist_scaling(length)[:, None], dec
