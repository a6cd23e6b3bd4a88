"""Twists and wrenches: the conventions, reciprocity, shifts and unit scaling.

Pure numpy; this package does not import pinocchio.

Conventions (used everywhere in pinmob, never switched silently):

* A twist is ``t = [v; w]`` (linear velocity of the body point at the reference
  origin first, angular velocity second), Pinocchio's ``Motion`` order.
* A wrench is ``f = [f; tau]`` (force first, moment about the reference origin
  second), Pinocchio's ``Force`` order.
* The reciprocal product is the power ``f . v + tau . w``, i.e. the plain dot
  product ``wrench @ twist`` in this order. A wrench is reciprocal to (constrains
  nothing along) a twist when that product is zero.
* The seed paper writes twists axis first, ``(w; v)``; convert with
  :func:`twist_from_paper` only where comparing with its matrices.

Unit invariance: with a characteristic length ``L`` [m], a twist is made
dimensionless as ``[v / L; w]`` and a wrench as ``[f * L; tau]``. The product is
unchanged, and a mechanism scaled by ``k`` with ``L`` scaled by ``k`` gives the
same dimensionless matrices, hence the same ranks.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: Float array (twists, wrenches, configurations).
Array = NDArray[np.float64]
#: Boolean array, e.g. which rows of a residual are lengths.
Mask = NDArray[np.bool_]


def reciprocal_product(wrench: ArrayLike, twist: ArrayLike) -> float:
    """Power of a wrench on a twist: ``f . v + tau . w`` [W for SI units]."""
    return float(np.dot(np.asarray(wrench, float), np.asarray(twist, float)))


def twist_from_paper(s: ArrayLike) -> Array:
    """Convert the seed paper's axis-first twist ``(w; v)`` to ``[v; w]``; rows of 6 (shape (..., 6))."""
    s = np.asarray(s, float)
    return np.concatenate([s[..., 3:], s[..., :3]], axis=-1)


def twist_to_paper(t: ArrayLike) -> Array:
    """Convert twists ``[v; w]`` to the seed paper's axis-first ``(w; v)``; rows of 6 (the inverse swap)."""
    return twist_from_paper(t)


def shift_twists(twists: ArrayLike, r: ArrayLike) -> Array:
    """Express twists at a point displaced by ``r`` from their reference point.

    ``v' = v + w x r``, ``w' = w``.

    Args:
        twists: (6,) or (6, k) twists ``[v; w]``.
        r: (3,) displacement from the old to the new reference point [m].
    """
    t = np.array(twists, float)
    r = np.asarray(r, float)
    if t.ndim == 2 and r.ndim == 1:
        r = r[:, None]
    t[:3] = t[:3] + cross_columns(t[3:], r)
    return t


def shift_wrenches(wrenches: ArrayLike, r: ArrayLike) -> Array:
    """Express wrenches at a point displaced by ``r``: ``tau' = tau - r x f``."""
    f = np.array(wrenches, float)
    r = np.asarray(r, float)
    if f.ndim == 2 and r.ndim == 1:
        r = r[:, None]
    f[3:] = f[3:] - cross_columns(r, f[:3])
    return f


def rotate(screws: ArrayLike, rotation: ArrayLike) -> Array:
    """Rotate the axes of twists or wrenches (6,) or (6, k) by a (3, 3) rotation."""
    s = np.array(screws, float)
    rot = np.asarray(rotation, float)
    s[:3] = rot @ s[:3]
    s[3:] = rot @ s[3:]
    return s


def twist_scaling(length: float) -> Array:
    """Diagonal (6,) that makes twists dimensionless: ``[v / L; w]``."""
    return np.array([1 / length] * 3 + [1.0] * 3)


def wrench_scaling(length: float) -> Array:
    """Diagonal (6,) that makes wrenches dimensionless: ``[f * L; tau]``."""
    return np.array([length] * 3 + [1.0] * 3)


def cross_columns(a: Array, b: Array) -> Array:
    """Column-wise cross product of (3,) or (3, k) arrays, ``np.cross(a, b, axis=0)`` without its axis shuffling.

    Same formula, ``(a1 b2 - a2 b1, a2 b0 - a0 b2, a0 b1 - a1 b0)``, hence the same floating-point results.
    """
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])
