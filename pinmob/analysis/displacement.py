"""How far the platform moved between two poses, and how far off an intended motion (unit-invariant)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmob.screw.algebra import Array, twist_scaling


@dataclass(frozen=True)
class Displacement:
    """How far the platform went from the start, measured on its poses.

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
    """Angle [rad] between two vectors; 0 when either is zero."""
    na, nb = float(np.linalg.norm(a)), float(np.linalg.norm(b))
    if na == 0.0 or nb == 0.0:
        return 0.0
    return float(np.arccos(np.clip(a @ b / (na * nb), -1.0, 1.0)))


def measure_displacement(start: pin.SE3, end: pin.SE3, twist: Array, length: float) -> Displacement:
    """:class:`Displacement` from pose ``start`` to ``end`` against the intended ``twist`` (6,) at start's origin."""
    w = twist_scaling(length)
    return Displacement(
        float(np.linalg.norm(end.translation - start.translation)),
        float(np.linalg.norm(pin.log3(start.rotation.T @ end.rotation))),
        angle_between(w * displacement(start, end), w * twist),
    )
