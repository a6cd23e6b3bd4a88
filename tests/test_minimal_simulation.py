"""Minimal closures in a simulator, with Pinocchio alone (issue 32, item 4).

The Bennett linkage of ``tests/data/bennett_weld.xml`` (a spatial 4R loop, 1 DoF, closed by a weld: 6
equations of rank 3) gets the minimal closure ``3d`` from pinmob (MJCF: weld -> connect). Pinocchio's own
constraint models are built here by hand from pinmob's closures (the two frames' parent joints and
placements): ``CONTACT_6D`` for the weld as declared, ``CONTACT_3D`` for the minimal closure, in the legacy
API (``RigidConstraintModel``) and the new one (``FrameAnchorConstraintModel`` / ``PointAnchorConstraintModel``).
Checked with Pinocchio's algorithms:

- ``getConstraintsJacobian``: the minimal constraints' Jacobian has full row rank (3) at the named
  configuration, the weld's has rank 3 of 6 rows, and both have the null space of pinmob's closure Jacobian,
  Bennett's motion (``theta3 = -theta1``, ``theta4 = -theta2`` with this file's twists);
- ``computeDelassusMatrix``: singular for the weld (3 zero eigenvalues, the redundant rows), non-singular for
  the minimal closure;
- ``constraintDynamics`` under gravity from the closed configuration, 0.3 s with a 1 ms step and Baumgarte
  stabilisation: the loop residual (the distance between the two frames' origins, and their relative
  rotation) stays below 1e-4 L and 1e-4 rad, and the motion is the Bennett motion (it moves: it is not stuck).

Inertias: MuJoCo's compiled body inertias of the same file (MuJoCo only as the file's reader; the dynamics is
Pinocchio's). Pinocchio has no constraint with fewer rows than a point contact: the planar and spherical
minimal closures (``planar_weld``, ``orientation``, ...) have no Pinocchio model, which is why this check uses a
spatial loop.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pinmob
from pinmob.screw.bases import subspace_gap

DATA = Path(__file__).resolve().parent / "data"
BENNETT = DATA / "bennett_weld.xml"
#: Loop residual bound of the simulation: position / L and rotation [rad].
RESIDUAL_BOUND = 1e-4


@pytest.fixture(scope="module")
def bennett():
    mujoco = pytest.importorskip("mujoco")
    mech = pinmob.load(BENNETT)
    report = pinmob.analyze(mech, "reference")
    model = pin.Model(mech.model)
    m = mujoco.MjModel.from_xml_path(str(BENNETT))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    data = model.createData()
    pin.forwardKinematics(model, data, report.state.q)
    for j in range(1, model.njoints):  # pinmob's joint j is MuJoCo's body j, placed alike: its inertia applies
        body = m.jnt_bodyid[m.joint(model.names[j]).id]
        np.testing.assert_allclose(data.oMi[j].translation, d.xpos[body], atol=1e-12)
        np.testing.assert_allclose(data.oMi[j].rotation, d.xmat[body].reshape(3, 3), atol=1e-12)
        rot = pin.Quaternion(*m.body_iquat[body]).toRotationMatrix()
        model.inertias[j] = pin.Inertia(
            m.body_mass[body], m.body_ipos[body], rot @ np.diag(m.body_inertia[body]) @ rot.T
        )
    return mech, report, model


def frames_of(mech, closure):
    """(joint, placement) of the closure's two frames in pinmob's model."""
    out = []
    for f in (closure.frame_a_id, closure.frame_b_id):
        frame = mech.model.frames[f]
        out.append((frame.parentJoint, pin.SE3(frame.placement)))
    return out


def legacy(model, mech, closure, kind):
    (ja, pa), (jb, pb) = frames_of(mech, closure)
    c = pin.RigidConstraintModel(kind, model, ja, pa, jb, pb, pin.ReferenceFrame.LOCAL)
    c.name = closure.name
    return c


def jacobian(model, q, constraints):
    data = model.createData()
    datas = [c.createData() for c in constraints]
    pin.computeJointJacobians(model, data, q)
    for c, cd in zip(constraints, datas):  # the constraints' placements at q
        c.calc(model, data, cd)
    return pin.getConstraintsJacobian(model, data, constraints, datas)


def rank(a, rtol=1e-9):
    s = np.linalg.svd(a, compute_uv=False)
    return int(np.sum(s > rtol * s[0]))


def null(a, rtol=1e-9):
    _, s, vt = np.linalg.svd(a)
    return vt[rank(a, rtol) :].T


def test_pinmob_proposes_the_ball(bennett):
    mech, report, _ = bennett
    minimal = report.minimal_closures
    assert minimal is not None and minimal.complete
    (change,) = minimal.changes
    assert (change.name, change.type, change.rows, change.needed) == ("loop", "6d", 6, 3)
    assert str(change.proposed.type) == "3d"


def test_constraint_jacobians_rank_and_null_space(bennett):
    mech, report, model = bennett
    (closure,) = mech.closures
    q = report.state.q
    weld = jacobian(model, q, [legacy(model, mech, closure, pin.ContactType.CONTACT_6D)])
    ball = jacobian(model, q, [legacy(model, mech, closure, pin.ContactType.CONTACT_3D)])
    assert weld.shape == (6, 4) and rank(weld) == 3  # the weld as declared: 3 redundant rows
    assert ball.shape == (3, 4) and rank(ball) == 3  # the minimal closure: full row rank
    chain = report.mechanism_mobility
    assert chain.rank == 3 and chain.mechanism_dof == 1
    motions = chain.motions  # pinmob's closed-chain joint rates (hinges: no column scaling)
    assert subspace_gap(null(ball), motions) < 1e-7  # the gap's floor is sqrt(eps) ~ 1.5e-8
    assert subspace_gap(null(weld), motions) < 1e-7
    rates = null(ball)[:, 0]  # Bennett's motion: theta3 = -theta1 and theta4 = -theta2 (hence their rates)
    np.testing.assert_allclose(rates[2:], -rates[:2], atol=1e-9)


def test_new_api_gives_the_same_ranks(bennett):
    mech, report, model = bennett
    (closure,) = mech.closures
    (ja, pa), (jb, pb) = frames_of(mech, closure)
    q = report.state.q
    for kind, rows, expected in (
        (pin.FrameAnchorConstraintModel, 6, 3),
        (pin.PointAnchorConstraintModel, 3, 3),
    ):
        constraints = pin.StdVec_ConstraintModel()
        constraints.append(pin.ConstraintModel(kind(model, ja, pa, jb, pb)))
        data = model.createData()
        datas = pin.StdVec_ConstraintData()
        for c in constraints:
            datas.append(c.createData())
        pin.computeJointJacobians(model, data, q)
        for c, cd in zip(constraints, datas):
            c.calc(model, data, cd)
        jac = pin.getConstraintsJacobian(model, data, constraints, datas)
        assert jac.shape == (rows, 4) and rank(jac) == expected, kind.__name__


def delassus(model, q, constraints):
    data = model.createData()
    datas = [c.createData() for c in constraints]
    return pin.computeDelassusMatrix(model, data, q, constraints, datas)


def test_delassus_singular_for_the_weld_not_for_the_ball(bennett):
    mech, report, model = bennett
    (closure,) = mech.closures
    q = report.state.q
    weld = np.linalg.eigvalsh(delassus(model, q, [legacy(model, mech, closure, pin.ContactType.CONTACT_6D)]))
    ball = np.linalg.eigvalsh(delassus(model, q, [legacy(model, mech, closure, pin.ContactType.CONTACT_3D)]))
    assert np.sum(weld < 1e-10 * weld[-1]) == 3  # one zero eigenvalue per redundant row
    assert ball[0] > 1e-6 * ball[-1]  # non-singular, conditioned far from the round-off


def test_constraint_dynamics_under_gravity_keeps_the_loop_closed(bennett):
    mech, report, model = bennett
    (closure,) = mech.closures
    c = legacy(model, mech, closure, pin.ContactType.CONTACT_3D)
    c.setBaumgarteCorrectorParameters(pin.BaumgarteCorrectorParameters(100.0, 20.0))  # drives the residual back
    constraints = [c]
    data, datas = model.createData(), [c.createData()]
    pin.initConstraintDynamics(model, data, constraints, datas)
    q, v, tau = report.state.q.copy(), np.zeros(model.nv), np.zeros(model.nv)
    dt, length, worst = 1e-3, mech.length_scale, (0.0, 0.0)
    fa, fb = closure.frame_a_id, closure.frame_b_id
    for _ in range(300):
        a = pin.constraintDynamics(model, data, q, v, tau, constraints, datas)
        v = v + dt * a
        q = pin.integrate(model, q, dt * v)
        pin.framesForwardKinematics(model, data, q)
        rel = data.oMf[fa].actInv(data.oMf[fb])
        worst = (
            max(worst[0], np.linalg.norm(rel.translation) / length),
            max(worst[1], np.linalg.norm(pin.log3(rel.rotation))),
        )
    assert worst[0] < RESIDUAL_BOUND and worst[1] < RESIDUAL_BOUND, worst  # the dropped rotation rows hold too
    assert np.abs(q - report.state.q).max() > 1e-2  # it moved under gravity (not stuck)


@pytest.mark.parametrize("configuration", ["generic", "theta1-140deg"])
def test_builtin_bennett_at_each_named_configuration(configuration):
    """The built-in Bennett (limbs X and Y, Y's tip welded to the platform): pinmob's fix makes that weld a ball
    (``limb_Y``, 3d); Pinocchio's CONTACT_3D on its frames has full row rank at each named configuration, with
    the null space of pinmob's closed chain, where the CONTACT_6D of the weld has rank 3 of 6."""
    mech = pinmob.load("Bennett")
    fixed = pinmob.fix_closures(mech)
    (closure,) = fixed.closures
    assert (closure.name, str(closure.type)) == ("limb_Y", "3d")
    q = pinmob.analyze(mech, configuration).state.q
    model = pin.Model(mech.model)
    ball = jacobian(model, q, [legacy(model, fixed, closure, pin.ContactType.CONTACT_3D)])
    weld = jacobian(model, q, [legacy(model, fixed, closure, pin.ContactType.CONTACT_6D)])
    assert rank(ball) == ball.shape[0] == 3 and rank(weld) == 3
    motions = pinmob.analyze(fixed, q).mechanism_mobility.motions
    assert motions.shape[1] == 1 and subspace_gap(null(ball), motions) < 1e-7
