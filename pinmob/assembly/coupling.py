"""Residuals of couplings: closures between coordinates (joint values, tendon lengths), not frames.

MuJoCo's ``<equality joint>`` and ``<equality tendon>`` (``mj_instantiateEquality``): ``x1 - r1 = P(x2 - r2)``
with ``P(x) = sum_k c_k x^k`` (``polycoef``), ``x`` a joint value or a tendon length and ``r`` its value at
``qpos0``; with one coordinate, ``x1 - r1 = c_0``. One row each.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmob.model import Closure
from pinmob.screw import Array, Mask


def polynomial_and_slope(coefficients: tuple[float, ...], x: float) -> tuple[float, float]:
    """``P(x) = sum_k c_k x^k`` and ``P'(x)`` by Horner's rule.

    A coupling's residual is evaluated at every solver step: building ``np.polynomial.Polynomial`` and its
    derivative there cost more than the tendon lengths.
    """
    value = slope = 0.0
    for c in reversed(coefficients):
        slope = slope * x + value
        value = value * x + c
    return value, slope


def coupling_error(model: pin.Model, data: pin.Data, c: Closure) -> tuple[Array, Array, Mask]:
    """Residual ``(q1 - r1) - P(q2 - r2)`` of a ``joint`` closure (``P(x) = sum_k c_k x^k``), its row and mask.

    The joint values are those of the last kinematics (``data.joints[j].joint_q``); the row has 1 at joint
    1's velocity and ``-P'(q2 - r2)`` at joint 2's. It is a length when joint 1 slides.
    """
    j1 = model.getJointId(c.joints[0])
    row = np.zeros((1, model.nv))
    row[0, model.joints[j1].idx_v] = 1.0
    e = float(data.joints[j1].joint_q[0]) - c.reference[0]
    if len(c.joints) > 1:
        j2 = model.getJointId(c.joints[1])
        value, slope = polynomial_and_slope(c.polycoef, float(data.joints[j2].joint_q[0]) - c.reference[1])
        e -= value
        row[0, model.joints[j2].idx_v] -= slope
    else:
        e -= c.polycoef[0]
    linear = "Prismatic" in model.joints[j1].shortname()
    return np.array([e]), row, np.array([linear])


def tendon_error(model: pin.Model, data: pin.Data, c: Closure) -> tuple[Array, Array, Mask]:
    """Residual ``(l1 - r1) - P(l2 - r2)`` of a ``tendon`` closure (MuJoCo's ``mjEQ_TENDON``), its row and mask.

    The lengths and their rows are the tendons' (:meth:`~pinmob.model.tendon.Tendon.length`) at the last
    kinematics; the row is ``dl1/dq - P'(l2 - r2) dl2/dq``. It is a length when tendon 1's length is one.
    """
    l1, row = c.tendons[0].length(model, data)
    e = l1 - c.reference[0]
    if len(c.tendons) > 1:
        l2, row2 = c.tendons[1].length(model, data)
        value, slope = polynomial_and_slope(c.polycoef, l2 - c.reference[1])
        e -= value
        row = row - slope * row2
    else:
        e -= c.polycoef[0]
    return np.array([e]), row.reshape(1, model.nv), np.array([c.tendons[0].linear])
