"""The decisions that classify a span of twists: free translations, then screws grouped by pitch.

Steps 1-3 of :func:`pinmob.screw.classify.principal_screws_of_span` (its module docstring): the free
translations, the directions with a component along them (pitch 0), and the principal pitches of the others,
equal pitches (within ``10 rtol``) grouped. :func:`~pinmob.screw.classify.principal_screws_of_span` places each
group's screws (axes, points); :func:`~pinmob.screw.motion_label.motion_type_of_span` only counts them. One
function for both, so that a scan's motion type and the report's are the same decisions.
"""

from __future__ import annotations

import numpy as np

from pinmob.screw.algebra import Array
from pinmob.screw.bases import canonical_directions
from pinmob.screw.rank import RTOL, decide_rank


def screw_groups(
    span: Array, rtol: float = RTOL
) -> tuple[Array, Array, Array, list[tuple[Array | None, Array, float]]]:
    """The decisions of :func:`principal_screws_of_span` (steps 1-3), before any axis or point is computed.

    Returns:
        the free translations (3, t) (canonical directions), the complement's moments ``gv`` and directions ``gw``,
        and each group of screws of one pitch: ``(basis, dirs, pitch)``, its directions ``dirs`` (canonical), the
        complement's coefficients ``basis @ lstsq(gw @ basis, dirs)`` (``basis`` None: the identity) and its
        pitch (0 for the directions with a component along the translations). :func:`motion_type_of_span
        <pinmob.screw.motion_label.motion_type_of_span>` counts them, :func:`principal_screws_of_span` places them.
    """
    v, w = span[:3], span[3:]
    tie = max(1e-9, rtol)  # components of unit directions closer than this are ties (round-off must not pick)
    empty = np.zeros((3, 0))
    if float(np.sqrt((w * w).sum())) <= rtol:  # every singular value of w is below rtol: no direction, all free
        return canonical_directions(v, tie), empty, empty, []
    split = decide_rank(w, rtol, at_least=1.0)  # directions of the orthonormal span: natural scale 1
    wr = split.rank
    trans = canonical_directions(v @ split.null_space.T, tie) if wr < w.shape[1] else empty
    if wr == 0:
        return trans, empty, empty, []
    gv, gw = v @ split.row_space.T, w @ split.row_space.T  # complement: span(gw) has dimension wr
    pitch_tol = max(1e-9, 10 * rtol)
    # split span(gw) into W0 (perpendicular to T) and its orthogonal complement W1
    if trans.shape[1]:
        dec = decide_rank(trans.T @ gw, rtol, n=wr, at_least=1.0)  # orthonormal span and directions: natural scale 1
        x0, x1 = dec.null_space.T, dec.row_space.T
    else:
        x0, x1 = np.eye(wr), np.zeros((wr, 0))
    groups: list[tuple[Array | None, Array, float]] = []
    if x1.shape[1]:
        # W1 directions, orthogonal to W0 in direction space, all with pitch 0
        w0 = gw @ x0
        groups.append(
            (None, canonical_directions(gw @ x1 - (w0 @ np.linalg.pinv(w0) @ (gw @ x1) if w0.size else 0), tie), 0.0)
        )
    if x0.shape[1]:
        a = x0.T @ (0.5 * (gw.T @ gv + gv.T @ gw)) @ x0
        b = x0.T @ gw.T @ gw @ x0
        pitches, y = _generalised_eigh(a, b)
        i = 0
        while i < len(pitches):
            j = i
            while j + 1 < len(pitches) and abs(pitches[j + 1] - pitches[i]) <= pitch_tol:
                j += 1
            group = x0 @ y[:, i : j + 1]
            groups.append((group, canonical_directions(gw @ group, tie), float(np.mean(pitches[i : j + 1]))))
            i = j + 1
    return trans, gv, gw, groups


def _generalised_eigh(a: Array, b: Array) -> tuple[Array, Array]:
    """Eigenvalues (ascending) and B-orthonormal eigenvectors of ``a x = h b x`` (symmetric a, positive definite b).

    LAPACK's reduction (``dsygv``, what SciPy's ``eigh(a, b)`` calls), with numpy: ``b = L L^T``
    (Cholesky), the eigenpairs ``(h, z)`` of the symmetric ``L^-1 a L^-T``, and ``x = L^-T z``
    (so that ``x^T b x = I``).
    """
    low = np.linalg.cholesky(b)
    c = np.linalg.solve(low, np.linalg.solve(low, a).T)  # L^-1 a L^-T (a is symmetric)
    vals, z = np.linalg.eigh(0.5 * (c + c.T))
    return np.asarray(vals, dtype=np.float64), np.asarray(np.linalg.solve(low.T, z), dtype=np.float64)
