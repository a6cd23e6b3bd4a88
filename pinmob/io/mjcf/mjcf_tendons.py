"""MJCF tendons and actuators as MuJoCo moves them: tendon equalities as closures, actuators as held rows.

Tendon equality (``<equality tendon>``, MuJoCo's ``mjEQ_TENDON`` in ``mj_instantiateEquality``), on any
tendon, fixed or spatial: ``l1 - l1_0 = sum_k polycoef_k (l2 - l2_0)^k`` with ``l`` the tendon's length
(``ten_length``) and ``l_0`` its length at ``qpos0`` (``tendon_length0``); with one tendon,
``l1 - l1_0 = polycoef_0``. A fixed tendon's length ``sum_j coef_j qpos_j`` is a
:class:`~pinmob.model.tendon.FixedTendon`; a spatial one (sites, wrapping geoms, pulleys) a
:class:`SpatialTendon` whose length and row are MuJoCo's ``ten_length`` and ``ten_J`` at the configuration.

Actuators (MuJoCo's transmissions): one on a hinge or slide (``joint``, ``jointinparent``) actuates its
joint; one on a fixed tendon is a :class:`~pinmob.model.tendon.TendonActuator`; one on a spatial tendon, a
site, a slider-crank or a ball or free joint is a :class:`MomentActuator`, held as MuJoCo's moment arms
at the configuration (its row of ``actuator_moment``); the finite analysis holds what it drives at its length
(the tendon's, or :mod:`pinmob.io.mjcf.actuator_lengths`). An orientation servo (MuJoCo's ``mjTRN_SO3``, three
outputs) is three, ``name[0..2]``, one per component of its expmap; rows, lengths and gears are those of
MuJoCo's outputs (:func:`outputs`), not of its controls (``nu``: a PID servo may have two). One on a body
(adhesion) acts through contacts and is left out. Tendon limits (``limited``, even a narrow range) are
MuJoCo's one-sided constraints, active only at the range's ends, not equalities: left out. :func:`left_out`
says both in one line.

MuJoCo is asked at each configuration through :class:`~pinmob.io.mjcf.mujoco_kinematics.MujocoKinematics`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.io.mjcf.actuator_lengths import actuator_length
from pinmob.io.mjcf.mjcf_names import label
from pinmob.io.mjcf.mjcf_tree import BALL, FREE, SLIDE, Tree
from pinmob.io.mjcf.mujoco_kinematics import MujocoKinematics
from pinmob.model import (
    Closure,
    FixedTendon,
    Tendon,
    TendonActuator,
    Transmission,
    joint_configuration,
    make_tendon_coupling,
)
from pinmob.screw import Array


@dataclass(frozen=True, eq=False)
class SpatialTendon(Tendon):
    """A tendon whose length MuJoCo computes (``ten_length``, ``ten_J`` at the configuration).

    Attributes:
        name: the tendon's name.
        index: its MuJoCo index.
        kinematics: the compiled model.
        joints: indices of the Pinocchio joints that move it (those carrying its sites and geoms).
        sites: its sites' Pinocchio frames, in order, when it runs straight between sites (else empty).
    """

    name: str
    index: int
    kinematics: MujocoKinematics = field(repr=False)
    joints: frozenset[int] = frozenset()
    linear: bool = True
    sites: tuple[int, ...] = ()

    def site_frames(self) -> tuple[int, ...]:
        """Its sites' frames when it runs straight between sites (no wrapping geom, no pulley), else ``()``."""
        return self.sites

    def length(self, model: pin.Model, data: pin.Data) -> tuple[float, Array]:
        """MuJoCo's ``ten_length`` and ``ten_J`` row (on Pinocchio's ``v``) at the last kinematics' q."""
        q = joint_configuration(model, data)
        kin, t = self.kinematics, self.index
        d, m = kin.at(q), kin.m
        row = kin.sparse_row(d.ten_J, int(m.ten_J_rownnz[t]), int(m.ten_J_rowadr[t]), m.ten_J_colind)
        return float(d.ten_length[t]), kin.to_v(row, q)

    def joint_ids(self, model: pin.Model) -> frozenset[int]:
        """The joints carrying its sites and geoms, and the joints that support them."""
        return self.joints


@dataclass(frozen=True, eq=False)
class MomentActuator(Transmission):
    """An actuator held as MuJoCo's moment arms at the configuration (its ``actuator_moment`` row).

    Attributes:
        name: the actuator's name.
        kind: what it drives: ``tendon``, ``site``, ``slider-crank``, ``ball joint`` (a free joint too) or
            ``orientation`` (one of an orientation servo's outputs, named ``name[k]``).
        index: its MuJoCo output (its row of ``actuator_length``, ``actuator_moment``: ``actuator_outadr``).
        kinematics: the compiled model.
        tendon: the spatial tendon or the :class:`~pinmob.io.mjcf.actuator_lengths.ActuatorLength` it drives (None
            for a site without a reference site and a free joint: MuJoCo gives them no length).
    """

    name: str
    kind: str
    index: int
    kinematics: MujocoKinematics = field(repr=False)
    tendon: Tendon | None = field(default=None, repr=False)

    def driven_tendon(self, model: pin.Model) -> Tendon | None:
        """The spatial tendon or the actuator length it drives, or None (no length: see ``tendon``)."""
        return self.tendon

    def rate_row(self, model: pin.Model, q: Array) -> Array:
        """(nv,) MuJoCo's ``actuator_moment`` row at q, on Pinocchio's ``v``."""
        return self.kinematics.moment_row(self.index, q)


def _wraps(m: Any, t: int) -> range:
    return range(int(m.tendon_adr[t]), int(m.tendon_adr[t] + m.tendon_num[t]))


def is_fixed(m: Any, t: int) -> bool:
    """True for a fixed tendon (every wrap a joint)."""
    import mujoco

    return all(int(m.wrap_type[w]) == mujoco.mjtWrap.mjWRAP_JOINT for w in _wraps(m, t))


def is_length(m: Any, t: int) -> bool:
    """True when tendon ``t``'s length is in metres: a spatial tendon, or a fixed one over a slide."""
    return not is_fixed(m, t) or any(int(m.jnt_type[int(m.wrap_objid[w])]) == SLIDE for w in _wraps(m, t))


def tendon_name(m: Any, t: int) -> str:
    """The tendon's name, or ``tendon#<t>`` (:func:`pinmob.io.mjcf.mjcf_names.label`)."""
    return label(m, "tendon", t)


def tendon_of(m: Any, tree: Tree, t: int, kinematics: MujocoKinematics) -> Tendon:
    """Tendon ``t`` of the compiled model: a :class:`FixedTendon` or a :class:`SpatialTendon`."""
    import mujoco

    model, wraps = tree.model, _wraps(m, t)
    if is_fixed(m, t):
        names = tuple(tree.joint_names[int(m.wrap_objid[w])] for w in wraps)
        return FixedTendon(tendon_name(m, t), names, tuple(float(m.wrap_prm[w]) for w in wraps), is_length(m, t))
    bodies = {
        int(
            m.site_bodyid[int(m.wrap_objid[w])]
            if m.wrap_type[w] == mujoco.mjtWrap.mjWRAP_SITE
            else m.geom_bodyid[int(m.wrap_objid[w])]
        )
        for w in wraps
        if m.wrap_type[w] in (mujoco.mjtWrap.mjWRAP_SITE, mujoco.mjtWrap.mjWRAP_SPHERE, mujoco.mjtWrap.mjWRAP_CYLINDER)
    }
    joints = frozenset(int(j) for b in bodies for j in model.supports[tree.body_joint[b]] if j > 0)
    straight = all(m.wrap_type[w] == mujoco.mjtWrap.mjWRAP_SITE for w in wraps)
    sites = tuple(model.getFrameId(tree.site_frame[int(m.wrap_objid[w])]) for w in wraps) if straight else ()
    return SpatialTendon(tendon_name(m, t), t, kinematics, joints, sites=sites)


def tendon_frames(m: Any, tree: Tree, t: int) -> list[int]:
    """Frame indices on tendon ``t``: its joints' ``JOINT`` frames (fixed) or its sites' frames (spatial)."""
    import mujoco

    model, out = tree.model, []
    for w in _wraps(m, t):
        kind, obj = int(m.wrap_type[w]), int(m.wrap_objid[w])
        if kind == mujoco.mjtWrap.mjWRAP_JOINT:
            jid = model.getJointId(tree.joint_names[obj])
            out += [i for i, f in enumerate(model.frames) if f.parentJoint == jid and f.type == pin.FrameType.JOINT][:1]
        elif kind == mujoco.mjtWrap.mjWRAP_SITE:
            out.append(model.getFrameId(tree.site_frame[obj]))
    return out


def tendon_closure(m: Any, tree: Tree, e: int, name: str, kinematics: MujocoKinematics) -> Closure:
    """The ``tendon`` closure of equality ``e`` (``eq_obj1id``, ``eq_obj2id``: tendons; ``eq_data[:5]``: polycoef)."""
    ids = [int(t) for t in (m.eq_obj1id[e], m.eq_obj2id[e]) if t >= 0]
    tendons = tuple(tendon_of(m, tree, t, kinematics) for t in ids)
    frames = tendon_frames(m, tree, ids[0]) + [f for t in ids[1:] for f in tendon_frames(m, tree, t)]
    frames = frames or [0]
    reference = tuple(float(m.tendon_length0[t]) for t in ids)
    return make_tendon_coupling(tree.model, name, tendons, tuple(m.eq_data[e, :5]), reference, (frames[0], frames[-1]))


def outputs(m: Any) -> list[tuple[int, int, int]]:
    """``(actuator, its first output, its number of outputs)`` for each of MuJoCo's actuators.

    An actuator may have several controls and outputs (``nu``: controls, ``nactuator``: actuators); its
    lengths, moment rows and gears are at its outputs (``actuator_outadr``, ``actuator_outnum``).
    """
    return [(a, int(m.actuator_outadr[a]), int(m.actuator_outnum[a])) for a in range(m.nactuator)]


def read_actuators(
    m: Any, tree: Tree, kinematics: MujocoKinematics
) -> tuple[list[tuple[str, str]], list[Transmission], list[str]]:
    """``(actuator, joint)`` per actuator on a hinge or slide, the other held actuators, the ones left out by name.

    See the module docstring. The joints actuated are those of the pairs, each once: two actuators on one joint
    (MuJoCo's position and velocity servo pair) drive one coordinate, and hold it once.

    Raises:
        ValueError: an actuator with several outputs other than an orientation servo (named).
    """
    import mujoco

    trn = mujoco.mjtTrn
    joints: list[tuple[str, str]] = []
    held: list[Transmission] = []
    adhesion: list[str] = []
    for a, out, count in outputs(m):
        kind, target = int(m.actuator_trntype[a]), int(m.actuator_trnid[a, 0])
        name = label(m, "actuator", a)
        if count != 1 and kind != trn.mjTRN_SO3:
            raise ValueError(
                f"actuator {name!r} has {count} outputs on a transmission pinmob reads with one (of MuJoCo's "
                "transmissions, only an orientation servo has several): remove it or give it one output"
            )
        if kind in (trn.mjTRN_JOINT, trn.mjTRN_JOINTINPARENT) and int(m.jnt_type[target]) not in (FREE, BALL):
            joints.append((name, tree.joint_names[target]))  # a hinge's or slide's own coordinate
        elif kind == trn.mjTRN_TENDON and is_fixed(m, target):
            wraps = _wraps(m, target)
            coef = tuple(float(m.wrap_prm[w]) for w in wraps)
            names = tuple(tree.joint_names[int(m.wrap_objid[w])] for w in wraps)
            held.append(TendonActuator(name, tendon_name(m, target), names, coef))
        elif kind == trn.mjTRN_BODY:
            adhesion.append(name)
        elif kind == trn.mjTRN_SO3:  # an orientation servo: three outputs, the expmap's components
            on_site = int(m.actuator_trnid[a, 1]) >= 0
            for k in range(count):
                axis = np.zeros(6)
                axis[3 + k if on_site else k] = 1.0
                part = f"{name}[{k}]"
                length = actuator_length(m, tree, a, out + k, part, kinematics, axis)
                held.append(MomentActuator(part, "orientation", out + k, kinematics, length))
        else:
            what = {trn.mjTRN_TENDON: "tendon", trn.mjTRN_SITE: "site", trn.mjTRN_SLIDERCRANK: "slider-crank"}
            tendon: Tendon | None = (
                tendon_of(m, tree, target, kinematics)
                if kind == trn.mjTRN_TENDON
                else actuator_length(m, tree, a, out, name, kinematics, np.asarray(m.actuator_gear[out], float))
            )
            held.append(MomentActuator(name, what.get(kind, "ball joint"), out, kinematics, tendon))
    return joints, held, adhesion


def left_out(m: Any, adhesion: list[str]) -> str:
    """What MuJoCo constrains or drives that pinmob leaves out, in one sentence (``""`` when nothing).

    Tendon limits (each with its range; MuJoCo refuses an empty one) and actuators on bodies (adhesion).
    """
    parts = []
    limited = [t for t in range(m.ntendon) if m.tendon_limited[t]]
    if limited:
        ranges = ", ".join(
            f"{tendon_name(m, t)} [{m.tendon_range[t, 0]:.4g}, {m.tendon_range[t, 1]:.4g}]" for t in limited
        )
        parts.append(
            f"tendon limits ({ranges}: one-sided constraints in MuJoCo, active only at an end of the range, so not "
            "couplings however narrow; an <equality tendon> is one)"
        )
    if adhesion:
        parts.append(f"actuator(s) {', '.join(adhesion)} on bodies (adhesion, through contacts)")
    return f"left out: {'; '.join(parts)}" if parts else ""
