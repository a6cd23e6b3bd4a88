"""MuJoCo's actuator lengths held as closures: slider-cranks, ball joints, sites with a reference site, orientations.

MuJoCo gives an actuator a length (``actuator_length``, ``mj_transmission``) on a slider-crank (the slider's
position), a ball joint (its rotation vector along ``gear``), a site with a reference site (the site's pose in
the reference site's frame along ``gear``) and, since MuJoCo 3.11, an orientation servo (the three components of
a ball's or a site's expmap, one per output). Held, such an actuator keeps its length: an
:class:`ActuatorLength`, a :class:`~pinmob.model.tendon.Tendon` whose value is MuJoCo's and whose row is the
value's exact derivative (:func:`refsite_row` on a site). A site without a reference site and a free joint have
no length (MuJoCo's is 0): :func:`actuator_length` gives None.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, ClassVar

import numpy as np
import pinocchio as pin

from pinmob.io.mjcf.mjcf_tree import BALL, Tree
from pinmob.io.mjcf.mujoco_kinematics import MujocoKinematics
from pinmob.model import Tendon, joint_configuration
from pinmob.screw import Array


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
        """MuJoCo's ``actuator_length`` and its derivative's row (on Pinocchio's ``v``) at the last kinematics' q."""
        q = joint_configuration(model, data)
        kin, a = self.kinematics, self.index
        d = kin.at(q)
        if self.refsite is not None:
            return float(d.actuator_length[a]), kin.to_v(refsite_row(kin.m, d, *self.refsite), q)
        row = kin.moment_row(a, q)
        if self.ball is not None:
            joint, gear = model.joints[self.ball[0]], np.array(self.ball[1])
            rot = pin.Quaternion(np.array(q[joint.idx_q : joint.idx_q + 4], float)).normalized().toRotationMatrix()
            row[joint.idx_v : joint.idx_v + 3] = gear @ pin.Jlog3(rot)
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
    servo's expmap (``gear`` a unit axis). None for a site without a reference site and for a free joint:
    MuJoCo's length is 0 there whatever the configuration (a force or a torque at the site or body, with nothing
    to hold at finite amplitude).
    """
    import mujoco

    trn, model = mujoco.mjtTrn, tree.model
    kind, first, second = int(m.actuator_trntype[a]), int(m.actuator_trnid[a, 0]), int(m.actuator_trnid[a, 1])
    if kind == trn.mjTRN_SO3:  # the expmap of the ball's rotation or of the site's relative to the reference site
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
