"""One-sided Jacobi SVDs of small matrices, compiled (numba): the batch kernels' ranks and complements.

* :func:`span`: Jacobi rotations of the columns of a matrix given by its rows (rank, singular values, right
  singular vectors: the row space and the null space);
* :func:`orthogonalize` and :func:`column_rank`: the same rotations on columns 6 long (screws, wrenches), no
  singular vectors kept: the column lengths are the singular values, the long columns the left singular vectors;
  :func:`complete`: the orthogonal complement of columns by Householder reflections.

Rotations of the matrix itself, never of its Gram matrix: the singular values of the matrix to round-off
(LAPACK's: ``tests/test_fast_paths.py``, ``tests/test_batch_kernel.py``), not those of its square, so a rank
decided at ``rtol`` is as sharp as LAPACK's. Importing this module imports numba.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pinmob.jit_cache import njit
from pinmob.screw.algebra import Array

#: Integer array (column orders).
Ints = NDArray[np.int64]

#: Columns count as orthogonal when ``|g_j . g_l| <= ORTHOGONAL * rows * |g_j| |g_l|`` (round-off of the dot product).
ORTHOGONAL = 2.0**-52


@njit
def rotation(alpha: float, beta: float, gamma: float) -> tuple[float, float]:
    """Cosine and sine of the Jacobi rotation that makes two columns orthogonal (a 2 x 2 symmetric matrix diagonal).

    ``alpha``, ``beta``: their squared norms (the diagonal), ``gamma`` their dot product (off it);
    ``t = sign(zeta) / (|zeta| + sqrt(1 + zeta^2))``, ``zeta = (beta - alpha) / (2 gamma)`` (the smaller of the two
    angles; ``t = 1 / (2 zeta)`` where ``zeta^2`` would overflow); ``c = 1 / sqrt(1 + t^2)``, ``s = c t``.
    """
    zeta = (beta - alpha) / (2.0 * gamma)
    if abs(zeta) > 1e150:
        t = 0.5 / zeta
    else:
        t = (1.0 if zeta >= 0.0 else -1.0) / (abs(zeta) + np.sqrt(1.0 + zeta * zeta))
    c = 1.0 / np.sqrt(1.0 + t * t)
    return c, c * t


@njit
def span(g: Array, rows: int, rtol: float, sv: Array, v: Array) -> int:
    """Rank of ``g[:rows]`` (rows, p) by a one-sided Jacobi SVD, in place: singular values ``sv`` (p,), vectors ``v``.

    Plane rotations of pairs of columns (Hestenes) until every pair is
    orthogonal to round-off: ``g V = U diag(sv)``; ``sv`` sorted descending, the
    columns of ``v`` (the right singular vectors) sorted alike: the first ``rank``
    span the row space, the others its complement. Columns shorter than
    round-off of the whole matrix are zero and left alone. ``g[:rows]`` is overwritten
    by ``U diag(sv)`` (its columns sorted alike: ``g[:, j] / sv[j]`` is the j-th left singular vector).
    The rank is :func:`pinmob.screw.rank.rank_rule`'s: the singular values above
    ``rtol`` times the largest (0 when they are all zero).
    """
    p = g.shape[1]
    for i in range(p):
        for j in range(p):
            v[i, j] = 1.0 if i == j else 0.0
    total = 0.0
    for i in range(rows):
        for j in range(p):
            total += g[i, j] * g[i, j]
    negligible = (ORTHOGONAL * ORTHOGONAL) * total  # a column this short is zero to round-off: not rotated
    for _ in range(60):
        rotated = False
        for j in range(p - 1):
            for k in range(j + 1, p):
                alpha = beta = gamma = 0.0
                for i in range(rows):
                    alpha += g[i, j] * g[i, j]
                    beta += g[i, k] * g[i, k]
                    gamma += g[i, j] * g[i, k]
                if gamma == 0.0 or min(alpha, beta) <= negligible:
                    continue
                if abs(gamma) <= ORTHOGONAL * max(rows, 1) * np.sqrt(alpha * beta):
                    continue
                c, s = rotation(alpha, beta, gamma)
                if s == 0.0:
                    continue
                rotated = True
                for i in range(rows):
                    a, b = g[i, j], g[i, k]
                    g[i, j], g[i, k] = c * a - s * b, s * a + c * b
                for i in range(p):
                    a, b = v[i, j], v[i, k]
                    v[i, j], v[i, k] = c * a - s * b, s * a + c * b
        if not rotated:
            break
    for j in range(p):
        norm = 0.0
        for i in range(rows):
            norm += g[i, j] * g[i, j]
        sv[j] = np.sqrt(norm)
    for j in range(1, p):  # insertion sort, descending, columns of v and g alike
        k = j
        while k > 0 and sv[k - 1] < sv[k]:
            sv[k - 1], sv[k] = sv[k], sv[k - 1]
            for i in range(p):
                v[i, k - 1], v[i, k] = v[i, k], v[i, k - 1]
            for i in range(rows):
                g[i, k - 1], g[i, k] = g[i, k], g[i, k - 1]
            k -= 1
    if rows == 0 or sv[0] <= 0.0:
        return 0
    rank = 0
    for x in sv:
        if x > rtol * sv[0]:
            rank += 1
    return rank


@njit
def orthogonalize(g: Array, start: int, stop: int) -> None:
    """One-sided Jacobi on the columns ``g[:, :stop]`` (6, stop) in place, the first ``start`` already orthogonal.

    The rotations of :func:`span` on the columns themselves (screws or wrenches, no singular vectors kept),
    in round-robin order (:func:`round_robin`: consecutive pairs share no column, so the processor overlaps
    them; a third faster than the cyclic order on six columns). Columns ``start ..`` added to columns
    orthogonalised before (with the same singular values as the ones they came from) continue from there:
    the first sweep rotates only the pairs with a new column (the old pairs stay orthogonal until then).
    """
    if stop <= 6:
        first, second = PAIRS[0, stop], PAIRS[1, stop]
    else:
        first, second = round_robin(stop)
    total = 0.0
    for j in range(stop):
        for i in range(6):
            total += g[i, j] * g[i, j]
    negligible = (ORTHOGONAL * ORTHOGONAL) * total  # a column this short is zero to round-off: not rotated
    for sweep in range(60):
        rotated = False
        for pair in range(stop * (stop - 1) // 2):
            j, k = first[pair], second[pair]
            if sweep == 0 and k < start:
                continue
            alpha = beta = gamma = 0.0
            for i in range(6):
                alpha += g[i, j] * g[i, j]
                beta += g[i, k] * g[i, k]
                gamma += g[i, j] * g[i, k]
            if gamma == 0.0 or min(alpha, beta) <= negligible:
                continue
            if gamma * gamma <= (ORTHOGONAL * 6) ** 2 * (alpha * beta):  # span's test, squared
                continue
            c, s = rotation(alpha, beta, gamma)
            if s == 0.0:
                continue
            rotated = True
            for i in range(6):
                a, b = g[i, j], g[i, k]
                g[i, j], g[i, k] = c * a - s * b, s * a + c * b
        if not rotated:  # the first sweep turned nothing: the old columns are still orthogonal
            break


@njit
def round_robin(n: int) -> tuple[Ints, Ints]:
    """Every pair ``j < k`` of n columns once, in rounds of disjoint pairs (the circle method of a tournament)."""
    size = n + n % 2  # odd n: a dummy column sits out one pair per round
    first = np.empty(n * (n - 1) // 2, np.int64)
    second = np.empty(n * (n - 1) // 2, np.int64)
    ring = np.arange(size)
    count = 0
    for _ in range(size - 1):
        for i in range(size // 2):
            a, b = ring[i], ring[size - 1 - i]
            if a < n and b < n:
                first[count], second[count] = min(a, b), max(a, b)
                count += 1
        last = ring[size - 1]  # turn every column but the first one place on
        for i in range(size - 1, 1, -1):
            ring[i] = ring[i - 1]
        ring[1] = last
    return first, second


#: :func:`round_robin` of 0 to 6 columns, ``PAIRS[0, n]`` and ``PAIRS[1, n]`` (the first n (n - 1) / 2 entries).
PAIRS = np.zeros((2, 7, 15), np.int64)
for _n in range(7):
    for _row, _part in enumerate(round_robin.py_func(_n)):
        PAIRS[_row, _n, : _part.size] = _part


@njit
def column_rank(g: Array, m: int, rtol: float, sv: Array, order: Ints) -> int:
    """Singular values (descending, zero beyond m) and rank of the orthogonalised columns ``g[:, :m]``.

    ``order`` gets the columns by length, longest first (the left singular vectors' order). The rank is
    :func:`pinmob.screw.rank.rank_rule`'s: the lengths above ``rtol`` times the longest (0 when all are zero).
    """
    for j in range(sv.size):
        sv[j] = 0.0
        order[j] = j
    for j in range(m):
        norm = 0.0
        for i in range(6):
            norm += g[i, j] * g[i, j]
        sv[j] = np.sqrt(norm)
    for j in range(1, m):  # insertion sort, descending, order alike
        k = j
        while k > 0 and sv[k - 1] < sv[k]:
            sv[k - 1], sv[k] = sv[k], sv[k - 1]
            order[k - 1], order[k] = order[k], order[k - 1]
            k -= 1
    if m == 0 or sv[0] <= 0.0:
        return 0
    rank = 0
    for j in range(m):
        if sv[j] > rtol * sv[0]:
            rank += 1
    return rank


@njit
def complete(g: Array, order: Ints, rank: int, out: Array, first: int, rows: bool) -> int:
    """The orthogonal complement of the ``rank`` longest orthogonalised columns of g, orthonormal, into ``out``.

    Householder reflections of the unit columns ``u_1 .. u_r`` (QR of U): the last ``6 - r`` columns of Q
    span what is orthogonal to them, written as rows ``out[first:]`` (``rows``) or columns ``out[:, first:]``.

    Returns:
        6 - rank, the number written.
    """
    u = np.zeros((6, rank))
    for c in range(rank):
        norm = 0.0
        for i in range(6):
            norm += g[i, order[c]] * g[i, order[c]]
        norm = np.sqrt(norm)
        for i in range(6):
            u[i, c] = g[i, order[c]] / norm
    h = np.zeros((6, rank))  # reflector vectors, h[c:, c]
    beta = np.zeros(rank)
    for c in range(rank):
        norm = 0.0
        for i in range(c, 6):
            norm += u[i, c] * u[i, c]
        norm = np.sqrt(norm)
        for i in range(c, 6):
            h[i, c] = u[i, c]
        h[c, c] += norm if u[c, c] >= 0.0 else -norm
        hh = 0.0
        for i in range(c, 6):
            hh += h[i, c] * h[i, c]
        beta[c] = 2.0 / hh if hh > 0.0 else 0.0
        for d in range(c + 1, rank):  # reflect the later columns
            dot = 0.0
            for i in range(c, 6):
                dot += h[i, c] * u[i, d]
            dot *= beta[c]
            for i in range(c, 6):
                u[i, d] -= dot * h[i, c]
    q = np.zeros(6)
    for e in range(rank, 6):  # Q e_e = H_1 ... H_r e_e
        for i in range(6):
            q[i] = 1.0 if i == e else 0.0
        for c in range(rank - 1, -1, -1):
            dot = 0.0
            for i in range(c, 6):
                dot += h[i, c] * q[i]
            dot *= beta[c]
            for i in range(c, 6):
                q[i] -= dot * h[i, c]
        for i in range(6):
            if rows:
                out[first + e - rank, i] = q[i]
            else:
                out[i, first + e - rank] = q[i]
    return 6 - rank
