"""The motion types of many spans of free twists, compiled (numba): the counts of ``classify_twists``' decisions.

:func:`counts` takes, per span, the decisions :func:`pinmob.screw.motion_label.motion_type_of_orthonormal` takes
(the rotation rows below ``rtol``: all translations; else :func:`pinmob.screw.classify._orthonormal_span` and
the steps of :func:`pinmob.screw.screw_groups.screw_groups`: the free translations, the directions with a
component along them, the principal pitches grouped) and counts them as translations, rotations and screws.
The same matrices, the same rank rule (singular values above ``tol * max(1, sigma_1)``, the same tolerances)
and the same pitch grouping; each SVD is the one-sided Jacobi SVD of the batch kernel
(:func:`pinmob.screw.jacobi.span`: LAPACK's singular values and singular vectors to
round-off, no Gram matrix, so no squared condition number), the generalised eigenproblem of the pitches the
numpy path's reduction (Cholesky, then a cyclic Jacobi eigensolver for the symmetric ``L^-1 a L^-T``, at most
3 x 3). The labels are the numpy path's (``tests/test_scan_batch.py`` compares them with
``classify_twists`` on the same spans). Importing this module imports numba.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from pinmob.analysis.batch.small_matrices import EPS, cholesky, cols, mm, solve, symmetric_eig, tr
from pinmob.jit_cache import njit
from pinmob.screw import Array, span

#: The orthonormality test of :func:`pinmob.screw.classify._orthonormal_span` (``m^T m = c I`` to this).
GRAM_TOL = 1e-12


@njit
def _decide(m: Array, tol: float, at_least: float, v: Array) -> int:
    """``decide_rank(m, tol, at_least=at_least)``: the rank of m (r, c), its right singular vectors in ``v`` (c, c).

    The first ``rank`` columns of v span the row space, the others the null space (``row_space.T``,
    ``null_space.T`` of :func:`pinmob.screw.rank.decide_rank`). Singular values beyond ``min(r, c)`` (zero to
    round-off in the Jacobi SVD) are not counted, as LAPACK gives none.
    """
    rows, width = m.shape  # never empty here
    g = m.copy()
    sv = np.zeros(width)
    span(g, rows, tol, sv, v)
    if sv[0] <= 0.0:
        return 0
    bound = tol * max(at_least, sv[0])
    rank = 0
    for j in range(min(rows, width)):
        if sv[j] > bound:
            rank += 1
    return rank


@njit
def counts(spans: Array, dofs: NDArray[np.int64], length: float, rtol: float) -> NDArray[np.int64]:
    """(N, 3) translations, rotations and screws of N spans: ``spans[i][:, :dofs[i]]`` (N, 6, 6), orthonormal, ``[v / L; w]``.

    One loop over the spans, every step of the decisions in its body (module docstring), so that numba compiles
    them once.
    """
    out = np.zeros((spans.shape[0], 3), np.int64)
    u = np.zeros((3, 3))  # right singular vectors of a transposed (3, m): the canonical directions' span
    for idx in range(spans.shape[0]):
        s, k = spans[idx], dofs[idx]
        w_norm = 0.0
        for i in range(3, 6):
            for j in range(k):
                w_norm += s[i, j] * s[i, j]
        if k == 0:
            out[idx, 0], out[idx, 1], out[idx, 2] = 0, 0, 0
            continue
        if np.sqrt(w_norm) <= rtol:  # motion_type_of_orthonormal's closed form: no rotation row, all translations
            out[idx, 0], out[idx, 1], out[idx, 2] = k, 0, 0
            continue
        inverse = 1.0 / length  # the numpy path's round trip through SI units: span / st, then v / L
        m = np.zeros((6, k))
        for j in range(k):
            for i in range(3):
                m[i, j] = (s[i, j] / inverse) / length
            for i in range(3, 6):
                m[i, j] = s[i, j]
        # classify._orthonormal_span: orthogonal columns of one length are rescaled, else the SVD's row space
        gram = mm(tr(m), m)
        c = 0.0
        for j in range(k):
            c += gram[j, j]
        c /= k
        orthonormal = c > 0.0
        if orthonormal:
            for i in range(k):
                for j in range(k):
                    if abs(gram[i, j] / c - (1.0 if i == j else 0.0)) > GRAM_TOL:
                        orthonormal = False
        if orthonormal:
            basis = m / np.sqrt(c)
        else:
            v6 = np.zeros((6, 6))
            r = _decide(tr(m), rtol, 0.0, v6)
            basis = cols(v6, 0, r)
        n = basis.shape[1]
        if n == 0:
            out[idx, 0], out[idx, 1], out[idx, 2] = 0, 0, 0
            continue
        if n == 6:
            out[idx, 0], out[idx, 1], out[idx, 2] = 3, 3, 0
            continue
        # screw_groups
        v, w = basis[:3].copy(), basis[3:].copy()  # row slices of a C array: C-ordered
        tie = max(1e-9, rtol)
        w_norm = 0.0
        for i in range(3):
            for j in range(n):
                w_norm += w[i, j] * w[i, j]
        if np.sqrt(w_norm) <= rtol:
            t = _decide(tr(v), tie, 1.0, u)  # canonical_directions' rank
            out[idx, 0], out[idx, 1], out[idx, 2] = t, 0, 0
            continue
        vw = np.zeros((n, n))
        wr = _decide(w, rtol, 1.0, vw)
        t = 0
        trans = np.zeros((3, 0))
        if wr < n:
            t = _decide(tr(mm(v, cols(vw, wr, n))), tie, 1.0, u)  # u: a basis of the translations' span
            trans = cols(u, 0, t)
        if wr == 0:
            out[idx, 0], out[idx, 1], out[idx, 2] = t, 0, 0
            continue
        row = cols(vw, 0, wr)
        gv, gw = mm(v, row), mm(w, row)
        pitch_tol = max(1e-9, 10.0 * rtol)
        if t:
            vx = np.zeros((wr, wr))
            r1 = _decide(mm(tr(trans), gw), rtol, 1.0, vx)
            x0, x1 = cols(vx, r1, wr), cols(vx, 0, r1)
        else:
            x0, x1 = np.eye(wr), np.zeros((wr, 0))
        rotations = screws = 0
        r0 = x0.shape[1]
        w0 = mm(gw, x0)
        if x1.shape[1]:  # the directions with a component along the translations, less their part in span(w0)
            g1 = mm(gw, x1)
            if r0:
                vq = np.zeros((3, 3))
                g = tr(w0)
                sq = np.zeros(3)
                span(g, r0, 1.0, sq, vq)
                cutoff = max(3, r0) * EPS * sq[0]
                kept = 0
                for j in range(min(r0, 3)):
                    if sq[j] > cutoff:
                        kept += 1
                q = cols(vq, 0, kept)
                g1 = g1 - mm(q, mm(tr(q), g1))
            found = _decide(tr(g1), tie, 1.0, u)
            rotations += found
        if r0:
            sym = 0.5 * (mm(tr(gw), gv) + mm(tr(gv), gw))
            a = mm(mm(tr(x0), sym), x0)
            b = mm(tr(w0), w0)
            low = cholesky(b)
            c2 = solve(low, tr(solve(low, a, True)), True)  # L^-1 a L^-T
            pitches, z = symmetric_eig(0.5 * (c2 + tr(c2)))
            y = solve(tr(low), z, False)  # L^-T z
            i = 0
            while i < r0:
                j = i
                while j + 1 < r0 and abs(pitches[j + 1] - pitches[i]) <= pitch_tol:
                    j += 1
                found = _decide(tr(mm(w0, cols(y, i, j + 1))), tie, 1.0, u)
                pitch = 0.0
                for p in range(i, j + 1):
                    pitch += pitches[p]
                pitch /= j + 1 - i
                if abs(pitch) <= pitch_tol:
                    rotations += found
                else:
                    screws += found
                i = j + 1
        out[idx, 0], out[idx, 1], out[idx, 2] = t, rotations, screws
    return out
