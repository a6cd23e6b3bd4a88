"""Following free motions: every frame closed, the platform really moving, and stopping where it must."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.analysis.follow.motion_path import MAX_DEVIATION, follow_motion
from pinmob.assembly.residual import check_closed, compute_kinematics, mechanism_residuals, worst_residual


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
    q = pinmob.closed_configuration(puu, "generic")
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
    q = pinmob.closed_configuration(flat, "flat")
    mob = pinmob.analyze(flat, q)
    motion = next(m for m in mob.motions if m.kind is pinmob.MotionKind.TRANSLATION)
    path = follow_motion(flat, q, motion, amplitude=0.03, steps=6)
    assert path.complete
    idx = [flat.model.joints[flat.model.getJointId(f"{x}_slider")].idx_q for x in "ABC"]
    for qk in path.forward + path.backward:
        check_closed(flat, qk, 1e-6)
        z = platform_pose(flat, qk).translation[2]
        # each limb is serially singular here: a slider offset d moves its tip by only
        # d^2 / (2 (R - r)) along the link, so closing to 1e-6 L fixes the sliders to
        # sqrt(2 (R - r) 1e-6 L) = 2.5e-4 m (the follower's route lands 1e-5 to 4e-5 m off,
        # depending on how near-singular limb screws are weighed: 2e-5 held by luck before issue 14)
        assert_allclose(qk[idx], [z, z, z], atol=np.sqrt(2 * 0.15 * 1e-6 * flat.length_scale))
    # the last pose within the closure tolerance 1e-6 L of the target (1.2e-9 m off once slider rates are per L)
    assert_allclose(platform_pose(flat, path.forward[-1]).translation, [0, 0, 0.03], atol=1e-6 * flat.length_scale)


def test_rotation_of_flat_3puu_is_only_instantaneous(flat):
    # Rotating the platform by phi about z puts vertex i at distance
    # sqrt(R^2 + r^2 - 2 R r cos phi) > R - r from its guide: the links cannot reach,
    # so the free rotation R1 z found at 'flat' cannot be followed any finite amount.
    q = pinmob.closed_configuration(flat, "flat")
    mob = pinmob.analyze(flat, q)
    motion = next(m for m in mob.motions if m.kind is pinmob.MotionKind.ROTATION)
    path = follow_motion(flat, q, motion, steps=4)
    assert path.reached == (0.0, 0.0)
    assert len(path.forward) == len(path.backward) == 1
    assert not path.complete
    assert len(path.notes) == 1 and "only instantaneous" in path.notes[0] and motion.label in path.notes[0]
    assert len(path.frames()) == 2  # a static clip still has a duration


def test_follow_motion_rejects_bad_arguments(puu):
    q = pinmob.closed_configuration(puu, "generic")
    motion = pinmob.analyze(puu, q).motions[0]
    with pytest.raises(pinmob.ConfigurationError, match="steps"):
        follow_motion(puu, q, motion, steps=0)
    with pytest.raises(pinmob.ConfigurationError, match="amplitude"):
        follow_motion(puu, q, motion, amplitude=-1.0)
    with pytest.raises(pinmob.ClosureError):
        follow_motion(puu, puu.neutral() + 0.01, motion)


def test_a_configuration_is_followed_from_as_it_is(puu, flat):
    """From a closed Configuration, follow_motion gives the frames it gives from its vector with the same closure
    tolerance (the Configuration's own); an unchecked Configuration (loops not checked, no tolerance) or one of
    another mechanism is refused. On the old code a Configuration was not accepted at all."""
    conf = pinmob.Configuration(puu, "generic", closure_tol=1e-5)
    motion = pinmob.analyze(conf).motions[0]
    from_vector = follow_motion(puu, conf.q, motion, amplitude=0.04, steps=4, closure_tol=1e-5)
    from_conf = follow_motion(puu, conf, motion, amplitude=0.04, steps=4)
    assert from_conf.complete and len(from_conf.frames()) == len(from_vector.frames())
    for a, b in zip(from_conf.frames(), from_vector.frames(), strict=True):
        assert np.array_equal(a, b)
    with pytest.raises(pinmob.ConfigurationError, match=r"not Configuration\.unchecked"):
        follow_motion(puu, pinmob.Configuration.unchecked(puu, conf.q), motion)
    with pytest.raises(pinmob.ConfigurationError, match="closed Configuration of '3-PUU'"):
        follow_motion(puu, pinmob.Configuration(flat, "flat"), motion)


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
    q = pinmob.closed_configuration(mech, "rest")
    mob = pinmob.analyze(mech, q)
    assert mob.motion_type == "3R"
    for motion in mob.motions:
        result = follow_motion(mech, q, motion, amplitude=0.3, steps=6)
        assert result.complete, result.notes
        for qk in result.forward + result.backward:
            assert_allclose(np.linalg.norm(platform_pose(mech, qk).translation), 0.2, atol=1e-9)
        turned = pin.log3(platform_pose(mech, result.forward[-1]).rotation)
        assert_allclose(turned, 0.3 * motion.direction, atol=1e-6)


def _rotation_off_axis(mech: pinmob.Mechanism, q0: np.ndarray, q1: np.ndarray, axis: np.ndarray) -> float:
    """Angle [rad] between the platform's finite rotation from q0 to q1 (world axes) and the line of ``axis``."""
    r0, r1 = platform_pose(mech, q0).rotation, platform_pose(mech, q1).rotation
    turned = pin.log3(r1 @ r0.T)  # world axes
    if np.linalg.norm(turned) < 1e-12:
        return 0.0
    return float(np.arccos(min(1.0, abs(turned @ axis) / np.linalg.norm(turned))))


def _generic_spherical(mech: pinmob.Mechanism) -> np.ndarray:
    from pinmob.assembly.assemble import assemble_joints

    # actuated values away from the limbs' stretched (serially singular) poses: the smallest
    # singular value of each limb's angular Jacobian is above 0.26 here (0.05 at 'generic')
    return assemble_joints(
        mech, {"A_r1": 1.07, "B_r1": 0.36, "C_r1": 0.2}, pinmob.closed_configuration(mech, "generic")
    )


def test_spherical_rotations_keep_their_axis_and_the_centre():
    # 3-RRR-spherical: all nine revolute axes meet at O = (0, 0, 0), so the platform turns
    # about O (3R) and any rotation about an axis through O is a finite motion: following
    # one keeps the platform origin 0.25 m from O and turns it by the amplitude about the
    # motion's axis (log3 of the end rotation = amplitude * direction).
    # (Each limb is a 3R spherical chain with non-orthogonal axes: its orientations are
    # limited, so the amplitude is kept within all three limbs' reach here.)
    mech = pinmob.load("3-RRR-spherical")
    q = _generic_spherical(mech)
    mob = pinmob.analyze(mech, q)
    assert mob.motion_type == "3R"
    for motion in mob.motions:
        path = follow_motion(mech, q, motion, amplitude=0.12, steps=4)
        assert path.complete, path.notes
        for qk in path.forward + path.backward:
            assert_allclose(np.linalg.norm(platform_pose(mech, qk).translation), 0.25, atol=1e-9)
        r0 = platform_pose(mech, q).rotation
        ends = ((1, path.forward[-1], path.displacement[0]), (-1, path.backward[-1], path.displacement[1]))
        for sign, end, moved in ends:
            assert_allclose(
                pin.log3(platform_pose(mech, end).rotation @ r0.T), sign * 0.12 * motion.direction, atol=1e-6
            )
            assert_allclose(moved.rotation, 0.12, atol=1e-6)
            assert moved.deviation < 1e-6


def test_near_singular_spherical_clips_stay_on_their_axes():
    # At 'generic' limb A is nearly stretched (smallest singular value of its angular
    # Jacobian 0.05): re-closing after a step can turn the platform about another axis
    # through O. Every clip must still turn about its own axis (measured on the poses, to
    # within the per-step tolerance), or stop and say so; the reported displacement must
    # match the poses.
    from pinmob.analysis.follow.motion_path import MAX_DEVIATION

    mech = pinmob.load("3-RRR-spherical")
    q = pinmob.closed_configuration(mech, "generic")
    for motion in pinmob.analyze(mech, q).motions:
        path = follow_motion(mech, q, motion, steps=6)
        for end, moved in ((path.forward[-1], path.displacement[0]), (path.backward[-1], path.displacement[1])):
            off = _rotation_off_axis(mech, q, end, motion.direction)
            assert off < MAX_DEVIATION, f"{motion.label} ends {np.degrees(off):.1f} deg off its axis"
            turned = np.linalg.norm(pin.log3(platform_pose(mech, end).rotation @ platform_pose(mech, q).rotation.T))
            assert_allclose(moved.rotation, turned, atol=1e-12)
        for note in path.notes:
            assert motion.label in note


def test_first_step_is_halved_before_giving_up():
    # 3-RRR-spherical, rotation R1 x in one step of 0.35 rad: limb B (a 3R spherical chain
    # with non-orthogonal axes) cannot reach that orientation, so the first step fails; a
    # halved step (0.175 rad) is within reach. The motion is finite, so there must be no
    # "only instantaneous" note, and the platform turns about x by what was reached.
    mech = pinmob.load("3-RRR-spherical")
    q = _generic_spherical(mech)
    motion = next(m for m in pinmob.analyze(mech, q).motions if m.label == "R1 x")
    path = follow_motion(mech, q, motion, amplitude=0.35, steps=1)
    assert len(path.forward) > 1 and 0 < path.reached[0] < 0.35
    assert not any("only instantaneous" in n for n in path.notes), path.notes
    turned = pin.log3(platform_pose(mech, path.forward[-1]).rotation @ platform_pose(mech, q).rotation.T)
    assert_allclose(turned, path.reached[0] * motion.direction, atol=1e-6)


@pytest.mark.parametrize("config", ["generic", "rods-horizontal"])
def test_delta_frames_close_every_loop(config):
    # The Delta's parallelograms are loops inside the limbs (3d closures): every frame of
    # every clip must close them too (the one residual measure, limb tips and closures).
    from pinmob.assembly.residual import CLOSURE_TOL, compute_kinematics, mechanism_residuals, worst_residual

    mech = pinmob.load("Delta")
    q = pinmob.closed_configuration(mech, config)
    assert pinmob.analyze(mech, q).motion_type == {"generic": "3T", "rods-horizontal": "3T2R"}[config]
    data = mech.model.createData()
    for motion in pinmob.analyze(mech, q).motions:
        path = follow_motion(mech, q, motion, steps=4)
        for qk in path.frames():
            compute_kinematics(mech.model, data, qk)
            assert worst_residual(mechanism_residuals(mech, data), mech.length_scale) <= CLOSURE_TOL
        # the loops always close again (all closures projected); where a clip stops (the
        # rotations at the constraint singularity 'rods-horizontal'), it is because the
        # platform does not follow, never because a parallelogram was left open
        assert not any("do not close again" in n for n in path.notes), path.notes
        if motion.kind is pinmob.MotionKind.TRANSLATION:  # the Delta translates everywhere (3T)
            assert path.complete, path.notes


@pytest.mark.parametrize("name", ["Bennett", "3-PRS"])
def test_curved_motions_are_followed_the_full_amplitude(name):
    # Bennett's coupler has one screw motion whose axis moves with the linkage; the 3-PRS's rotations
    # carry parasitic motions. Neither stays on the screw it starts with: each step is checked against the
    # free twist there (t projected on the free space), not against the starting screw, whose angle to the
    # free twist grows with the distance covered whatever the step size. Every frame must close, the
    # platform must really turn by most of the amplitude, and the end must be off the starting screw
    # (more than max_deviation: a check against it would have stopped the clip).
    mech = pinmob.load(name)
    q = pinmob.closed_configuration(mech, "generic")
    mob = pinmob.analyze(mech, q)
    motion = next(m for m in mob.motions if m.kind.value in ("R", "H"))
    path = follow_motion(mech, q, motion, amplitude=0.35, steps=8)
    assert path.complete, path.notes
    for qk in path.forward + path.backward:
        data = mech.model.createData()
        compute_kinematics(mech.model, data, qk)
        assert worst_residual(mechanism_residuals(mech, data), mech.length_scale) <= 1e-6
    for moved in path.displacement:
        assert moved.rotation > 0.25
    assert max(d.deviation for d in path.displacement) > MAX_DEVIATION


def _reach_limit(mech: pinmob.Mechanism, q: np.ndarray, limb: str, axis: np.ndarray, sign: float, top: float) -> float:
    """Largest angle [rad] the platform turns about ``sign * axis`` (through O) before ``limb`` cannot reach.

    A spherical RRR limb with link angles a1 (axes 1-2) and a2 (axes 2-3) reaches the platform
    exactly when the angle between its base axis u1 and its platform axis u3 lies in
    [|a1 - a2|, a1 + a2] (spherical triangle inequality); turning the platform turns u3.
    Bisection on that angle, up to ``top`` (inf when never out of reach).
    """
    model, data = mech.model, mech.model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    u1, u2, u3 = (data.J[3:, model.joints[model.getJointId(j)].idx_v] for j in mech.limb(limb).joints)
    a1, a2 = np.arccos(u1 @ u2), np.arccos(u2 @ u3)

    def inside(theta: float) -> bool:
        angle = np.arccos(np.clip(u1 @ (pin.exp3(sign * theta * axis) @ u3), -1.0, 1.0))
        return abs(a1 - a2) <= angle <= a1 + a2

    if inside(top):
        return np.inf
    lo, hi = 0.0, top
    for _ in range(60):
        lo, hi = ((lo + hi) / 2, hi) if inside((lo + hi) / 2) else (lo, (lo + hi) / 2)
    return lo


def test_short_spherical_clips_stop_at_a_limb_reach_limit_and_say_which_limb():
    # 'generic' is regular (singularity distance 0.0316), yet most clips stop after 0.005-0.3 rad:
    # limb A is 0.005 rad from its stretched pose there. Each stop must be where a limb really
    # stops reaching (the spherical triangle inequality, independent of the analysis), within one
    # continuation step, and the note must name that limb -- the nearest limit along the motion.
    mech = pinmob.load("3-RRR-spherical")
    q = pinmob.closed_configuration(mech, "generic")
    steps, stopped = 12, 0
    for motion in pinmob.analyze(mech, q).motions:
        path = follow_motion(mech, q, motion, steps=steps)
        step = path.amplitude / steps
        for sign, word, reached in ((1.0, "forwards", path.reached[0]), (-1.0, "backwards", path.reached[1])):
            limits = {b.name: _reach_limit(mech, q, b.name, motion.direction, sign, 0.5) for b in mech.limbs}
            nearest = min(limits, key=limits.__getitem__)
            note = [n for n in path.notes if f"stopped {word}" in n]
            if limits[nearest] > path.amplitude:
                assert not note and reached == pytest.approx(path.amplitude)
                continue
            stopped += 1
            assert limits[nearest] - step <= reached <= limits[nearest], (motion.label, word, reached, limits)
            assert len(note) == 1 and f"limb {nearest} reaches the edge of its workspace" in note[0], note
    assert stopped == 5


def test_the_flat_rotation_names_the_stretched_limbs(flat):
    q = pinmob.closed_configuration(flat, "flat")
    motion = next(m for m in pinmob.analyze(flat, q).motions if m.label == "R1 z")
    (note,) = follow_motion(flat, q, motion, steps=4).notes
    assert "limbs A, B, C are already at the edge of their workspace (a serial singularity" in note
