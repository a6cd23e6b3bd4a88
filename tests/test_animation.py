"""Following free motions: every frame closed, the platform really moving, and stopping where it must."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.animation import follow_motion
from pinmob.closure import check_closed


@pytest.fixture(scope="module")
def puu() -> pinmob.Mechanism:
    return pinmob.load("3-PUU")


@pytest.fixture(scope="module")
def flat() -> pinmob.Mechanism:
    return pinmob.load("3-PUU-flat")


def platform_pose(mech: pinmob.Mechanism, q: np.ndarray) -> pin.SE3:
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    return data.oMf[mech.platform_id].copy()


def test_translation_of_translational_3puu_is_followed_exactly(puu):
    # The generic 3-PUU is translational (paper eq. 38): moving along T1 x keeps the
    # orientation and moves the platform origin along x by the amplitude, both ways.
    q = puu.configuration("generic")
    mob = pinmob.analyze(puu, q)
    motion = next(m for m in mob.motions if m.label == "T1 x")
    path = follow_motion(puu, q, motion, amplitude=0.04, steps=8)
    assert path.complete and path.notes == ()
    assert len(path.forward) == len(path.backward) == 9
    p0 = platform_pose(puu, q)
    for sign, branch in ((1.0, path.forward), (-1.0, path.backward)):
        for k, qk in enumerate(branch):
            check_closed(puu, qk, 1e-6)
            pose = platform_pose(puu, qk)
            assert_allclose(pose.rotation, np.eye(3), atol=1e-9)
            assert_allclose(pose.translation - p0.translation, [sign * 0.005 * k, 0, 0], atol=1e-9)
    frames = path.frames()
    assert len(frames) == 4 * 8 + 1
    assert_allclose(frames[0], q, atol=0)
    assert_allclose(frames[-1], q, atol=1e-12)


def test_vertical_translation_of_flat_3puu_keeps_links_horizontal(flat):
    # 3-PUU-flat (links R - r long, coplanar with the platform): the platform rises with
    # all three sliders by the same amount (hand derivation: the links stay horizontal).
    q = flat.configuration("flat")
    mob = pinmob.analyze(flat, q)
    motion = next(m for m in mob.motions if m.kind is pinmob.MotionKind.TRANSLATION)
    path = follow_motion(flat, q, motion, amplitude=0.03, steps=6)
    assert path.complete
    idx = [flat.model.joints[flat.model.getJointId(f"{x}_slider")].idx_q for x in "ABC"]
    for qk in path.forward + path.backward:
        check_closed(flat, qk, 1e-6)
        z = platform_pose(flat, qk).translation[2]
        # each limb is serially singular here: a slider offset d moves its tip by only
        # d^2 / (2 (R - r)) along the link, so closing to 1e-6 L fixes the sliders to ~1e-5 m
        assert_allclose(qk[idx], [z, z, z], atol=2e-5)
    assert_allclose(platform_pose(flat, path.forward[-1]).translation, [0, 0, 0.03], atol=1e-9)


def test_rotation_of_flat_3puu_is_only_instantaneous(flat):
    # Rotating the platform by phi about z puts vertex i at distance
    # sqrt(R^2 + r^2 - 2 R r cos phi) > R - r from its guide: the links cannot reach,
    # so the free rotation R1 z found at 'flat' cannot be followed any finite amount.
    q = flat.configuration("flat")
    mob = pinmob.analyze(flat, q)
    motion = next(m for m in mob.motions if m.kind is pinmob.MotionKind.ROTATION)
    path = follow_motion(flat, q, motion, steps=4)
    assert path.reached == (0.0, 0.0)
    assert len(path.forward) == len(path.backward) == 1
    assert not path.complete
    assert len(path.notes) == 1 and "only instantaneous" in path.notes[0] and motion.label in path.notes[0]
    assert len(path.frames()) == 2  # a static clip still has a duration


def test_follow_motion_rejects_bad_arguments(puu):
    q = puu.configuration("generic")
    motion = pinmob.analyze(puu, q).motions[0]
    with pytest.raises(pinmob.ConfigurationError, match="steps"):
        follow_motion(puu, q, motion, steps=0)
    with pytest.raises(pinmob.ConfigurationError, match="amplitude"):
        follow_motion(puu, q, motion, amplitude=-1.0)
    with pytest.raises(pinmob.ClosureError):
        follow_motion(puu, puu.neutral() + 0.01, motion)


def test_rotation_about_a_fixed_point_keeps_the_distance(tmp_path):
    # A spherical joint (three revolutes through the origin) carrying the platform at
    # (0, 0, 0.2): every free motion is a rotation about the origin, so following one
    # keeps the platform origin 0.2 m from the origin and turns it by the amplitude.
    from pinmob.builder import MechanismBuilder

    b = MechanismBuilder("S", "one spherical joint")
    b.limb("A").spherical("s", at=[0, 0, 0])
    b.limbs[0].tip(at=[0, 0, 0.2])
    path = b.write(tmp_path, "s", {"rest": {"joints": {"A_sa": 0.0}}})
    mech = pinmob.load(path)
    q = mech.configuration("rest")
    mob = pinmob.analyze(mech, q)
    assert mob.motion_type == "3R"
    for motion in mob.motions:
        result = follow_motion(mech, q, motion, amplitude=0.3, steps=6)
        assert result.complete, result.notes
        for qk in result.forward + result.backward:
            assert_allclose(np.linalg.norm(platform_pose(mech, qk).translation), 0.2, atol=1e-9)
        turned = pin.log3(platform_pose(mech, result.forward[-1]).rotation)
        assert_allclose(turned, 0.3 * motion.direction, atol=1e-6)
