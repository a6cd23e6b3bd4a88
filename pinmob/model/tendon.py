"""Tendons and transmissions: lengths that couple joints (MJCF ``<tendon>``) and actuators that act through them.

A tendon has a length ``l(q)`` and a row ``dl/dq`` on the joint rates (``dl/dt = row . v``). A fixed tendon
(``<tendon><fixed>``) is a linear combination of joint values, ``l = sum_j c_j q_j``, computed here; a
spatial one (routed over sites and wrapping geoms) is MuJoCo's (``ten_length``, ``ten_J``; see
:mod:`pinmob.io.mjcf.mjcf_tendons`). A tendon equality is a closure between tendon lengths
(:func:`pinmob.model.closure.make_tendon_coupling`).

An actuator held with the actuated joints is a :class:`Transmission`: locked, it holds ``row . v = 0`` where
``row`` is its moment arms at the configuration (MuJoCo's ``actuator_moment``): for an actuator on a fixed
tendon, the tendon's coefficients (:class:`TendonActuator`); for one on a spatial tendon, a site, a
slider-crank or a ball joint, MuJoCo's row at q.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Sequence
from dataclasses import dataclass
from typing import ClassVar

import numpy as np
import pinocchio as pin

from pinmob.model.joints import joint_id
from pinmob.screw import Array


class Transmission(ABC):
    """An actuator held through its moment arms: locked, ``row(q) . v = 0`` (one row on the joint rates).

    Attributes:
        name: the actuator's name.
        kind: what it drives: ``tendon``, ``site``, ``slider-crank``, ``ball joint`` or ``orientation`` (one
            component of an orientation servo).
    """

    name: str
    kind: str

    @abstractmethod
    def rate_row(self, model: pin.Model, q: Array) -> Array:
        """(nv,) the actuator's moment arms at q: ``row . v`` is the rate of what it drives."""

    def driven_tendon(self, model: pin.Model) -> Tendon | None:
        """The tendon or length it drives (held: keeps), or None (a site without a reference site, a free joint)."""
        return None


class Tendon(ABC):
    """A tendon's length as a function of the configuration (see the module docstring).

    Attributes:
        name: the tendon's name.
        linear: its length is in metres (a spatial tendon, or a fixed one over a slide); else it is a
            combination of angles.
        noun, unwritten_why: what a report calls it, and why its higher derivatives are not written when
            they are not (:func:`pinmob.analysis.finite.sampled_side.unwritten`).
    """

    name: str
    linear: bool
    noun: ClassVar[str] = "tendon"
    unwritten_why: ClassVar[str] = "wrapping geoms or over a pulley"

    @abstractmethod
    def length(self, model: pin.Model, data: pin.Data) -> tuple[float, Array]:
        """The length and its (nv,) row ``dl/dq`` at the configuration of the last kinematics in ``data``."""

    @abstractmethod
    def joint_ids(self, model: pin.Model) -> frozenset[int]:
        """The joints whose motion can change the length."""

    def site_frames(self) -> tuple[int, ...]:
        """Frame indices of the sites the tendon runs straight between, in order (empty: not such a tendon).

        Such a tendon's length is ``sum_i |p_(i+1) - p_i|`` over these frames' origins.
        """
        return ()


@dataclass(frozen=True)
class FixedTendon(Tendon):
    """MuJoCo's fixed tendon: ``l = sum_j c_j q_j`` over one-degree joints (``coef`` per joint, as compiled).

    Attributes:
        name: the tendon's name.
        joints: its joints (hinges and slides).
        coefficients: ``c_j`` per joint.
        linear: the length is in metres (a slide among the joints).
    """

    name: str
    joints: tuple[str, ...]
    coefficients: tuple[float, ...]
    linear: bool = False

    def row(self, model: pin.Model) -> Array:
        """(nv,) ``c_j`` at each joint's velocity index."""
        row = np.zeros(model.nv)
        for joint, c in zip(self.joints, self.coefficients):
            row[model.joints[joint_id(model, joint, self.name)].idx_v] += c
        return row

    def length(self, model: pin.Model, data: pin.Data) -> tuple[float, Array]:
        """``sum_j c_j q_j`` from the joint values of the last kinematics, and :meth:`row`."""
        ids = [joint_id(model, j, self.name) for j in self.joints]
        value = sum(c * float(data.joints[j].joint_q[0]) for j, c in zip(ids, self.coefficients))
        return float(value), self.row(model)

    def joint_ids(self, model: pin.Model) -> frozenset[int]:
        """The tendon's joints."""
        return frozenset(joint_id(model, j, self.name) for j in self.joints)


@dataclass(frozen=True)
class TendonActuator(Transmission):
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
    kind: str = "tendon"

    def rate_row(self, model: pin.Model, q: Array | None = None) -> Array:
        """(nv,) the row ``s`` with ``s . dq = dl / dt``: ``c_j`` at each joint's velocity index (any q)."""
        return FixedTendon(self.tendon, self.joints, self.coefficients).row(model)

    def driven_tendon(self, model: pin.Model) -> Tendon | None:
        """Its fixed tendon (a length in metres when a slide is among its joints)."""
        linear = any("Prismatic" in model.joints[joint_id(model, j, self.name)].shortname() for j in self.joints)
        return FixedTendon(self.tendon, self.joints, self.coefficients, linear)


def tendon_rows(model: pin.Model, tendons: Sequence[Transmission], q: Array, col: Array) -> Array:
    """(k, nv) the rows holding each actuator on the dimensionless joint rates ``x`` (``dq = col x``), unit length.

    An actuator is held when ``row(q) . (col x) = 0``: its :meth:`Transmission.rate_row` at q times ``col``,
    normalised as a held joint's selector row is (the actuation's rank decisions take 1 as the natural
    scale; a row MuJoCo gives as zero stays zero: the actuator moves nothing there).
    """
    rows = np.array([t.rate_row(model, q) * col for t in tendons]).reshape(len(tendons), model.nv)
    norms = np.linalg.norm(rows, axis=1, keepdims=True)
    return rows / np.where(norms > 0, norms, 1.0)


def joint_configuration(model: pin.Model, data: pin.Data) -> Array:
    """(nq,) the configuration of the last kinematics in ``data``, gathered from each joint's ``joint_q``."""
    q = np.zeros(model.nq)
    for j in range(1, model.njoints):
        joint = model.joints[j]
        q[joint.idx_q : joint.idx_q + joint.nq] = np.asarray(data.joints[j].joint_q).reshape(-1)
    return q
