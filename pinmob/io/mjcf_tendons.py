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
at the configuration (its row of ``actuator_moment``). An orientation servo (MuJoCo 3.12's ``mjTRN_SO3``, three
outputs) is three, ``name[0..2]``, one per component of its expmap; rows, lengths and gears are those of
MuJoCo's outputs (:func:`outputs`), not of its controls (``nu``: a PID servo may have two). One on a body (adhesion) acts through contacts and
is left out. Tendon limits (``limited``, even a narrow range) are MuJoCo's one-sided constraints, active
only at the range's ends, not equalities: left out. :func:`left_out` says both in one line.

MuJoCo is asked at each configuration through :class:`~pinmob.io.mujoco_kinematics.MujocoKinematics`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
import pinocchio as pin

from pinmob.io.mjcf_names import label
from pinmob.io.mjcf_tree import BALL, FREE, SLIDE, Tree
from pinmob.io.mujoco_kinematics import MujocoKinematics
from pinmob.model.closure import Closure, make_tendon_coupling
from pinmob.model.tendon import FixedTendon, Tendon, TendonActuator, Transmission, joint_configuration
from pinmob.screw.algebra import Array


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
        tendon: the spatial tendon or the :class:`ActuatorLength` it drives (None for a site without a reference
            site and a free joint: MuJoCo gives them no length).
    """

    name: str
    kind: str
    index: int
    kinematics: MujocoKinematics = field(repr=False)
    tendon: Tendon | None = field(default=None, repr=False)

    def driven_tendon(self, model: pin.Model) -> Tendon | None:
        """The spatial tendon it drives, or None."""
        return self.tendon

    def rate_row(self, model: pin.Model, q: Array) -> Array:
        """(nv,) MuJoCo's ``actuator_moment`` row at q, on Pinocchio's ``v``."""
        kin, a = self.kinematics, self.index
        d = kin.at(np.asarray(q, float))
        row = kin.sparse_row(d.actuator_moment, int(d.moment_rownnz[a]), int(d.moment_rowadr[a]), d.moment_colind)
        return kin.to_v(row, q)


@dataclass(frozen=True, eq=False)
class ActuatorLength(Tendon):
    """What an actuator on a slider-crank, a ball joint or a site with a reference site drives, as a length.

    MuJoCo gives such an actuator a length (``actuator_length``): the slider-crank's slider position, the
    ball's rotation vector along ``gear`` (``gear . log(R)``), the site's pose in its reference site's frame
    along ``gear``. Held, the actuator keeps it, a closure like a spatial tendon's, decided by closed samples
    (no written higher derivatives). The row is the length's exact derivative: MuJoCo's ``actuator_moment`` on a
    slider-crank (its chain rule); on a ball joint ``gear . Jlog3(R)`` (MuJoCo's moment is ``gear`` itself, equal
    at R = I); on a site with a reference site :func:`refsite_row` (MuJoCo's moment leaves out the reference
    frame's turning and the expmap's Jacobian: equal only where the reference site does not turn and the
    relative rotation is the identity).

    Attributes:
        name: the actuator's name.
        index: its MuJoCo output (its row of ``actuator_length``, ``actuator_moment``).
        kinematics: the compiled model.
        joints: indices of the Pinocchio joints that move it.
        linear: its length is in metres (a slider-crank, a site with a translational gear).
        ball: the ball joint's Pinocchio index and ``gear[:3]`` (None for the other kinds).
        refsite: MuJoCo's site and reference site indices and ``gear`` (None for the other kinds).
    """

    name: str
    index: int
    kinematics: MujocoKinematics = field(repr=False)
    joints: frozenset[int] = frozenset()
    linear: bool = True
    ball: tuple[int, tuple[float, float, float]] | None = None
    refsite: tuple[int, int, tuple[float, ...]] | None = None
    noun: ClassVar[str] = "actuator length"
    unwritten_why: ClassVar[str] = "MuJoCo's length of a slider-crank, a ball joint or a site"

    def length(self, model: pin.Model, data: pin.Data) -> tuple[float, Array]:
        """MuJoCo's ``actuator_length`` and the row of its derivative (on Pinocchio's ``v``) at the last kinematics' q."""
        q = joint_configuration(model, data)
        kin, a = self.kinematics, self.index
        d = kin.at(q)
        row = kin.to_v(
            kin.sparse_row(d.actuator_moment, int(d.moment_rownnz[a]), int(d.moment_rowadr[a]), d.moment_colind), q
        )
        if self.ball is not None:
            joint, gear = model.joints[self.ball[0]], np.array(self.ball[1])
            rot = pin.Quaternion(np.array(q[joint.idx_q : joint.idx_q + 4], float)).normalized().toRotationMatrix()
            row[joint.idx_v : joint.idx_v + 3] = gear @ pin.Jlog3(rot)
        elif self.refsite is not None:
            row = kin.to_v(refsite_row(kin.m, d, *self.refsite), q)
        return float(d.actuator_length[a]), row

    def joint_ids(self, model: pin.Model) -> frozenset[int]:
        """The joints supporting the bodies it acts between."""
        return self.joints


def refsite_row(m: Any, d: Any, site: int, ref: int, gear: tuple[float, ...]) -> Array:
    """(nv,) on ``qvel``: the exact derivative of MuJoCo's length of a site transmission with a reference site.

    MuJoCo's length (``mj_transmission``) is ``g . R_r^T (p_s - p_r) + g' . log(R_r^T R_s)``, with ``g``, ``g'``
    the translational and rotational gear and ``p``, ``R`` the sites' positions and frames. Its derivative:
    ``(R_r g) . (v_s - v_r - w_r x (p_s - p_r))`` (the site's velocity relative to the reference body's point at
    the site) plus ``g' . Jlog3(R_r^T R_s) R_s^T (w_s - w_r)`` (the relative angular velocity in the site's frame,
    through the expmap's Jacobian); MuJoCo's moment keeps ``(R_r g) . (v_s - v_r) + (R_r g') . (w_s - w_r)``.
    """
    import mujoco

    nv, g = m.nv, np.asarray(gear, float)
    jac_s, jac_r = (np.zeros((3, nv)), np.zeros((3, nv))), (np.zeros((3, nv)), np.zeros((3, nv)))
    mujoco.mj_jacSite(m, d, jac_s[0], jac_s[1], site)
    mujoco.mj_jacSite(m, d, jac_r[0], jac_r[1], ref)
    row = np.zeros(nv)
    if np.any(g[:3]):
        offset = d.site_xpos[site] - d.site_xpos[ref]
        turn = np.cross(offset[:, None], jac_r[1], axis=0)  # -(w_r x offset) = offset x w_r, per column
        row += (d.site_xmat[ref].reshape(3, 3) @ g[:3]) @ (jac_s[0] - jac_r[0] + turn)
    if np.any(g[3:]):
        a, b = d.site_xmat[ref].reshape(3, 3), d.site_xmat[site].reshape(3, 3)
        rates = b.T @ (jac_s[1] - jac_r[1])  # Q's rate in the site's frame: the relative angular velocity
        rel = a.T @ b
        row += g[3:] @ pin.Jlog3(rel) @ rates
    return row


def actuator_length(
    m: Any, tree: Tree, a: int, out: int, name: str, kinematics: MujocoKinematics, gear: Array
) -> ActuatorLength | None:
    """The length output ``out`` of actuator ``a`` drives along ``gear``, or None.

    A slider-crank's, a ball joint's, a site's with a reference site, or one component of an orientation
    servo's expmap (``gear`` a unit axis). None for a site without a reference site and for a free joint: MuJoCo's length is 0 there whatever the
    configuration (a force or a torque at the site or body, with nothing to hold at finite amplitude).
    """
    import mujoco

    trn, model = mujoco.mjtTrn, tree.model
    kind, first, second = int(m.actuator_trntype[a]), int(m.actuator_trnid[a, 0]), int(m.actuator_trnid[a, 1])
    if kind == so3(trn):  # the expmap of the ball's rotation or of the site's relative to the reference site
        kind = trn.mjTRN_SITE if second >= 0 else trn.mjTRN_JOINT
    ball = refsite = None
    if kind == trn.mjTRN_SLIDERCRANK or (kind == trn.mjTRN_SITE and second >= 0):
        bodies = [int(m.site_bodyid[first]), int(m.site_bodyid[second])]
        linear = kind == trn.mjTRN_SLIDERCRANK or bool(np.any(gear[:3]))
        if kind == trn.mjTRN_SITE:
            refsite = (first, second, tuple(float(g) for g in gear))
    elif kind in (trn.mjTRN_JOINT, trn.mjTRN_JOINTINPARENT) and int(m.jnt_type[first]) == BALL:
        bodies, linear = [int(m.jnt_bodyid[first])], False
        ball = (model.getJointId(tree.joint_names[first]), (float(gear[0]), float(gear[1]), float(gear[2])))
    else:
        return None
    joints = frozenset(int(j) for b in bodies for j in model.supports[tree.body_joint[b]] if j > 0)
    return ActuatorLength(name, out, kinematics, joints, linear, ball, refsite)


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
    """The tendon's name, or ``tendon#<t>`` (:func:`pinmob.io.mjcf_names.label`)."""
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


def so3(trn: Any) -> int:
    """MuJoCo's orientation transmission (``mjTRN_SO3``, since MuJoCo 3.12; -1 before, where none has it)."""
    return int(getattr(trn, "mjTRN_SO3", -1))


def outputs(m: Any) -> list[tuple[int, int, int]]:
    """``(actuator, its first output, its number of outputs)`` for each of MuJoCo's actuators.

    Since MuJoCo 3.12 an actuator may have several controls and outputs (``nu``: controls, ``nactuator``:
    actuators); its lengths, moment rows and gears are at its outputs (``actuator_outadr``, ``actuator_outnum``).
    """
    if not hasattr(m, "actuator_outadr"):
        return [(a, a, 1) for a in range(m.nu)]
    return [(a, int(m.actuator_outadr[a]), int(m.actuator_outnum[a])) for a in range(m.nactuator)]


def read_actuators(
    m: Any, tree: Tree, kinematics: MujocoKinematics
) -> tuple[list[tuple[str, str]], list[Transmission], list[str]]:
    """``(actuator, joint)`` per actuator on a hinge or slide, the other held actuators, the ones left out by name.

    See the module docstring. The joints actuated are those of the pairs, each once: two actuators on one joint (MuJoCo's position and
    velocity servo pair) drive one coordinate, and hold it once.
    """
    import mujoco

    trn = mujoco.mjtTrn
    joints: list[tuple[str, str]] = []
    held: list[Transmission] = []
    adhesion: list[str] = []
    for a, out, count in outputs(m):
        kind, target = int(m.actuator_trntype[a]), int(m.actuator_trnid[a, 0])
        name = label(m, "actuator", a)
        if kind in (trn.mjTRN_JOINT, trn.mjTRN_JOINTINPARENT) and int(m.jnt_type[target]) not in (FREE, BALL):
            joints.append((name, tree.joint_names[target]))  # a hinge's or slide's own coordinate
        elif kind == trn.mjTRN_TENDON and is_fixed(m, target):
            wraps = _wraps(m, target)
            coef = tuple(float(m.wrap_prm[w]) for w in wraps)
            names = tuple(tree.joint_names[int(m.wrap_objid[w])] for w in wraps)
            held.append(TendonActuator(name, tendon_name(m, target), names, coef))
        elif kind == trn.mjTRN_BODY:
            adhesion.append(name)
        elif kind == so3(trn):  # an orientation servo: three outputs, the expmap's components
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
