"""Canonical bases and comparisons of subspaces: world-aligned directions, labels, round-off cleaning."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from pinmob.screw.algebra import Array
from pinmob.screw.rank import decide_rank

AXIS_NAMES = ("x", "y", "z")


def canonical_directions(basis: ArrayLike, tol: float = 1e-9) -> Array:
    """Canonical orthonormal basis of a subspace of R^3.

    Greedy: at each step, project the world axes x, y, z onto what is left of
    the subspace, take the axis with the largest projection (ties go to the
    earlier axis), normalise the projection and remove it. The result is sorted
    by that axis and each vector points along its axis, so the basis depends only
    on the subspace, not on the input basis.

    The greedy steps have a closed form per dimension r of the subspace
    (:func:`canonical_directions_greedy` runs them one by one; the tests compare
    both): r = 3 gives the world axes; r = 1 the unit direction u, pointing along
    its largest component; r = 2, with unit normal n, first
    ``(e_a - n_a n) / |e_a - n_a n|`` for the axis a least inclined to the plane
    (smallest ``|n_a|``), then the unit vector ``n x`` that one, pointing along its
    largest component.

    Args:
        basis: (3, k) spanning vectors, k <= 3 (need not be orthonormal).
        tol: relative tolerance of the rank of ``basis``.

    Returns:
        (3, r) orthonormal canonical basis, r the rank of ``basis`` (singular
        values above ``tol * max(1, sigma_max)``).
    """
    d = np.asarray(basis, float).reshape(3, -1)
    if d.shape[1] == 0:
        return np.zeros((3, 0))
    dec = decide_rank(d.T, tol, at_least=1.0)  # the column span of d: row_space (r, 3), normal(s): null_space
    if dec.rank == 0:
        return np.zeros((3, 0))
    if dec.rank == 3:
        return np.eye(3)
    if dec.rank == 1:
        return clean(positive(dec.row_space[0], tol))[:, None]
    n = dec.null_space[0].tolist()
    norms = [math.sqrt(max(0.0, 1.0 - x * x)) for x in n]
    a = _first_within(norms, tol)
    first = [(float(i == a) - n[a] * x) / norms[a] for i, x in enumerate(n)]
    w = np.array(
        [n[1] * first[2] - n[2] * first[1], n[2] * first[0] - n[0] * first[2], n[0] * first[1] - n[1] * first[0]]
    )
    w /= np.linalg.norm(w)
    b = _first_within(np.abs(w).tolist(), tol)
    picked = sorted([(a, np.array(first)), (b, w if w[b] >= 0 else -w)], key=lambda p: p[0])
    return np.column_stack([clean(v) for _, v in picked])


def _first_within(values: list[float], tol: float) -> int:
    """Index of the first value within ``tol`` of the largest (the greedy's tie rule)."""
    top = max(values) - tol
    return next(i for i, x in enumerate(values) if x > top)


def canonical_directions_greedy(basis: ArrayLike, tol: float = 1e-9) -> Array:
    """:func:`canonical_directions` by its greedy steps, one projection at a time (the reference for the tests)."""
    return canonical_basis(np.asarray(basis, float).reshape(3, -1), tol)


def canonical_basis(basis: ArrayLike, tol: float = 1e-9) -> Array:
    """Canonical orthonormal basis of the column span of ``basis`` (n, k): :func:`canonical_directions`'s greedy in R^n.

    At each step the coordinate axis with the largest projection onto what is left of the subspace
    (the first within ``tol`` of the largest) gives the next vector, that projection normalised, and
    it is removed from the subspace. The vectors are sorted by their axes, each positive on its own
    axis: the result depends only on the subspace (ties go to the earlier axis), not on the basis
    given. Rank decided with ``tol`` at the natural scale 1 (``tol * max(1, sigma_max)``).

    Returns:
        (n, r) orthonormal canonical basis, r the rank of ``basis``.
    """
    d = np.asarray(basis, float)
    rows = d.shape[0]
    if d.size == 0:
        return np.zeros((rows, 0))
    rest = decide_rank(d.T, tol, at_least=1.0).row_space.T  # the column span of d
    picked: list[tuple[int, Array]] = []
    proj = rest @ rest.T  # projector onto what is left of the subspace
    for _ in range(rest.shape[1]):
        norms = np.sqrt((proj * proj).sum(axis=0))
        axis = int(np.argmax(norms > norms.max() - tol))  # first axis within tol of the best
        vec = proj[:, axis] / norms[axis]
        picked.append((axis, vec))
        proj = proj - np.outer(vec, vec)  # vec lies in the subspace: P - vec vec^T projects onto the rest
    if not picked:
        return np.zeros((rows, 0))
    picked.sort(key=lambda p: p[0])
    return np.column_stack([clean(v) for _, v in picked])


def axis_label(direction: ArrayLike, tol: float = 1e-9) -> str:
    """``'x'``, ``'-y'``, ... for a world axis, else the rounded vector."""
    u = np.asarray(direction, float)
    for i, name in enumerate(AXIS_NAMES):
        if abs(abs(u[i]) - 1.0) < tol:
            return name if u[i] > 0 else "-" + name
    return "[" + ", ".join(f"{c:.3g}" for c in u) + "]"


def clean(a: Array, scale: float = 1.0, tol: float = 1e-10) -> Array:
    """Zero the entries of ``a`` below ``tol * scale`` (numerical dust) and drop signed zeros."""
    a = np.where(np.abs(a) < tol * scale, 0.0, a)
    return a + 0.0


def positive(u: Array, tol: float = 1e-9) -> Array:
    """Flip u so that its largest-magnitude component (first on ties) is positive."""
    i = int(np.argmax(np.abs(u) > np.abs(u).max() - tol))
    return u if u[i] >= 0 else -u


def subspace_gap(a: ArrayLike, b: ArrayLike) -> float:
    """Largest sine of the principal angles between the column spans of a and b.

    0 when the spans are equal, 1 when one holds a direction orthogonal to the
    other. Spans of different dimension give 1. Scale the inputs first when they
    mix units.
    """
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    if a.shape[1] != b.shape[1]:
        return 1.0
    if a.shape[1] == 0:
        return 0.0
    qa = np.linalg.qr(a)[0]
    qb = np.linalg.qr(b)[0]
    cos = np.linalg.svd(qa.T @ qb, compute_uv=False)
    return float(np.sqrt(max(0.0, 1.0 - float(np.min(cos)) ** 2)))
