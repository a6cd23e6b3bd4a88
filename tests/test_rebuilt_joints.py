"""A model's copy with some joints rebuilt (``pinmob.model.with_joints``), which an Extended URDF's ``joint_type``
and Pinocchio's mimic joints (read as joints of their own) both use.

Truths by construction: a two-hinge arm built here by hand, with its limits, placements and a tool frame; a ball
joint at the identity places its child as a hinge at 0 does.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
from numpy.testing import assert_allclose

from pinmob.model import with_joints

BIG = np.finfo(float).max  # pin.Model.addJoint's limits
#: effort, velocity, lower and upper position limits of the two hinges
LIMITS_1 = (np.array([5.0]), np.array([3.0]), np.array([-1.0]), np.array([1.0]))
LIMITS_2 = (np.array([7.0]), np.array([4.0]), np.array([-2.0]), np.array([2.0]))


def arm() -> pin.Model:
    """Two hinges 0.3 m apart (limits +-1 and +-2 rad, effort 5 and 7, velocity 3 and 4), a tool 0.2 m further."""
    model = pin.Model()
    model.name = "arm"
    first = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "shoulder", *LIMITS_1)
    model.appendBodyToJoint(first, pin.Inertia.FromSphere(1.0, 0.05), pin.SE3.Identity())
    at = pin.SE3(np.eye(3), np.array([0.3, 0.0, 0.0]))
    second = model.addJoint(first, pin.JointModelRY(), at, "elbow", *LIMITS_2)
    model.appendBodyToJoint(second, pin.Inertia.FromSphere(2.0, 0.05), pin.SE3.Identity())
    model.addFrame(pin.Frame("tool", second, pin.SE3(np.eye(3), np.array([0.2, 0.0, 0.0])), pin.FrameType.OP_FRAME))
    return model


def test_a_rebuilt_joint_keeps_its_place_and_the_other_joints_their_limits():
    model = arm()
    out = with_joints(model, {2: pin.JointModelSpherical()})
    assert (out.name, list(out.names), out.nq, out.nv) == ("arm", ["universe", "shoulder", "elbow"], 5, 4)
    assert [f.name for f in out.frames] == [f.name for f in model.frames]
    assert_allclose(out.lowerPositionLimit, [-1.0, -BIG, -BIG, -BIG, -BIG], atol=0)
    assert_allclose(out.upperPositionLimit, [1.0, BIG, BIG, BIG, BIG], atol=0)
    assert_allclose(out.effortLimit, [5.0, BIG, BIG, BIG], atol=0)
    assert_allclose(out.velocityLimit, [3.0, BIG, BIG, BIG], atol=0)
    assert_allclose(out.inertias[2].mass, 2.0, atol=0)
    data = out.createData()
    pin.framesForwardKinematics(out, data, pin.neutral(out))
    assert_allclose(data.oMf[out.getFrameId("tool")].translation, [0.5, 0.0, 0.0], atol=1e-15)  # 0.3 + 0.2 along x


def test_only_the_limits_named_are_copied():
    out = with_joints(arm(), {}, ("lowerPositionLimit", "upperPositionLimit"))
    assert_allclose(out.lowerPositionLimit, [-1.0, -2.0], atol=0)
    assert_allclose(out.upperPositionLimit, [1.0, 2.0], atol=0)
    assert_allclose(out.effortLimit, [BIG, BIG], atol=0)
    assert_allclose(out.velocityLimit, [BIG, BIG], atol=0)
