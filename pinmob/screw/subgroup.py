"""The motion subgroup a set of joint screws spans: planar, spherical, translational, ... or all of SE(3).

A mechanism whose joint screws span a subspace ``S`` of dimension ``d < 6`` that is closed under the Lie
bracket (a subalgebra: ``[a, b]`` in ``S`` for every ``a, b`` in ``S``) moves within the subgroup
``exp(S)`` at every configuration it reaches, not only to first order: a planar linkage stays planar. There,
a loop closure's six spatial equations hold at most ``d`` independent ones, which is why the spatial
Grubler-Kutzbach count of a planar mechanism comes out too low.

The subgroups named (``d``: dimension, ``t``: its pure translations ``dim(S ∩ {w = 0})``):

- ``planar`` (d 3, t 2, the rotations about the normal of the translations' plane);
- ``spherical`` (d 3, t 0: rotations about one point);
- ``translational`` (t = d);
- ``cylindrical`` (d 2, t 1: a rotation about the translation's direction);
- ``Schoenflies`` (d 4, t 3: the translations and rotations about one direction);
- otherwise ``<d>-dimensional``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinmob.screw.algebra import Array
from pinmob.screw.lie import bracket
from pinmob.screw.rank import RTOL, decide_rank


@dataclass(frozen=True)
class MotionSubgroup:
    """A proper motion subgroup spanned by joint screws.

    Attributes:
        dimension: ``d`` (1 to 5).
        translations: its pure translations ``t``.
        name: ``planar``, ``spherical``, ``translational``, ``cylindrical``, ``Schoenflies`` or ``<d>-dimensional``.
    """

    dimension: int
    translations: int
    name: str


def motion_subgroup(twists: Array, rtol: float = RTOL) -> MotionSubgroup | None:
    """The proper motion subgroup the dimensionless twists ``[v / L; w]`` (6, n) span, or None.

    None: their span is all of se(3), or it is not a subalgebra (the motions it allows to first order are not
    confined to it). Ranks are decided with ``rtol`` relative to the largest singular value; the span is a subalgebra when every
    bracket of its orthonormal basis leaves it by less than ``rtol`` (the basis has unit twists, so their brackets
    are of order 1).
    """
    span = decide_rank(np.asarray(twists, float).T, rtol, 6)
    d = span.rank
    if d in (0, 6):
        return None
    basis = span.row_space  # (d, 6) orthonormal rows
    i, j = np.triu_indices(d, 1)
    brackets = bracket(basis[i], basis[j])
    outside = brackets - (brackets @ basis.T) @ basis
    if outside.size and float(np.abs(outside).max()) > rtol:
        return None
    rotations = decide_rank(basis[:, 3:], rtol, 3, at_least=1.0)  # the span's angular parts
    t = d - rotations.rank
    names = {(3, 2): "planar", (3, 0): "spherical", (2, 1): "cylindrical", (4, 3): "Schoenflies"}
    name = "translational" if t == d else names.get((d, t), f"{d}-dimensional")
    if name == "planar":  # closed: the rotation is normal to the translations' plane; planar if it has no pitch
        axis = rotations.row_space[0]
        turning = np.linalg.lstsq(basis[:, 3:].T, axis, rcond=None)[0] @ basis  # the twist with w = axis
        if abs(float(turning[:3] @ axis)) > np.sqrt(rtol):  # a screw about the normal: a helical group
            name = f"{d}-dimensional"
    return MotionSubgroup(d, t, name)
