"""Small dense matrices, compiled (numba): the motion-type kernel's products, Cholesky and eigenproblem.

:func:`mm`, :func:`tr` and :func:`cols` (products, transposes and column slices as new C-ordered arrays, plain
loops: no BLAS call per tiny product), :func:`cholesky`, :func:`solve` (triangular) and :func:`symmetric_eig`
(cyclic Jacobi rotations of a symmetric matrix, at most 3 x 3 here). Importing this module imports numba.
"""

from __future__ import annotations

import numpy as np

from pinmob.jit_cache import njit
from pinmob.screw import Array, rotation

#: The unit round-off of a double (an off-diagonal entry below it times both diagonals cannot change them).
EPS = 2.0**-52


@njit
def mm(a: Array, b: Array) -> Array:
    """``a @ b`` of small matrices (a plain loop: no BLAS call per tiny product)."""
    n, k = a.shape
    m = b.shape[1]
    out = np.zeros((n, m))
    for i in range(n):
        for j in range(m):
            s = 0.0
            for p in range(k):
                s += a[i, p] * b[p, j]
            out[i, j] = s
    return out


@njit
def tr(a: Array) -> Array:
    """``a.T`` as a new C-ordered array."""
    n, m = a.shape
    out = np.zeros((m, n))
    for i in range(n):
        for j in range(m):
            out[j, i] = a[i, j]
    return out


@njit
def cols(a: Array, start: int, stop: int) -> Array:
    """``a[:, start:stop]`` as a new C-ordered array."""
    out = np.zeros((a.shape[0], stop - start))
    for i in range(a.shape[0]):
        for j in range(start, stop):
            out[i, j - start] = a[i, j]
    return out


@njit
def cholesky(b: Array) -> Array:
    """Lower-triangular L with ``L L^T = b`` (symmetric positive definite, n <= 3)."""
    n = b.shape[0]
    low = np.zeros((n, n))
    for j in range(n):
        s = b[j, j]
        for k in range(j):
            s -= low[j, k] * low[j, k]
        low[j, j] = np.sqrt(s)
        for i in range(j + 1, n):
            s = b[i, j]
            for k in range(j):
                s -= low[i, k] * low[j, k]
            low[i, j] = s / low[j, j]
    return low


@njit
def solve(t: Array, a: Array, lower: bool) -> Array:
    """``T^-1 a`` for a triangular T: forward substitution when ``lower``, else back substitution."""
    n, m = a.shape
    x = np.zeros((n, m))
    for c in range(m):
        for step in range(n):
            i = step if lower else n - 1 - step
            s = a[i, c]
            for k in range(n):
                if (k < i) if lower else (k > i):
                    s -= t[i, k] * x[k, c]
            x[i, c] = s / t[i, i]
    return x


@njit
def symmetric_eig(c: Array) -> tuple[Array, Array]:
    """Ascending eigenvalues and orthonormal eigenvectors (columns) of a small symmetric matrix: cyclic Jacobi."""
    n = c.shape[0]
    a = c.copy()
    z = np.eye(n)
    for _ in range(60):
        off = 0.0
        for p in range(n):
            for q in range(p + 1, n):
                off += abs(a[p, q])
        if off == 0.0:
            break
        for p in range(n):
            for q in range(p + 1, n):
                apq = a[p, q]
                if apq == 0.0:
                    continue
                if abs(apq) <= EPS * 0.5 * min(abs(a[p, p]), abs(a[q, q])):  # below round-off of both diagonals
                    a[p, q] = a[q, p] = 0.0
                    continue
                cs, sn = rotation(a[p, p], a[q, q], apq)
                for k in range(n):  # a <- a J (columns p, q)
                    akp, akq = a[k, p], a[k, q]
                    a[k, p], a[k, q] = cs * akp - sn * akq, sn * akp + cs * akq
                for k in range(n):  # a <- J^T a (rows p, q)
                    apk, aqk = a[p, k], a[q, k]
                    a[p, k], a[q, k] = cs * apk - sn * aqk, sn * apk + cs * aqk
                a[p, q] = a[q, p] = 0.0
                for k in range(n):
                    zkp, zkq = z[k, p], z[k, q]
                    z[k, p], z[k, q] = cs * zkp - sn * zkq, sn * zkp + cs * zkq
    vals = np.zeros(n)
    for i in range(n):
        vals[i] = a[i, i]
    order = np.argsort(vals)
    vecs = np.zeros((n, n))
    for j in range(n):
        for i in range(n):
            vecs[i, j] = z[i, order[j]]
    return vals[order], vecs
