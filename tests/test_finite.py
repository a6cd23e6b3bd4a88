"""Finite versus instantaneous mobility on classical cases, each against a hand derivation or a second method.

The source of every expected value is in the test's docstring (or in :mod:`finite_cases`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin
import pytest
from closed_samples import ClosedSet, motion_type, platform_twists, sampled_dimensions, trace
from finite_cases import (
    bricard_line_symmetric,
    four_bar_flat,
    generic_6r,
    joints_follow,
    platform_follows,
    three_rpr_radial,
)
from millimetres import in_millimetres, moved, q_in_millimetres
from numpy.testing import assert_allclose

import pinmob
import pinmob.analysis.finite.motion_tracing as tracing
from pinmob.analysis.chain.closed_chain import frame_rows
from pinmob.analysis.finite.branches import branch_joints
from pinmob.analysis.finite.finite_mobility import finite_mobility
from pinmob.analysis.finite.verdicts import Verdict
from pinmob.analysis.follow.motion_path import follow_rates
from pinmob.analysis.follow.path_follower import closed_rates
from pinmob.exceptions import ConfigurationError
from pinmob.scan import path_spec, with_finite
from pinmob.screw.algebra import twist_scaling


def finite(mech: pinmob.Mechanism, q, **kw) -> pinmob.Report:
    return pinmob.analyze(mech, q, finite=True, **kw)


def parallel(a: np.ndarray, b: np.ndarray) -> bool:
    """Two vectors along one line (either sense)."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    return abs(abs(a @ b) / (np.linalg.norm(a) * np.linalg.norm(b)) - 1.0) < 1e-6


def test_four_bar_branches_cross_at_the_change_point() -> None:
    """Equal opposite links, all four collinear (Müller 2016, the planar four-bar's bifurcation).

    By hand (:func:`finite_cases.four_bar_flat`): instantaneous DoF 2, two branches of DoF 1 with joint
    rates (1, -1, 1) (parallelogram) and (1, k, k), k = (ground + crank) / (crank - ground) = -2
    (antiparallelogram). With the crank held, B is fixed and C lies on two internally tangent circles
    (radius ground about B, crank about D, |BD| = ground - crank): one point, first-order free, rigid.
    """
    mech = four_bar_flat()
    fm = finite(mech, mech.neutral()).finite
    assert fm.free.mechanism_dof == 2 and fm.finite_mechanism_dof == 1
    assert [b.dimension for b in fm.free.branches] == [1, 1]
    tangents = [b.rates[:, 0] for b in fm.free.branches]
    for expected in ([1, -1, 1], [1, -2, -2]):
        assert sum(parallel(t, expected) for t in tangents) == 1, (expected, tangents)
    assert all(b.traced > 0 for b in fm.free.branches)
    # the kernel's basis (two motions): neither lies on a branch alone
    assert [v.verdict for v in fm.free.internal] == [Verdict.BRANCH_POINT] * 2
    assert fm.locked is not None and fm.locked.mechanism_dof == 1 and fm.finite_dof_locked == 0
    assert fm.free.samples.unexplained == 0 and fm.free.samples.per_branch == (1, 1)


def test_flat_3puu_rotation_and_internal_motions_are_shaky() -> None:
    """The seed paper's beta = 0 (docs/seed-paper.md): with links exactly R - r, every vertex must stay within R - r of its
    guide horizontally; a rotation about z or a tilt of any link needs more, at second order. The
    platform only translates along z (with the sliders): 1T finite, 1T1R instantaneous; each limb's
    internal motion (its U joints turning against each other, the slider following) is blocked at order 2.
    With the sliders held nothing moves: a tilted link is shorter horizontally (R - r) cos(beta).
    """
    report = finite(pinmob.load("3-PUU-flat"), "flat")
    fm = report.finite
    assert (fm.free.dof, fm.finite_dof, fm.free.mechanism_dof, fm.finite_mechanism_dof) == (2, 1, 5, 1)
    verdicts = {v.label: v for v in fm.motions}
    assert verdicts["T1 z"].verdict is Verdict.FINITE
    assert verdicts["R1 z"].verdict is Verdict.BLOCKED and verdicts["R1 z"].order == 2
    # a trace without the finite analysis: a step along each motion projected back on the closed set
    q = report.state.q
    mech = report.state.mechanism
    assert min(platform_follows(mech, q, verdicts["T1 z"].motion.twist)) > 0.5
    assert max(map(abs, platform_follows(mech, q, verdicts["R1 z"].motion.twist))) < 0.01
    assert [v.label for v in fm.free.internal] == ["limb A", "limb B", "limb C"]
    for v in fm.free.internal:
        assert v.verdict is Verdict.BLOCKED and v.order == 2
        assert set(v.joints) <= {f"{v.label[-1]}_{j}" for j in ("slider", "u1a", "u1b", "u2a", "u2b")}
        # what survives the projection is only its share along the finite branch (the sliders' 0.07)
        assert max(map(abs, joints_follow(mech, q, v.test.rates[: mech.model.nv]))) < 0.2
    (branch,) = fm.free.branches
    assert min(joints_follow(mech, q, branch.rates[:, 0])) > 0.99
    assert [b.motion_type for b in fm.free.branches] == ["1T"]
    assert fm.finite_dof_locked == 0 and [(v.label, v.order) for v in fm.locked.motions] == [("T1 z", 2), ("R1 z", 2)]
    doc = report.to_dict()
    assert (doc["finite_dof"], doc["finite_mechanism_dof"], doc["finite_dof_locked"]) == (1, 1, 0)
    assert {m["label"]: (m["finite"], m["order"]) for m in doc["finite"]["motions"]} == {
        "T1 z": (True, None),
        "R1 z": (False, 2),
    }


def test_3rpr_at_a_type_ii_singularity_is_shaky_with_the_legs_held() -> None:
    """Radial legs (:func:`finite_cases.three_rpr_radial`): leg length^2 = (R - r)^2 + R r phi^2 + O(phi^4) for a
    platform rotation phi about the centre. Legs held: instantaneous 1 (R1 z), finite 0, blocked at order 2.
    Legs free: the regular 2T1R of a planar 3-RPR.
    """
    mech = three_rpr_radial()
    fm = finite(mech, mech.neutral(), generic_rank=3).finite
    assert (fm.free.dof, fm.finite_dof) == (3, 3)
    assert fm.locked.dof == 1 and fm.finite_dof_locked == 0
    (motion,) = fm.locked.motions
    assert motion.label == "R1 z" and motion.verdict is Verdict.BLOCKED and motion.order == 2
    assert_allclose(motion.motion.point, [0, 0, 0], atol=1e-9)


def test_overconstrained_bennett_and_bricard_move_and_a_generic_6r_does_not() -> None:
    """Bennett (1903): 4R, Grubler-Kutzbach 6 (4 - 1) - 5 x 4 = -2, moves with 1 DoF. Bricard's line-symmetric
    6R (1897): Grubler-Kutzbach 0, 1 DoF, and by the half-turn symmetry |w1| = |w4|, |w2| = |w5|, |w3| = |w6|
    along the motion (:func:`finite_cases.bricard_line_symmetric`). Six random axes: rigid.
    """
    bennett = finite(pinmob.load("Bennett"), "generic")
    assert bennett.mechanism_mobility.grubler == -2
    assert bennett.finite.finite_dof == 1 and bennett.finite.finite_mechanism_dof == 1
    assert bennett.finite.motions[0].verdict is Verdict.FINITE
    bricard = bricard_line_symmetric()
    report = finite(bricard, bricard.neutral(), generic_rank=5)
    assert report.mechanism_mobility.grubler == 0
    fm = report.finite
    assert fm.finite_mechanism_dof == 1 and fm.finite_dof == 1 and fm.free.branches[0].traced > 0
    rates = fm.free.branches[0].rates[:, 0]
    names = list(bricard.model.names[1:])
    w = {n: abs(rates[i]) for i, n in enumerate(names)}
    for a, b in (("X_j1", "Y_j4"), ("X_j2", "Y_j5"), ("X_j3", "Y_j6")):
        assert w[a] == pytest.approx(w[b], rel=1e-6)
    rigid = generic_6r()
    fm = finite(rigid, rigid.neutral(), generic_rank=6).finite
    assert (fm.free.mechanism_dof, fm.finite_mechanism_dof, fm.finite_dof) == (0, 0, 0)


def _leg_lengths(anchors: np.ndarray, platform_points: np.ndarray, pose: pin.SE3) -> np.ndarray:
    """|p + R b_i - a_i| for each leg (hand-coded geometry, no Pinocchio kinematics)."""
    return np.linalg.norm(pose.translation + platform_points @ pose.rotation.T - anchors, axis=1)


def test_gough_stewart_at_fichters_pose_is_shaky_with_the_legs_held() -> None:
    """Fichter (1986): the platform turned by 90 deg has one uncontrolled twist with the legs held.

    Second method, by hand: leg lengths l(M exp(s t)) from the anchor points alone; J = dl/dxi (6 x 6, rank
    5), t its null vector, c its left null vector. A second-order motion exists iff ``c . l''(t, t) = 0``
    (no pose acceleration w can cancel it in ``J w + l''``); it is not: shaky, finite 0.
    """
    mech = pinmob.load("6-UPS")
    report = finite(mech, "type2")
    fm = report.finite
    assert fm.locked.dof == 1 and fm.finite_dof_locked == 0
    (motion,) = fm.locked.motions
    assert motion.verdict is Verdict.BLOCKED and motion.order == 2
    model, data = mech.model, mech.model.createData()
    pin.framesForwardKinematics(model, data, report.state.q)
    pose = data.oMf[mech.platform_id].copy()
    anchors, points = [], []
    for limb in mech.limbs:
        ids = [model.getJointId(j) for j in limb.joints]
        anchors.append(data.oMi[ids[0]].translation.copy())
        points.append(pose.actInv(data.oMi[ids[-1]].translation.copy()))
    a, b = np.array(anchors), np.array(points)
    h = 1e-5
    jac = np.column_stack(
        [
            (_leg_lengths(a, b, pose * pin.exp6(h * e)) - _leg_lengths(a, b, pose * pin.exp6(-h * e))) / (2 * h)
            for e in np.eye(6)
        ]
    )
    u, s, vt = np.linalg.svd(jac)
    assert s[-1] < 1e-6 * s[0] < s[-2]
    t, c = vt[-1], u[:, -1]
    k = 1e-3
    second = (
        _leg_lengths(a, b, pose * pin.exp6(k * t))
        + _leg_lengths(a, b, pose * pin.exp6(-k * t))
        - 2 * _leg_lengths(a, b, pose)
    ) / k**2
    assert abs(c @ second) > 1e-3 * np.abs(second).max()


def test_sarrus_at_its_top_dead_centre_moves_only_at_second_order() -> None:
    """Both limbs straight: to first order the platform is rigid and each knee may bend alone; at second order
    knee A lowers the platform by k_A a^2 and knee B by k_B b^2, which must agree: ``k_A a^2 = k_B b^2``,
    two lines (knees in/out together). Finite: 1 DoF on each, the platform translating along z
    (downwards only): finite 1T where the first-order analysis says rigid.
    """
    fm = finite(pinmob.load("Sarrus"), "stretched").finite
    assert (fm.free.dof, fm.finite_dof, fm.free.mechanism_dof, fm.finite_mechanism_dof) == (0, 1, 2, 1)
    assert [(b.dimension, b.motion_type, b.where) for b in fm.free.branches] == [(1, "1T", "near q")] * 2
    assert [(v.label, v.verdict) for v in fm.free.internal] == [(f"limb {x}", Verdict.BRANCH_POINT) for x in "AB"]
    assert [b.motions[0].label for b in fm.free.branches] == ["T1 z", "T1 z"]


def test_delta_with_stretched_arms_reaches_a_full_workspace() -> None:
    """Arms stretched (the bottom of the workspace): first-order rigid, yet the platform moves up into the
    workspace in 3T (finite 3): the lost freedoms appear at second order.
    """
    fm = finite(pinmob.load("Delta"), "arms-stretched").finite
    assert (fm.free.dof, fm.finite_dof) == (0, 3)
    assert [b.motion_type for b in fm.free.branches] == ["3T"]


def test_4ruu_is_kinematotropic_at_its_parallel_axes_configuration() -> None:
    """Two branches of different DoF meet (a kinematotropic point): the Schoenflies mode (4 DoF, 3T1R) and a
    2-DoF mode. Confirmed away from q: each branch is followed 0.3 rad and the first-order analysis there
    (a generic point of the branch) gives its DoF.
    """
    mech = pinmob.load("4-RUU")
    report = finite(mech, "parallel-axes")
    fm = report.finite
    assert sorted((b.dimension, b.motion_type) for b in fm.free.branches) == [(2, "2R"), (4, "3T1R")]
    rng = np.random.default_rng(1)
    for branch in fm.free.branches:
        path = follow_rates(
            mech, report.state.q, branch.rates @ rng.normal(size=branch.dimension), amplitude=0.3, steps=10
        )
        assert path.reached == (0.3, 0.3)
        far = pinmob.analyze(mech, path.forward[-1])
        assert far.dof == branch.dimension == far.mechanism_mobility.mechanism_dof


def _tilted(closed: ClosedSet, q: np.ndarray, tilt: np.ndarray) -> np.ndarray | None:
    """A closed configuration near q whose platform is turned by ``tilt`` (rad, about world x and y) from q's: Newton
    on the closure residual and the two tilt rows (Pinocchio's platform Jacobian), minimum-norm steps."""
    model, data, pid = closed.model, closed.data, closed.platform
    start = closed.pose(q).rotation
    x = q.copy()
    for _ in range(100):
        e, jac = closed.residual(x)
        rotation = closed.pose(x).rotation
        pin.computeJointJacobians(model, data, x)
        rows = pin.getFrameJacobian(model, data, pid, pin.LOCAL_WORLD_ALIGNED)[3:5] * closed.col
        e = np.r_[e, pin.log3(rotation @ start.T)[:2] - tilt]
        if np.max(np.abs(e)) < 1e-12:
            return x
        x = pin.integrate(model, x, closed.col * -np.linalg.lstsq(np.vstack([jac, rows]), e, rcond=1e-12)[0])
    return None


def test_delta_rods_horizontal_two_3dof_modes_meet() -> None:
    """The Delta with horizontal rods: every parallelogram in the platform's plane, its couple vertical, so to first
    order the platform also tilts (5 DoF, 3T2R). Per limb, with u the direction of rod a, a the edge, r the rod and t
    the motor axis, the quadrilateral closes when ``u . (R - I) t = -(a / 2r) |(R - I) t|^2``: R = I (the
    parallelograms, the 3T mode) or a tilted platform with the rods leaving the plane, a second mode whose
    tangent cone at q is not a linear space. Both are 3-dimensional (9 with the rods' idle spins); the five
    first-order freedoms never combine into more. Second method, Pinocchio alone: closed configurations
    with the platform tilted by 0.02 rad about x or y exist (it is not the 3T mode), and there the probes of
    :mod:`closed_samples` find 9 and 3 dimensions; closed samples near q give (3, 9), and with the motors
    held the platform stays put (0). The analysis decides it from closed samples (the conditions up to
    order 4 do not: it said "cannot decide") and names the branches.
    """
    mech = pinmob.load("Delta")
    report = finite(mech, "rods-horizontal")
    fm, q = report.finite, report.state.q
    assert (fm.finite_dof, fm.finite_mechanism_dof, fm.finite_dof_locked) == (3, 9, 0)
    assert [(b.dimension, b.dof) for b in fm.free.branches] == [(9, 3), (9, 3)]
    assert fm.free.branches[0].motion_type == "3T" and fm.free.branches[1].test is None
    assert "closed samples" in fm.free.evidence and "closed samples" in fm.locked.evidence
    closed = ClosedSet(mech)
    kinds = []
    for tilt in ([0.02, 0.0], [0.0, 0.02], [-0.014, 0.014]):
        p = _tilted(closed, q, np.array(tilt))
        assert p is not None and np.linalg.norm(closed.moved(q, p)) < 0.1
        assert closed.dimensions_at(p) == (9, 3)
        _, twists = closed.tangent_at(p)
        kinds.append(motion_type(twists, mech.length_scale))
    # the tilting mode's platform motion, from the pitches at the test's own samples: at the tilts about x and about
    # the bisector three screws (rotation parts of rank 3, every principal pitch non-zero); about y exactly (a
    # plane of symmetry) one of them degenerates into a translation, the others into rotations
    assert kinds == ["3H", "1T2R", "3H"]
    assert fm.free.branches[1].motion_type == "3H"
    name = report.to_dict()["finite"]["branch_point"]
    assert name == "two 3-DoF branches meet: 3T and 3H"
    assert f"branches through q: 2 ({name})" in str(fm) and "cannot decide" not in str(fm)
    # the 3T mode: the platform's twists at a sample reached by translating it (the test's own continuation)
    t = trace(
        closed,
        q,
        closed.null(q)
        @ (
            closed.null(q).T
            @ np.linalg.lstsq(platform_twists(closed, q, np.eye(mech.model.nv)), [1.0, 1.0, 1.0, 0, 0, 0], rcond=None)[
                0
            ]
        ),
        0.05,
        5,
    )
    assert t is not None and motion_type(closed.tangent_at(t)[1], mech.length_scale) == "3T"
    assert sampled_dimensions(mech, q) == (3, 9)
    assert sampled_dimensions(mech, q, tuple(mech.actuated)) == (0, 6)


#: The platform's motion type at the generic points of a branch (0.2 from q along it), where it is not the one the
#: analysis names: the analysis names the type at q (on the branch's tangent, which has the branch's DoF there),
#: and along these branches pitches or rotations appear that grow with the distance from q (the test below
#: measures them): the 3-PUU-vertical's 1T2R mode has two screws of opposite pitches +-0.0244 L per 0.1 from q,
#: whose axes tilt off the translation (z) so that one of them is a rotation again (1T1R1H); the Delta-3RUU's mixed 2T1R mode picks up rotations about the other axes (singular values of the
#: rotation parts 0.002 at 0.02 from q, 0.02 at 0.2: three screws, 3H). None: a pitch within a factor 2 of the
#: classification's tolerance there (the 4-RUU's 2R mode: -9.5e-4 L at 0.2), not asserted.
AT_GENERIC_POINTS: dict[tuple[str, str], str | None] = {
    ("3-PUU-vertical", "1T2R"): "1T1R1H",
    ("Delta-3RUU", "2T1R"): "3H",
    ("4-RUU", "2R"): None,
}


@pytest.mark.parametrize(
    ("name", "config"),
    [
        ("3-UPU", "constraint-singular"),
        ("Delta-3RUU", "constraint-singular"),
        ("4-RUU", "parallel-axes"),
        ("3-PUU-vertical", "vertical"),
        ("Sarrus", "stretched"),
    ],
)
def test_each_branch_traced_by_the_tests_own_continuation(name: str, config: str) -> None:
    """Where branches meet, each branch the analysis names is followed by the test's own continuation
    (:func:`closed_samples.trace`: Pinocchio's closure residual, Newton, no pinmob analysis), both ways from q along
    a random tangent of it. 0.002 from q the platform's motion type, from its twists' rotation ranks and principal
    pitches (:func:`closed_samples.motion_type`), is the one the analysis names (the type at q, the limit along the
    branch); 0.2 from q (a generic point of the branch) the closed chain's first-order DoF is the branch's, and the
    platform's type is the named one or the one of :data:`AT_GENERIC_POINTS`."""
    mech = pinmob.load(name)
    report = finite(mech, config)
    q = report.state.q
    branches = report.finite.free.branches
    assert len(branches) == 2
    closed = ClosedSet(mech)
    rng = np.random.default_rng(3)
    for branch in branches:
        direction = branch.rates @ rng.normal(size=branch.dimension)
        for sign in (1.0, -1.0):
            near = trace(closed, q, sign * direction, 0.002, 1)
            assert near is not None
            kind = motion_type(platform_twists(closed, near, closed.null(near)), mech.length_scale)
            assert kind == branch.motion_type, (sign, kind)
            far = trace(closed, q, sign * direction, 0.2, 10)
            assert far is not None
            null = closed.null(far)
            assert null.shape[1] == branch.dimension
            generic = AT_GENERIC_POINTS.get((name, branch.motion_type), branch.motion_type)
            if generic is not None:
                assert motion_type(platform_twists(closed, far, null), mech.length_scale) == generic, sign


def test_two_modes_with_the_actuators_held_leave_one_motion_growing_like_s_cubed() -> None:
    """The 3-UPU at its constraint singularity (two 3-DoF modes, 2T1R and 3T, meet) driven by A_u2a, B_u1b and C_leg:
    with those held one first-order motion is left (T1 z), passing the conditions of orders 2 and 3. The closure
    equations reduced to it (solved in every other direction by the test's own Newton, Pinocchio alone) leave a
    residual growing like s^3 (each doubling of s multiplies it by 8): q is isolated, the platform's finite DoF 0.
    The analysis said ``finite_dof_locked`` None at the default order bound 4 (its closed samples, "closed" within
    the closure tolerance at s^3 ~ 1e-6, lay on no branch).
    """
    import dataclasses

    base = pinmob.load("3-UPU")
    limbs = tuple(dataclasses.replace(b, actuated=(a,)) for b, a in zip(base.limbs, ("A_u2a", "B_u1b", "C_leg")))
    mech = dataclasses.replace(base, limbs=limbs, extra_actuated=())
    report = finite(mech, "constraint-singular")
    fm, q = report.finite, report.state.q
    assert (fm.finite_dof, fm.finite_dof_locked) == (3, 0)
    assert report.to_dict()["finite"]["branch_point"] == "two 3-DoF branches meet: 2T1R and 3T"
    assert fm.locked.mechanism_dof == 1 and fm.locked.finite_mechanism_dof == 0
    assert "grow like s^3" in fm.locked.evidence
    ((label, verdict),) = [(v.label, v.verdict) for v in fm.locked.motions]
    assert (label, verdict) == ("T1 z", Verdict.BLOCKED)
    closed = ClosedSet(mech, tuple(mech.actuated))
    (n,) = closed.null(q).T
    others = np.linalg.svd(np.eye(mech.model.nv)[:, closed.free] - np.outer(n, n[closed.free]))[0]
    others = others[:, : int(closed.free.sum()) - 1]  # the free joint directions orthogonal to n
    values = []
    for s in (0.01, 0.02, 0.04):
        w = np.zeros(others.shape[1])
        for _ in range(50):
            e, jac = closed.residual(pin.integrate(mech.model, q, closed.col * (s * n + others @ w)))
            w -= np.linalg.lstsq(jac @ others, e, rcond=1e-12)[0]
        values.append(
            np.linalg.norm(closed.residual(pin.integrate(mech.model, q, closed.col * (s * n + others @ w)))[0])
        )
    assert values[0] > 1e-8 and all(7 < b / a < 9 for a, b in zip(values, values[1:]))
    assert sampled_dimensions(mech, q, tuple(mech.actuated)) == (0, 0)


def test_the_fallback_evidence_alone_on_shaky_held_configurations() -> None:
    """The evidence of :mod:`pinmob.analysis.finite.sample_modes` on its own, where the hand derivations above know the
    answer: the flat 3-PUU with its sliders held (two first-order motions, each blocked at order 2: a tilted link is
    shorter horizontally) is rigid, every closed sample falling back onto q; Fichter's pose with the legs held (one
    motion, ``c . l''(t, t) != 0``: blocked at order 2) leaves a reduced equation growing like s^2."""
    from pinmob.analysis.finite.higher_order import HigherOrder
    from pinmob.analysis.finite.loop_screws import mechanism_loops
    from pinmob.analysis.finite.sample_modes import decide_by_samples
    from pinmob.assembly.assemble import joint_velocity_indices

    found = {}
    for name, config in (("3-PUU-flat", "flat"), ("6-UPS", "type2")):
        mech = pinmob.load(name)
        conf = pinmob.Configuration(mech, config)
        held = tuple(int(i) for i in joint_velocity_indices(mech, list(mech.actuated)))
        ho = HigherOrder(mechanism_loops(conf), 1e-6, held)
        ev = decide_by_samples(conf, ho.kernel[: mech.model.nv], ho, (), held, 1e-6)
        found[name] = (ev.finite_mechanism_dof, ev.finite_dof, ev.how)
    assert found["3-PUU-flat"][:2] == (0, 0) and "every one fell back onto q" in found["3-PUU-flat"][2]
    assert found["6-UPS"][:2] == (0, 0) and "grow like s^2" in found["6-UPS"][2]


def test_finite_analysis_does_not_depend_on_units() -> None:
    """The flat 3-PUU in millimetres: same verdicts, orders and finite DoF (pitches and points scale)."""
    mech = pinmob.load("3-PUU-flat")
    q = pinmob.closed_configuration(mech, "flat")
    mm = in_millimetres(mech)
    a = finite(mech, q, generic_rank=4).finite
    b = finite(mm, q_in_millimetres(mech, q), generic_rank=4).finite
    assert [(v.label, v.verdict, v.order) for v in a.motions] == [(v.label, v.verdict, v.order) for v in b.motions]
    assert (a.finite_dof, a.finite_mechanism_dof, a.finite_dof_locked) == (
        b.finite_dof,
        b.finite_mechanism_dof,
        b.finite_dof_locked,
    )
    assert a.tolerance == pytest.approx(b.tolerance, rel=1e-6)


def _summary(fm) -> tuple:
    """What must not change with units, placement or the random seed: finite DoF, branches, verdicts, notes."""
    verdicts = sorted((v.motion.kind.value, v.verdict.value, v.order) for v in fm.motions)
    locked = sorted((v.motion.kind.value, v.verdict.value, v.order) for v in fm.locked.motions) if fm.locked else []
    branches = sorted((b.dimension, b.dof, b.motion_type, b.where) for b in fm.free.branches)
    return fm.finite_dof, fm.finite_mechanism_dof, fm.finite_dof_locked, branches, verdicts, locked, fm.free.notes


@pytest.mark.parametrize(("name", "config", "expected"), [("4-RUU", "parallel-axes", 4), ("Sarrus", "stretched", 1)])
def test_branches_do_not_depend_on_units_placement_or_seed(name: str, config: str, expected: int) -> None:
    """The 4-RUU (a 4-DoF and a 2-DoF branch) and the Sarrus (two 1-DoF branches) in metres, in millimetres, turned
    and moved, under eight seeds: the same branches and verdicts (the cone's sampling missed the 4-RUU's 2R branch for
    2 seeds of 30, the Sarrus's second branch for 2, and the 4-RUU in millimetres said "cannot decide": "not a union
    of linear spaces")."""
    mech = pinmob.load(name)
    q = pinmob.closed_configuration(mech, config)
    generic = pinmob.analyze(mech, config).singularity.generic_rank
    rot = pin.rpy.rpyToMatrix(0.7, -0.4, 2.1)
    variants = [(mech, q), (in_millimetres(mech), q_in_millimetres(mech, q)), (moved(mech, rot, [0.4, -1.2, 3.0]), q)]
    variants.append((moved(variants[1][0], rot, [400.0, -1200.0, 3000.0]), variants[1][1]))
    reference = _summary(finite(mech, q, generic_rank=generic).finite)
    assert reference[0] == expected and reference[-1] == ()
    for variant, qv in variants:
        assert _summary(finite(variant, qv, generic_rank=generic).finite) == reference
        conf = pinmob.Configuration(variant, qv)
        for seed in range(1, 8):
            fm = finite_mobility(conf, 1e-6, seed=seed)
            assert (fm.finite_dof, sorted(b.dimension for b in fm.free.branches), fm.free.notes) == (
                reference[0],
                sorted(b[0] for b in reference[3]),
                (),
            )


@pytest.mark.parametrize(
    ("name", "config"),
    [("3-UPU", "constraint-singular"), ("Delta-3RUU", "constraint-singular"), ("3-PUU-vertical", "vertical"),
     ("Sarrus", "stretched")],
)  # fmt: skip
def test_branches_are_listed_in_one_order(name: str, config: str) -> None:
    """Branches are listed (and numbered in the motions' verdicts) in one order, whatever the random cone points: the
    larger first, then by motion type, then by tangent. They came in the order of the cone's groups, which the seed
    (or, with one seed, the machine's BLAS kernel) decided: 3-UPU 2T1R, 3T or 3T, 2T1R."""
    conf = pinmob.Configuration(pinmob.load(name), config)
    printed = set()
    for seed in range(6):
        fm = finite_mobility(conf, 1e-6, seed=seed)
        branches = [(b.dimension, b.motion_type, str(branch_joints(conf, b))) for b in fm.free.branches]
        printed.add((str(branches), tuple(v.words(True) for v in fm.motions + fm.free.internal)))
    assert len(printed) == 1, printed


def test_finite_analysis_does_not_depend_on_placement_or_limb_order() -> None:
    """The radial 3-RPR turned and moved in space, its limbs declared in another order: the same finite DoF,
    free and held, the same verdicts and orders, and the held rotation's axis through the moved centre."""
    rot = pin.rpy.rpyToMatrix(0.4, -0.3, 1.2)
    shift = (0.5, -0.2, 0.3)
    results = []
    for mech, centre in (
        (three_rpr_radial(), np.zeros(3)),
        (three_rpr_radial(order="CAB", rotation=rot, shift=shift), np.array(shift)),
    ):
        fm = finite(mech, mech.neutral(), generic_rank=3).finite
        verdicts = sorted((v.motion.kind.value, v.verdict.value, v.order) for v in fm.motions + fm.locked.motions)
        results.append((fm.finite_dof, fm.finite_mechanism_dof, fm.finite_dof_locked, verdicts))
        (held,) = fm.locked.motions
        axis_point = fm.conf.platform_origin + held.motion.point
        assert_allclose(np.cross(axis_point - centre, held.motion.direction), 0, atol=1e-9)
    assert results[0] == results[1]


def test_order_bound_is_checked(capsys) -> None:
    from pinmob.cli import main

    assert main(["analyze", "3-PUU", "--finite-order", "3"]) == 0  # implies --finite (it was silently ignored)
    assert "higher-order conditions up to order 3" in capsys.readouterr().out
    mech = pinmob.load("3-PUU")
    with pytest.raises(ConfigurationError, match="integer from 2 to 8, got 1"):
        pinmob.analyze(mech, "generic", finite=True, finite_order=1)
    fm = finite(mech, "generic", finite_order=2).finite
    assert fm.order == 2 and [len(v.test.residuals) for v in fm.motions] == [1, 1, 1]  # the 3-PUU's 3T: order 2 only
    conf = pinmob.Configuration(mech, "generic")
    assert finite_mobility(conf, 1e-6) is finite_mobility(conf, 1e-6)  # computed once per configuration


def test_scan_gives_each_samples_finite_dof(tmp_path, capsys) -> None:
    """``pinmob scan --finite``: the flat 3-PUU's path from 'flat' to 'flat-raised' stays in the flat family, where
    every configuration is shaky like 'flat' (docs/seed-paper.md's derivation: links exactly R - r): 2 DoF 1T1R to first
    order, finite 1 (and 1 for the whole mechanism) at every sample. The 3-PUU's generic-to-offset path is regular:
    finite = instantaneous = 3. ``--finite-order`` alone implies ``--finite``."""
    import csv

    from pinmob.cli import main

    flat, regular = tmp_path / "flat.csv", tmp_path / "regular.csv"
    assert main(["scan", "3-PUU-flat", "--from", "flat", "--to", "flat-raised", "-n", "4", "--finite",
                 "--csv", str(flat), "--no-progress"]) == 0  # fmt: skip
    assert "finite DoF of the platform at the assembled samples: 4 x 1 DoF" in capsys.readouterr().out
    rows = list(csv.DictReader(flat.open()))
    assert [(r["dof"], r["finite_dof"], r["finite_mechanism_dof"]) for r in rows] == [("2", "1", "1")] * 4
    assert main(["scan", "3-PUU", "--from", "generic", "--to", "offset", "-n", "3", "--finite-order", "3",
                 "--csv", str(regular), "--no-progress"]) == 0  # fmt: skip
    assert "order bound 3" in capsys.readouterr().out
    rows = list(csv.DictReader(regular.open()))
    assert [(r["dof"], r["finite_dof"], r["finite_mechanism_dof"]) for r in rows] == [("3", "3", "3")] * 3
    with pytest.raises(ConfigurationError, match="integer from 2 to 8, got 9"):
        with_finite(pinmob.load("3-PUU"), path_spec(pinmob.load("3-PUU"), "generic", "offset", 2), 9)
    assert main(["scan", "3-PUU", "--finite-order", "1", "--csv", str(regular), "--force"]) == 2
    assert capsys.readouterr().err.startswith("pinmob: error: the order bound of the finite analysis")


@pytest.mark.parametrize(
    ("name", "config"), [("Sarrus", "stretched"), ("3-PUU-flat", "flat"), ("five-bar", "limb-B-stretched")]
)
def test_printed_internal_motions_and_branches_do_not_depend_on_the_limbs_order(name: str, config: str) -> None:
    """Internal motions and branch tangents are printed on one canonical basis of their space.

    The same joint rates per label with the limbs declared in the reverse order (they were the SVD's basis:
    the Sarrus knees as A_r2 -1, A_r1 +0.5, A_r3 +0.5 or its negative), and each printed internal motion is
    a closed-chain motion leaving the platform still to first order (Pinocchio's Jacobians: K dq = 0,
    J_platform dq = 0).
    """
    import dataclasses

    from pinmob.assembly.residual import stacked_error

    mech = pinmob.load(name)
    printed = []
    for m in (mech, dataclasses.replace(mech, limbs=tuple(reversed(mech.limbs)))):
        doc = pinmob.analyze(m, config, finite=True).to_dict()["finite"]
        internal = {v["label"]: v["joints"] for v in doc["internal_motions"]}
        branches = [b["joints"] for b in doc["branches"]]
        printed.append((internal, branches))
    assert printed[0] == printed[1] and (printed[0][0] or printed[0][1])
    q = pinmob.closed_configuration(mech, config)
    data = mech.model.createData()
    pin.computeJointJacobians(mech.model, data, q)
    pin.updateFramePlacements(mech.model, data)
    _, k = stacked_error(mech, mech.model, data, mech.all_closures)
    platform = pin.getFrameJacobian(mech.model, data, mech.platform_id, pin.LOCAL_WORLD_ALIGNED)
    for joints in printed[0][0].values():
        dq = np.zeros(mech.model.nv)
        for joint, rate in joints.items():
            dq[mech.model.joints[mech.model.getJointId(joint)].idx_v] = rate
        assert np.abs(k @ dq).max() < 1e-5 and np.abs(platform @ dq).max() < 1e-5


def test_internal_motions_of_a_mechanism_without_limbs_do_not_depend_on_the_basis() -> None:
    """An MJCF five-bar (no limbs): its closed chain's motions, given on any orthonormal basis, are printed as the
    same canonical motions (they were the basis given: another SVD, another 'motion 1')."""
    from pathlib import Path

    from pinmob.analysis.chain.closed_chain import closed_chain
    from pinmob.analysis.finite.finite_side import internal_motions

    mech = pinmob.load(Path(__file__).parent / "data" / "formats" / "fivebar" / "fivebar.xml")
    conf = pinmob.analyze(mech).state
    null = closed_chain(conf, 1e-6).null
    assert null.shape[1] == 2 and not mech.limbs
    rng = np.random.default_rng(5)
    reference = internal_motions(conf, null)
    for _ in range(4):
        turned = internal_motions(conf, null @ np.linalg.qr(rng.normal(size=(2, 2)))[0])
        assert [label for label, _ in turned] == [label for label, _ in reference] == ["motion 1", "motion 2"]
        for (_, a), (_, b) in zip(turned, reference):
            assert_allclose(a, b, atol=1e-9)


def test_a_held_motion_followed_only_backwards_is_traced(monkeypatch: pytest.MonkeyPatch) -> None:
    """The 3-PUU at 'generic' with A's and B's sliders held keeps one translation (limb C's slider drives it).

    Its rates are followed with ``either=True``: backwards only when forwards stops short. Here the forward half
    is cut to q (as a singularity just ahead would cut it) and the real backward half is kept: the platform then
    moved along -twist, as predicted, and the motion counts as followed. On the old code its end was compared
    along +twist and the motion counted as not followed (0.0)."""
    mech = pinmob.load("3-PUU")
    conf = pinmob.Configuration(mech, "generic")
    model = mech.model
    held = tuple(model.joints[model.getJointId(n)].idx_v for n in ("A_slider", "B_slider"))
    null = closed_rates(conf, held, 1e-6)
    assert null.shape[1] == 1  # one motion left with two sliders held (3T less two)
    rates = null[:, 0]
    twist = twist_scaling(mech.length_scale) * (frame_rows(conf, mech.platform) @ rates)
    both = tracing.trace_rates(conf, rates, held, 1e-6, twist)
    assert both > 0

    def forward_cut(*args, **kwargs):
        path = follow_rates(*args, **{**kwargs, "either": False})  # both halves followed; the forward one cut
        return replace(path, forward=path.forward[:1], reached=(0.0, path.reached[1]))

    monkeypatch.setattr(tracing, "follow_rates", forward_cut)
    assert tracing.trace_rates(conf, rates, held, 1e-6, twist) == pytest.approx(both)
