"""How far the platform moved between two poses, and how far off an intended motion (unit-invariant)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmob.assembly import CLOSURE_TOL
from pinmob.screw import Array, twist_scaling


@dataclass(frozen=True)
class Displacement:
    """How far the platform went from the start, measured on its poses.

    Each value is given to the resolution the closure tolerance ``tol`` allows (poses are closed to
    ``tol L`` and ``tol`` rad, so smaller values are noise of the solver and read 0): translation below
    ``tol L``, rotation below ``tol``, and deviation below ``tol L / |achieved|`` (the angle a pose error of
    ``tol`` can make over the displacement, W metric) count as 0.

    Attributes:
        translation: ``|p_end - p_0|`` [m] (platform origin).
        rotation: ``|log3(R_0^T R_end)|`` [rad].
        deviation: angle [rad] in the metric W between the achieved displacement
            twist (``log6(M_0^-1 M_end)``, at the start origin, world axes) and the
            intended motion's twist; 0 when the platform did not move.
    """

    translation: float
    rotation: float
    deviation: float

    def to_dict(self) -> dict[str, float]:
        """``{translation, rotation, deviation}`` (plain JSON)."""
        return {"translation": self.translation, "rotation": self.rotation, "deviation": self.deviation}


def displacement(a: pin.SE3, b: pin.SE3) -> Array:
    """Twist [v; w] at a's origin, world axes, that carries pose a to pose b in unit time."""
    local = pin.log6(a.actInv(b)).vector
    rot = a.rotation
    return np.concatenate([rot @ local[:3], rot @ local[3:]])


def angle_between(a: Array, b: Array) -> float:
    """Angle [rad] between two vectors; 0 when either is zero.

    ``2 atan2(|u - v|, |u + v|)`` of the unit vectors u, v: accurate to round-off also for nearly parallel
    vectors, where ``arccos(u . v)`` loses half the digits (1e-8 rad of noise).
    """
    na, nb = float(np.linalg.norm(a)), float(np.linalg.norm(b))
    if na == 0.0 or nb == 0.0:
        return 0.0
    u, v = a / na, b / nb
    return float(2.0 * np.arctan2(np.linalg.norm(u - v), np.linalg.norm(u + v)))


def measure_displacement(
    start: pin.SE3, end: pin.SE3, twist: Array, length: float, tol: float = CLOSURE_TOL
) -> Displacement:
    """:class:`Displacement` from pose ``start`` to ``end`` against the intended ``twist`` (6,) at start's origin.

    Args:
        start: the platform's first pose.
        end: its last pose.
        twist: (6,) the intended motion ``[v; w]`` at start's origin, world axes.
        length: L [m].
        tol: the closure tolerance the poses were closed to (dimensionless): the resolution of the values.
    """
    w = twist_scaling(length)
    achieved = w * displacement(start, end)
    translation = float(np.linalg.norm(end.translation - start.translation))
    rotation = float(np.linalg.norm(pin.log3(start.rotation.T @ end.rotation)))
    size = float(np.linalg.norm(achieved))
    deviation = angle_between(achieved, w * twist)
    return Displacement(
        translation if translation > tol * length else 0.0,
        rotation if rotation > tol else 0.0,
        deviation if size > 0 and deviation > tol / size else 0.0,
    )
