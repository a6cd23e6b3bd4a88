"""The motion type of a span of twists from the counts alone, for the many samples of a scan.

:func:`motion_type_of_span` takes the decisions of :func:`~pinmob.screw.classify.classify_twists`, that is of
:func:`~pinmob.screw.classify.principal_screws` (the same calls on the same matrices, in the same order: the
free translations, the directions with a component along them, the principal pitches and their groups) and
counts translations, rotations and screws, without their axes, points and canonical vectors (least squares,
closest points, cleaning), which the label does not read: ``motion_type(classify_twists(t, L, rtol))``
exactly, at about half its cost (``tests/test_scan_batch.py`` compares them).
"""

from __future__ import annotations

import numpy as np

from pinmob.screw.algebra import Array
from pinmob.screw.bases import canonical_directions
from pinmob.screw.classify import _generalised_eigh, _orthonormal_span
from pinmob.screw.rank import RTOL, decide_rank


def motion_type_of_span(twists: Array, length: float, rtol: float = RTOL) -> str:
    """``motion_type(classify_twists(twists, length, rtol))``: ``3T``, ``1T2R``, ``rigid``... (module docstring).

    Args:
        twists: (6, k) basis ``[v; w]`` in SI units.
        length: characteristic length L [m].
        rtol: relative tolerance for ranks and for a zero pitch (pitch/L).
    """
    t = np.asarray(twists, float).reshape(6, -1)
    v, w = t[:3] / length, t[3:]
    if v.shape[1] == 0:
        return _label(0, 0, 0)
    span = _orthonormal_span(np.vstack([v, w]), rtol)
    if span.shape[1] == 0:
        return _label(0, 0, 0)
    if span.shape[1] == 6:
        return _label(3, 3, 0)
    return _label(*_counts(span, rtol))


def _counts(span: Array, rtol: float) -> tuple[int, int, int]:
    """Translations, rotations and screws of :func:`~pinmob.screw.classify.principal_screws_of_span` (6, r)."""
    v, w = span[:3], span[3:]
    tie = max(1e-9, rtol)
    if float(np.sqrt((w * w).sum())) <= rtol:
        return canonical_directions(v, tie).shape[1], 0, 0
    split = decide_rank(w, rtol, at_least=1.0)
    wr = split.rank
    trans = canonical_directions(v @ split.null_space.T, tie) if wr < w.shape[1] else np.zeros((3, 0))
    if wr == 0:
        return trans.shape[1], 0, 0
    gv, gw = v @ split.row_space.T, w @ split.row_space.T
    pitch_tol = max(1e-9, 10 * rtol)
    if trans.shape[1]:
        dec = decide_rank(trans.T @ gw, rtol, n=wr, at_least=1.0)
        x0, x1 = dec.null_space.T, dec.row_space.T
    else:
        x0, x1 = np.eye(wr), np.zeros((wr, 0))
    rotations = screws = 0
    if x1.shape[1]:  # zero-pitch directions with a component along the translations
        w0 = gw @ x0
        rotations += canonical_directions(gw @ x1 - (w0 @ np.linalg.pinv(w0) @ (gw @ x1) if w0.size else 0), tie).shape[
            1
        ]
    if x0.shape[1]:
        a = x0.T @ (0.5 * (gw.T @ gv + gv.T @ gw)) @ x0
        b = x0.T @ gw.T @ gw @ x0
        pitches, y = _generalised_eigh(a, b)
        i = 0
        while i < len(pitches):
            j = i
            while j + 1 < len(pitches) and abs(pitches[j + 1] - pitches[i]) <= pitch_tol:
                j += 1
            count = canonical_directions(gw @ (x0 @ y[:, i : j + 1]), tie).shape[1]
            if abs(float(np.mean(pitches[i : j + 1]))) <= pitch_tol:
                rotations += count
            else:
                screws += count
            i = j + 1
    return trans.shape[1], rotations, screws


def _label(translations: int, rotations: int, screws: int) -> str:
    """:func:`pinmob.screw.classify.motion_type`'s label of the counts."""
    counts = [(translations, "T"), (rotations, "R"), (screws, "H")]
    return "".join(f"{n}{c}" for n, c in counts if n) or "rigid"
