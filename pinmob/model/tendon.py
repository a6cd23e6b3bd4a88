"""Actuators on fixed tendons: an actuator that drives a linear combination of joint values (MJCF ``<fixed>``)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmob.screw.algebra import Array


@dataclass(frozen=True)
class TendonActuator:
    """An actuator on a fixed tendon: it drives, and locked holds, the length ``l = sum_j c_j q_j``.

    MuJoCo's fixed tendon (``<tendon><fixed>``) with an actuator on it (``<general tendon=...>``): the
    actuator acts on ``l``, so locking it holds ``sum_j c_j dq_j = 0``, one row on the joint rates
    instead of one held joint. A hinge's ``c_j`` is in m/rad, a slide's is dimensionless (MuJoCo's
    ``coef``, as compiled).

    Attributes:
        name: the actuator's name.
        tendon: the tendon's name.
        joints: the tendon's joints (one coordinate each: hinges and slides).
        coefficients: ``c_j`` per joint.
    """

    name: str
    tendon: str
    joints: tuple[str, ...]
    coefficients: tuple[float, ...]

    def rate_row(self, model: pin.Model) -> Array:
        """(nv,) the row ``s`` with ``s . dq = dl / dt``: ``c_j`` at each joint's velocity index."""
        row = np.zeros(model.nv)
        for joint, c in zip(self.joints, self.coefficients):
            row[model.joints[model.getJointId(joint)].idx_v] += c
        return row


def tendon_rows(model: pin.Model, tendons: Sequence[TendonActuator], col: Array) -> Array:
    """(k, nv) the rows holding each tendon on the dimensionless joint rates ``x`` (``dq = col x``), unit length.

    A tendon of length ``l = sum_j c_j q_j`` is held when ``sum_j c_j col_j x_j = 0``: its
    :meth:`TendonActuator.rate_row` times ``col``, normalised as a held joint's selector row is (the
    actuation's rank decisions take 1 as the natural scale).
    """
    rows = np.array([t.rate_row(model) * col for t in tendons]).reshape(len(tendons), model.nv)
    norms = np.linalg.norm(rows, axis=1, keepdims=True)
    return rows / np.where(norms > 0, norms, 1.0)
