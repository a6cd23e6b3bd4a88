"""The motion type of a span of twists from the counts alone, for the many samples of a scan.

:func:`motion_type_of_span` counts the decisions :func:`~pinmob.screw.classify.classify_twists` takes (one
function, :func:`~pinmob.screw.screw_groups.screw_groups`: the free translations, the directions with a
component along them, the principal pitches and their groups) as translations, rotations and screws, without
their axes, points and canonical vectors (least squares, closest points, cleaning), which the label does not
read: ``motion_type(classify_twists(t, L, rtol))`` exactly, at about half its cost (``tests/test_scan_batch.py``
compares them).
"""

from __future__ import annotations

import numpy as np

from pinmob.screw.algebra import Array, twist_scaling
from pinmob.screw.classify import _orthonormal_span, screw_groups
from pinmob.screw.rank import RTOL


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
        return label(0, 0, 0)
    span = _orthonormal_span(np.vstack([v, w]), rtol)
    if span.shape[1] == 0:
        return label(0, 0, 0)
    if span.shape[1] == 6:
        return label(3, 3, 0)
    return label(*_counts(span, rtol))


def motion_type_of_orthonormal(span: Array, length: float, rtol: float = RTOL) -> str:
    """The label of an orthonormal span (6, k) of dimensionless twists ``[v / L; w]`` (a batch's free twists).

    One closed form: ``kT`` when the rotation rows are below ``rtol``
    (:func:`pinmob.screw.classify.principal_screws_of_span`'s test: no direction, all free; it answers k = 0 and
    k = 6 itself); else :func:`motion_type_of_span` of the span in SI units.
    :func:`pinmob.analysis.batch.motion_kernel.counts` is this function compiled.
    """
    w = span[3:]
    if span.shape[1] and float(np.sqrt((w * w).sum())) <= rtol:
        return f"{span.shape[1]}T"
    return motion_type_of_span(span / twist_scaling(length)[:, None], length, rtol)


def _counts(span: Array, rtol: float) -> tuple[int, int, int]:
    """Translations, rotations and screws of :func:`~pinmob.screw.classify.screw_groups` (its decisions counted)."""
    trans, _, _, groups = screw_groups(span, rtol)
    pitch_tol = max(1e-9, 10 * rtol)
    rotations = sum(dirs.shape[1] for _, dirs, pitch in groups if abs(pitch) <= pitch_tol)
    screws = sum(dirs.shape[1] for _, dirs, pitch in groups if abs(pitch) > pitch_tol)
    return trans.shape[1], rotations, screws


def label(translations: int, rotations: int, screws: int) -> str:
    """:func:`pinmob.screw.classify.motion_type`'s label of the counts."""
    counts = [(translations, "T"), (rotations, "R"), (screws, "H")]
    return "".join(f"{n}{c}" for n, c in counts if n) or "rigid"
