"""Pinocchio's constraint models in and out: ``Mechanism.from_pinocchio`` and ``Mechanism.to_pinocchio``.

Truth: Pinocchio's own ``getConstraintsJacobian`` (its rank, by numpy's SVD) on the exported constraints;
Pinocchio's forward kinematics of its own mimic joints; a four-bar by hand (four parallel hinges: one DoF; a
ball closure's three equations have rank 2 in the plane, a weld's six rank 3); the round trip
file -> pinmob -> Pinocchio -> pinmob compared with the file's own answers.
"""

from __future__ import annotations

import dataclasses
import json
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest

import pinmob
from pinmob.model.closure import make_closure, make_coupling
from pinmob.model.constraint_models import ConstraintModelError, PinocchioExportWarning

DATA = Path(__file__).parent / "data"
EPR = DATA / "example-parallel-robots"

#: files of tests/data whose closures Pinocchio has no model for, or that do not close as declared (their
#: answers change, said in the export's warning: test_unmodelled_closures_are_named), or with no closure at all
UNMODELLED = {
    "couplings/humanoid_legs.xml": "polynomial joint couplings",
    "tendons/gripper.xml": "tendon couplings",
    "tendons/cable_hand.xml": "tendon couplings",
    "third_party/mujoco_testdata/multiple_constraints.xml": "a joint held at a value",
    "third_party/mujoco_testdata/core_smooth/rne_post/weld/tfratio0_multiple_constraints.xml": "a joint held at a value",
    "third_party/mujoco_testdata/core_constraint/dofless_weld.xml": "a weld of the world to itself",
}
NOT_CLOSED_OR_OPEN = {
    "example-parallel-robots/kangaroo_like/robot.yaml",  # does not close as declared
    "couplings/shaky_couplings.xml",  # tendon couplings only: nothing left to export
    "couplings/site_tendons.xml",
    "third_party/menagerie_franka_hand/hand.xml",
    "third_party/mujoco_testdata/actuation/tendon_dampratio.xml",
    "third_party/mujoco_testdata/sleep/equality.xml",
}
#: every built-in model, and every TOML, MJCF, Extended URDF, onshape-to-robot and mimic URDF file of tests/data
#: but those above
SOURCES = sorted(pinmob.builtin_models()) + sorted(
    name
    for pattern in ("*.toml", "*.xml", "robot.yaml", "cad_gaps/*/robot.urdf", "mimic/**/*.urdf")
    for p in DATA.rglob(pattern)
    if (name := str(p.relative_to(DATA))) not in UNMODELLED.keys() | NOT_CLOSED_OR_OPEN
    and not name.startswith("third_party/menagerie_xarm7_hand/xarm7")  # hand.xml / scene.xml include it
    and p.name != "package.xml"  # a ROS package's manifest beside a xacro description
)


#: closure tolerance per file whose loops close to CAD accuracy only (1 micrometre: tests/test_cad_gaps.py)
CLOSURE_TOL = {"cad_gaps/spherical_3rrr/robot.urdf": 3e-5}


def load(source: str) -> pinmob.Mechanism:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # meshes not found, MJCF parts left out: not what is tested here
        return pinmob.load(source if source in pinmob.builtin_models() else DATA / source)


def exported(mech: pinmob.Mechanism, api: str, mimic: bool = False) -> tuple[pin.Model, Any]:
    with warnings.catch_warnings():
        warnings.simplefilter("error", PinocchioExportWarning)  # every closure of SOURCES is written exactly
        return mech.to_pinocchio(api, mimic=mimic)


def reread(mech: pinmob.Mechanism, model: pin.Model, constraints: Any) -> pinmob.Mechanism:
    back = pinmob.Mechanism.from_pinocchio(
        model,
        constraints,
        platform=mech.platform or None,
        limbs={b.name: b.tip for b in mech.limbs},
        actuated=mech.actuated,
        name=mech.name,
        configurations=mech.configurations,
        expected=mech.expected,
        length_scale=mech.length_scale,
    )
    # what a Pinocchio model does not hold: MuJoCo's quaternion order, its actuators on tendons and their names
    return dataclasses.replace(
        back,
        quaternion_wxyz=mech.quaternion_wxyz,
        actuated_tendons=mech.actuated_tendons,
        joint_actuators=mech.joint_actuators,
    )


def answers(report: pinmob.Report) -> dict[str, Any]:
    mm = report.mechanism_mobility
    act = mm.actuation
    out = {
        "dof": mm.mechanism_dof,
        "rank": mm.rank,
        "redundant": mm.redundant_constraints,
        "idle": mm.idle_dof,
        "actuated": act.actuated,
        "actuation valid": act.valid,
        "locked dof": act.locked_dof,
        "redundant actuators": act.redundant_actuators,
        "motion type": report.motion_type if report.mobility is not None else None,
    }
    s = report.singularity
    if s is not None:
        out |= {"constraint singular": s.constraint, "actuation singular": s.actuation, "serial": s.limbs}
    return out


@pytest.mark.parametrize("api", ["new", "legacy"])
@pytest.mark.parametrize("source", SOURCES)
def test_round_trip_keeps_every_answer(source: str, api: str) -> None:
    """file -> pinmob -> Pinocchio -> pinmob: DoF, motion type, redundancy, actuation, singularity kept."""
    mech, tol = load(source), CLOSURE_TOL.get(source, 1e-6)
    first = pinmob.analyze(mech, closure_tol=tol)
    model, constraints = exported(mech, api, mimic=True)
    back = reread(mech, model, constraints)
    assert back.model.nq == mech.model.nq and back.model.nv == mech.model.nv
    again = pinmob.analyze(back, first.state.q, configuration=first.configuration, closure_tol=tol)
    assert answers(again) == answers(first)
    assert again.mechanism_mobility.rows == first.mechanism_mobility.rows


def document(report: pinmob.Report, couplings: set[str]) -> Any:
    """``report.to_dict()`` without the per-closure entries of the couplings, the closures in name order.

    A coupling goes through Pinocchio as a mimic joint, which has no name of its own, and Pinocchio wants a
    mimic joint after the joint it mimics: the couplings come back as ``mimic_<joint>``, each joint of a group
    coupled to the group's first joint (the same equations, written between other pairs). Their totals stay
    in the document (rows, rank, redundancy, DoF); their entries by name are left out.
    """

    def without(x: Any) -> Any:
        if isinstance(x, dict):
            return {k: without(v) for k, v in x.items() if k not in couplings}
        if isinstance(x, list):
            return [without(v) for v in x if not (isinstance(v, dict) and v.get("name") in couplings)]
        return x

    doc = without(json.loads(json.dumps(report.to_dict(), default=str)))
    doc["closures"] = sorted(doc["closures"], key=lambda c: c["name"])
    doc.pop("ignored", None)  # what the file held and pinmob does not read: never in a model it wrote
    for closure in (doc.get("minimal_closures") or {}).get("closures", []):
        # the proposal's two frames: Pinocchio keeps a constraint's joints and placements, not its frames'
        # names; the import names each end by a frame at that placement (another one of the same place)
        for side in ("proposed", "current"):
            if isinstance(closure.get(side), dict):
                closure[side].pop("frames", None)
    return doc


def coupling_names(mech: pinmob.Mechanism) -> set[str]:
    return {c.name for c in mech.closures if c.type == "joint"}


def close(a: Any, b: Any, path: str = "") -> list[str]:
    """Where two documents differ (numbers within 1e-6 relative; NaN equals NaN)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return [d for k in a.keys() | b.keys() for d in close(a.get(k), b.get(k), f"{path}.{k}")]
    if isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        return [d for i, (x, y) in enumerate(zip(a, b)) for d in close(x, y, f"{path}[{i}]")]
    if isinstance(a, float) and isinstance(b, float):
        return [] if abs(a - b) <= 1e-6 * max(1.0, abs(a)) or (a != a and b != b) else [f"{path}: {a} != {b}"]
    return [] if a == b else [f"{path}: {a!r} != {b!r}"]


@pytest.mark.parametrize("source", SOURCES)
def test_round_trip_gives_the_same_report(source: str) -> None:
    """The whole report document (``pinmob analyze --json``) is the same after the round trip (new API).

    Only what a Pinocchio model cannot hold differs: the couplings' names and pairs, the frame names of the
    minimal closures proposed (:func:`document`) and the order of the closures.
    """
    mech, tol = load(source), CLOSURE_TOL.get(source, 1e-6)
    first = pinmob.analyze(mech, closure_tol=tol)
    back = reread(mech, *exported(mech, "new", mimic=True))
    if first.configuration is not None and first.configuration in mech.configurations:
        again = pinmob.analyze(back, first.configuration, closure_tol=tol)
    else:  # found by projection: the same vector, said to be given
        again = pinmob.analyze(back, first.state.q, closure_tol=tol)
    a, b = document(first, coupling_names(mech)), document(again, coupling_names(back))
    if first.configuration is None or first.configuration not in mech.configurations:
        a["closed_configuration"].pop("method"), b["closed_configuration"].pop("method")
    assert close(a, b) == []


def pinocchio_rank(model: pin.Model, constraints: Any, q: np.ndarray, length: float) -> int:
    """The rank of Pinocchio's ``getConstraintsJacobian`` at q, lengths in units of L (numpy's SVD)."""
    data = model.createData()
    legacy = isinstance(constraints, pin.StdVec_RigidConstraintModel)
    datas = pin.StdVec_RigidConstraintData() if legacy else pin.StdVec_ConstraintData()
    for c in constraints:
        datas.append(c.createData())
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    for c, d in zip(constraints, datas):  # the constraint's placements at q (both APIs read them)
        c.calc(model, data, d)
    jac = np.asarray(pin.getConstraintsJacobian(model, data, constraints, datas)).reshape(-1, model.nv)
    rows = []  # a row in metres (a point's, a frame's first three) is divided by L
    for c in constraints:
        size = 3 if (c.type == pin.ContactType.CONTACT_3D if legacy else c.residualSize() == 3) else 6
        rows += [1 / length] * 3 + [1.0] * (size - 3)
    cols = np.ones(model.nv)  # a slide's rate [m/s] is multiplied by L
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.nv == 1 and "P" in joint.shortname().replace("JointModel", "")[:1]:
            cols[joint.idx_v] = length
    scaled = np.asarray(rows)[:, None] * jac * cols[None, :]
    if scaled.size == 0:
        return 0
    sv = np.linalg.svd(scaled, compute_uv=False)
    return int((sv > 1e-7 * max(1.0, sv[0])).sum())


@pytest.mark.parametrize("api", ["new", "legacy"])
@pytest.mark.parametrize("source", SOURCES)
def test_pinocchio_rank_is_pinmob_rank(source: str, api: str) -> None:
    """The exported constraints' Jacobian rank (Pinocchio's) is pinmob's closure rank at every named configuration.

    (Every one that closes; the configuration pinmob finds for a file without one.) Joint couplings are left out of the export by
    default (Pinocchio's constrained algorithms refuse mimic joints): pinmob's rank is then that of the
    mechanism without them.
    """
    mech = load(source)
    kept = dataclasses.replace(mech, closures=tuple(c for c in mech.closures if not c.is_coupling))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PinocchioExportWarning)  # the couplings left out, said
        model, constraints = mech.to_pinocchio(api)
    tol = CLOSURE_TOL.get(source, 1e-6)
    configurations = [pinmob.analyze(mech, closure_tol=tol).state.q]  # the first, or the one pinmob finds
    for name in list(mech.configurations)[1:]:
        try:
            configurations.append(pinmob.closed_configuration(mech, name, tol))
        except pinmob.ClosureError:  # a keyframe that does not close (cassie's 'home'): pinmob refuses it too
            pass
    for q in configurations:
        pinmob_rank = pinmob.analyze_mechanism(kept, q, closure_tol=tol).rank if kept.all_closures else 0
        assert pinocchio_rank(model, constraints, q, mech.length_scale) == pinmob_rank
    if not kept.all_closures:  # couplings only: nothing exported, both ranks 0; the mimic export holds them instead
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PinocchioExportWarning)  # a coupling that closes a cycle, said
            mimicked, _ = mech.to_pinocchio(api, mimic=True)
        coupled = pinmob.analyze_mechanism(mech, configurations[0], closure_tol=tol)
        assert constraints == [] or len(constraints) == 0
        assert mimicked.nv == mech.model.nv - coupled.rank  # each independent coupling row: one coordinate fewer


# ---------------------------------------------------------------------------------------------- a four-bar by hand

#: ground 1.0, crank 0.4, coupler 1.2, rocker 0.8 [m]; the loop closes at the coupler's tip and the rocker's
CRANK, COUPLER, GROUND, ROCKER = 0.4, 1.2, 1.0, 0.8


def four_bar() -> tuple[pin.Model, tuple[int, pin.SE3, int, pin.SE3]]:
    """Three hinges about z in a tree (crank, coupler on the crank, rocker) and the loop's two ends."""
    model = pin.Model()
    crank = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "crank")
    coupler = model.addJoint(crank, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([CRANK, 0, 0])), "coupler")
    rocker = model.addJoint(0, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([GROUND, 0, 0])), "rocker")
    for j in (crank, coupler, rocker):
        model.appendBodyToJoint(j, pin.Inertia.FromBox(1.0, 0.1, 0.02, 0.02), pin.SE3.Identity())
    ends = (
        coupler,
        pin.SE3(np.eye(3), np.array([COUPLER, 0, 0])),
        rocker,
        pin.SE3(np.eye(3), np.array([ROCKER, 0, 0])),
    )
    return model, ends


def closed_angles(crank: float = 0.5) -> np.ndarray:
    """The hinge angles closing the loop at a crank angle, by hand: the coupler's tip P on two circles.

    |P - A| = COUPLER around the crank's tip A, |P - G| = ROCKER around the rocker's pivot G (the upper one).
    """
    a, g = CRANK * np.array([np.cos(crank), np.sin(crank)]), np.array([GROUND, 0.0])
    d = np.linalg.norm(g - a)
    along = (COUPLER**2 - ROCKER**2 + d**2) / (2 * d)
    p = a + along * (g - a) / d + np.sqrt(COUPLER**2 - along**2) * np.array([-(g - a)[1], (g - a)[0]]) / d
    coupler = np.arctan2(*(p - a)[::-1])
    return np.array([crank, coupler - crank, np.arctan2(*(p - g)[::-1])])


def hand_four_bar(kind: str) -> tuple[pin.Model, list[Any]]:
    """The four-bar's loop closed by one constraint of ``kind``.

    A weld (``CONTACT_6D``, a frame anchor) turns the closing point's hinge rigid: its rocker-side placement
    turns as the coupler does at :func:`closed_angles`, so that the triangle left closes there.
    """
    model, (j1, m1, j2, m2) = four_bar()
    if kind in ("CONTACT_6D", "frame anchor"):
        t = closed_angles()
        m2 = pin.SE3(pin.utils.rotate("z", t[0] + t[1] - t[2]), m2.translation)
    if kind == "CONTACT_3D":
        c = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, j1, m1, j2, m2, pin.LOCAL)
    elif kind == "CONTACT_6D":
        c = pin.RigidConstraintModel(pin.ContactType.CONTACT_6D, model, j1, m1, j2, m2, pin.LOCAL_WORLD_ALIGNED)
    elif kind == "point anchor":
        c = pin.ConstraintModel(pin.PointAnchorConstraintModel(model, j1, m1, j2, m2))
    elif kind == "bare point anchor":
        c = pin.PointAnchorConstraintModel(model, j1, m1, j2, m2)
    else:
        c = pin.ConstraintModel(pin.FrameAnchorConstraintModel(model, j1, m1, j2, m2))
    c.name = "loop"
    return model, [c]


@pytest.mark.parametrize(
    ("kind", "rows", "dof", "redundant"),
    [
        ("CONTACT_3D", 3, 1, 1),  # four parallel hinges (planar Grubler: 3 (4 - 1) - 2 x 4 = 1); 2 of 3 rows count
        ("point anchor", 3, 1, 1),
        ("bare point anchor", 3, 1, 1),
        ("CONTACT_6D", 6, 0, 3),  # the closing hinge welded: a triangle (0); 3 of 6 rows count (x, y, about z)
        ("frame anchor", 6, 0, 3),
    ],
)
def test_hand_built_four_bar(kind: str, rows: int, dof: int, redundant: int) -> None:
    """A four-bar built in Pinocchio: its DoF and redundant equations, at the hand-derived closed configuration."""
    model, constraints = hand_four_bar(kind)
    mech = pinmob.Mechanism.from_pinocchio(model, constraints, actuated=["crank"] if dof else ())
    (closure,) = mech.closures
    assert closure.name == "loop" and closure.rows == rows
    mm = pinmob.analyze(mech, closed_angles()).mechanism_mobility
    assert (mm.mechanism_dof, mm.redundant_constraints) == (dof, redundant)
    if dof:
        assert mm.actuation.valid and mm.actuation.actuated == ("crank",)


@pytest.mark.parametrize(
    ("names", "hinges", "rows"),
    [
        (("hinge", "hinge/axis"), None, 5),  # as to_pinocchio writes a revolute closure: one revolute again
        (("hinge/axis", "hinge"), None, 5),
        (("hinge", "hinge/axis"), False, 6),
        (("top", "bottom"), None, 6),  # a user's two anchors: their redundant row is counted
        (("top", "bottom"), True, 5),
    ],
)
def test_two_point_anchors_on_a_hinge(names: tuple[str, str], hinges: bool | None, rows: int) -> None:
    """Two point anchors on the loop's hinge axis: a revolute closure (5 rows) or two ``3d`` (6); rank 2 (x, y)."""
    model, (j1, m1, j2, m2) = four_bar()
    up = pin.SE3(np.eye(3), np.array([0, 0, 0.3]))
    anchors = [
        pin.ConstraintModel(pin.PointAnchorConstraintModel(model, j1, m1, j2, m2)),
        pin.ConstraintModel(pin.PointAnchorConstraintModel(model, j2, m2 * up, j1, m1 * up)),  # reversed ends
    ]
    anchors[0].name, anchors[1].name = names
    mech = pinmob.Mechanism.from_pinocchio(model, anchors, hinges=hinges)
    assert [c.type for c in mech.closures] == (["revolute"] if rows == 5 else ["3d", "3d"])
    if rows == 5:
        assert mech.closures[0].name == min(names, key=len)
    mm = pinmob.analyze(mech, closed_angles()).mechanism_mobility
    assert (mm.mechanism_dof, mm.rows, mm.redundant_constraints) == (1, rows, rows - 2)


def test_exported_four_bar_runs_in_pinocchio_constraint_dynamics() -> None:
    """Pinocchio's constrained forward dynamics accepts the legacy export; the loop's acceleration residual is 0."""
    model, constraints = hand_four_bar("CONTACT_3D")
    model.gravity = pin.Motion(np.array([0.0, -9.81, 0.0]), np.zeros(3))  # in the plane: the linkage falls
    mech = pinmob.Mechanism.from_pinocchio(model, constraints, actuated=["crank"])
    q = closed_angles()
    model2, exported_constraints = mech.to_pinocchio("legacy")
    data = model2.createData()
    datas = pin.StdVec_RigidConstraintData()
    for c in exported_constraints:
        datas.append(c.createData())
    pin.initConstraintDynamics(model2, data, exported_constraints, datas)
    v = np.zeros(model2.nv)
    prox = pin.ProximalSettings(1e-12, 1e-10, 20)  # regularised: the point's third row is redundant
    a = pin.constraintDynamics(model2, data, q, v, np.zeros(model2.nv), exported_constraints, datas, prox)
    pin.computeJointJacobians(model2, data, q)
    jac = pin.getConstraintsJacobian(model2, data, exported_constraints, datas)
    np.testing.assert_allclose(jac @ a, 0.0, atol=1e-8)  # at rest, the constraint's acceleration is J a
    assert np.linalg.norm(a) > 1e-3  # and it moves


# ---------------------------------------------------------------------------------------------- mimic joints


def mimic_model() -> pin.Model:
    """A hinge driving a mimicking slide along -x (negative scaling) and a mimicking hinge about a skew axis."""
    model = pin.Model()
    drive = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "drive")
    slide = model.addJoint(0, pin.JointModelPX(), pin.SE3(np.eye(3), np.array([0, 1.0, 0])), "slide")
    axis = np.array([1.0, 2.0, 2.0]) / 3.0
    skew = model.addJoint(
        slide, pin.JointModelRevoluteUnaligned(axis), pin.SE3(np.eye(3), np.array([0.5, 0, 0])), "skew"
    )
    for j in (drive, slide, skew):
        model.appendBodyToJoint(j, pin.Inertia.FromSphere(1.0, 0.05), pin.SE3.Identity())
    model.addFrame(pin.Frame("tip", skew, 0, pin.SE3(np.eye(3), np.array([0.3, 0.2, 0.1])), pin.FrameType.OP_FRAME))
    model = pin.transformJointIntoMimic(model, drive, slide, -0.5, 0.1)
    return pin.transformJointIntoMimic(model, drive, skew, 2.0, -0.3)


def test_mimic_joints_are_read_as_couplings() -> None:
    """Each mimic joint: a joint of its own and a coupling; the tip's pose along the coupling is Pinocchio's."""
    model = mimic_model()
    mech = pinmob.Mechanism.from_pinocchio(model, [], actuated=["drive"])
    assert (mech.model.nq, model.nq) == (3, 1)
    couplings = {c.name: (c.joints, c.polycoef) for c in mech.closures}
    assert couplings == {
        "mimic_slide": (("slide", "drive"), (0.1, -0.5)),
        "mimic_skew": (("skew", "drive"), (-0.3, 2.0)),
    }
    mm = pinmob.analyze(mech).mechanism_mobility
    assert (mm.mechanism_dof, mm.redundant_constraints) == (1, 0)
    for t in (-0.7, 0.0, 0.4):
        mimic_data, data = model.createData(), mech.model.createData()
        pin.framesForwardKinematics(model, mimic_data, np.array([t]))
        pin.framesForwardKinematics(mech.model, data, np.array([t, 0.1 - 0.5 * t, -0.3 + 2.0 * t]))
        tip = model.getFrameId("tip")
        np.testing.assert_allclose(
            data.oMf[mech.model.getFrameId("tip")].homogeneous, mimic_data.oMf[tip].homogeneous, atol=1e-12
        )
    back, constraints = mech.to_pinocchio(mimic=True)
    assert len(constraints) == 0 and back.nq == 1
    again, mimic_data = back.createData(), model.createData()
    pin.framesForwardKinematics(back, again, np.array([0.4]))
    pin.framesForwardKinematics(model, mimic_data, np.array([0.4]))
    np.testing.assert_allclose(
        again.oMf[back.getFrameId("tip")].homogeneous, mimic_data.oMf[model.getFrameId("tip")].homogeneous, atol=1e-12
    )


# ---------------------------------------------------------------------------------------------- warnings and errors


@pytest.mark.parametrize(
    ("kind", "axis_b", "says"),
    [
        ("universal", [0, 1, 0], "'bent' (universal): a point anchor"),
        ("cylindrical", None, "'bent' (cylindrical): left out"),
        ("planar", None, "'bent' (planar): left out"),
    ],
)
def test_closures_without_a_pinocchio_model_are_named(kind: str, axis_b: list[int] | None, says: str) -> None:
    mech = load("fourbar_revolute.toml")
    (c,) = mech.closures
    bent = make_closure(mech.model, "bent", c.frame_a, c.frame_b, kind, [0, 0, 1], axis_b)
    mech = dataclasses.replace(mech, closures=(bent,))
    for api in ("new", "legacy"):
        with pytest.warns(PinocchioExportWarning, match=r"1 closure\(s\)") as caught:
            _, constraints = mech.to_pinocchio(api)
        assert len(caught) == 1 and says in str(caught[0].message)
        assert len(constraints) == (1 if kind == "universal" else 0) + sum(1 for b in mech.limbs)


@pytest.mark.parametrize("source", sorted(UNMODELLED))
def test_unmodelled_closures_are_named(source: str) -> None:
    """Closures Pinocchio has no model for: left out of the export, each named in one warning.

    Tendon couplings, polynomial joint couplings (a mimic joint is linear), a joint held at a value, and a
    closure whose two frames are on one joint (no loop to close).
    """
    mech = load(source)
    model = mech.model
    unmodelled = [
        c.name
        for c in mech.closures
        if c.type == "tendon"
        or (c.type == "joint" and (len(c.joints) == 1 or any(c.polycoef[2:])))
        or model.frames[c.frame_a_id].parentJoint == model.frames[c.frame_b_id].parentJoint
    ]
    assert unmodelled
    with pytest.warns(PinocchioExportWarning) as caught:
        mech.to_pinocchio(mimic=True)
    assert len(caught) == 1
    message = str(caught[0].message)
    assert message.startswith(f"{len(unmodelled)} closure(s) have no exact Pinocchio constraint model")
    for name in unmodelled:
        assert f"{name!r} (" in message


def bad(model: pin.Model, kind: str) -> Any:
    if kind == "joint 0 twice":
        c = pin.RigidConstraintModel(pin.ContactType.CONTACT_6D, model, 0, pin.SE3.Identity(), 0, pin.SE3.Random())
    elif kind == "NaN placement":
        m = pin.SE3.Identity()
        m.translation = np.array([np.nan, 0, 0])
        c = pin.ConstraintModel(pin.PointAnchorConstraintModel(model, 1, m, 3, pin.SE3.Identity()))
    elif kind == "contact":
        c = pin.ConstraintModel(pin.PointContactConstraintModel(model, 1, pin.SE3.Identity(), 3, pin.SE3.Identity()))
    elif kind == "offset":
        c = pin.FrameAnchorConstraintModel(model, 1, pin.SE3.Identity(), 3, pin.SE3.Identity())
        c.desired_constraint_offset = np.array([0.1, 0, 0, 0, 0, 0])
    elif kind == "legacy offset":
        c = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, 1, pin.SE3.Identity(), 3, pin.SE3.Identity())
        c.desired_contact_placement = pin.SE3(np.eye(3), np.array([0, 0, 0.1]))
    elif kind == "joint limit":
        c = pin.ConstraintModel(pin.JointLimitConstraintModel(model, [1, 2]))
    else:
        c = pin.RigidConstraintModel(
            pin.ContactType.CONTACT_UNDEFINED, model, 1, pin.SE3.Identity(), 3, pin.SE3.Identity()
        )
    c.name = "oops"
    return c


@pytest.mark.parametrize(
    ("kind", "says"),
    [
        ("joint 0 twice", "joins joint 0 (the world) at both ends"),
        ("NaN placement", "joint1_placement is not finite"),
        ("contact", "PointContactConstraintModel is not a loop closure"),
        ("joint limit", "JointLimitConstraintModel is not a loop closure"),
        ("offset", "holds its ends apart (desired_constraint_offset is not the identity)"),
        ("legacy offset", "holds its ends apart (desired_contact_placement is not the identity)"),
        ("undefined contact", "CONTACT_UNDEFINED has no meaning as a loop closure"),
    ],
)
def test_bad_constraints_are_named(kind: str, says: str) -> None:
    model, good = hand_four_bar("point anchor")
    with pytest.raises(ConstraintModelError, match="constraint 'oops'") as raised:
        pinmob.Mechanism.from_pinocchio(model, [*good, bad(model, kind)])
    assert says in str(raised.value) and raised.value.constraint == "oops"
    assert "\n" not in str(raised.value)


def test_unnamed_constraint_is_named_by_its_index() -> None:
    model, _ = hand_four_bar("point anchor")
    c = pin.RigidConstraintModel(pin.ContactType.CONTACT_3D, model, 2, pin.SE3.Identity(), 2, pin.SE3.Random())
    with pytest.raises(
        ConstraintModelError, match=r"constraint 'constraint_models\[0\]' joins joint 'coupler' to itself"
    ):
        pinmob.Mechanism.from_pinocchio(model, [c])


def test_one_constraint_is_not_a_list() -> None:
    model, (c,) = hand_four_bar("CONTACT_3D")
    with pytest.raises(ConstraintModelError, match="constraint_models must be a list .* got RigidConstraintModel"):
        pinmob.Mechanism.from_pinocchio(model, c)


def test_unknown_api_is_refused() -> None:
    mech = load("Bennett")
    with pytest.raises(pinmob.ArgumentError, match="api must be one of 'new', 'legacy', got 'old'"):
        mech.to_pinocchio("old")


#: a hinge driving a slide along -y through MuJoCo's joint equality, and a slide along x driving a hinge
SLIDE_COUPLINGS = """
<mujoco model="slide_couplings">
  <worldbody>
    <body name="arm">
      <joint name="hinge" type="hinge" axis="0 0 1"/>
      <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.02"/>
      <site name="arm_tip" pos="0.5 0 0"/>
    </body>
    <body name="carriage" pos="1 0 0">
      <joint name="slide" type="slide" axis="0 -1 0"/>
      <geom type="box" size="0.05 0.05 0.05"/>
      <body name="flap" pos="0 0.2 0">
        <joint name="flap" type="slide" axis="1 0 0"/>
        <geom type="box" size="0.02 0.02 0.02"/>
        <site name="flap_tip" pos="0.1 0.1 0"/>
      </body>
    </body>
  </worldbody>
  <equality>
    <joint name="slide_follows" joint1="slide" joint2="hinge" polycoef="0.05 -0.3 0 0 0"/>
    <joint name="flap_follows" joint1="flap" joint2="slide" polycoef="0 2 0 0 0"/>
  </equality>
</mujoco>
"""


def test_slide_couplings_as_mimic_joints_move_as_in_mujoco(tmp_path: Path) -> None:
    """MJCF slide couplings exported as mimic joints: Pinocchio's sites where MuJoCo puts them (axis and sign)."""
    mujoco = pytest.importorskip("mujoco")
    path = tmp_path / "slide_couplings.xml"
    path.write_text(SLIDE_COUPLINGS)
    mech = load(str(path))
    model, constraints = exported(mech, "new", mimic=True)
    assert len(constraints) == 0 and model.nq == 1 and len(model.mimicking_joints) == 2
    mj = mujoco.MjModel.from_xml_path(str(path))
    mj_data = mujoco.MjData(mj)
    data = model.createData()
    for t in (-0.6, 0.0, 0.35):
        slide = 0.05 - 0.3 * t
        mj_data.qpos[:] = [t, slide, 2 * slide]
        mujoco.mj_kinematics(mj, mj_data)
        pin.framesForwardKinematics(model, data, np.array([t]))
        for site in ("arm_tip", "flap_tip"):
            expected = mj_data.site_xpos[mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_SITE, site)]
            np.testing.assert_allclose(data.oMf[model.getFrameId(site)].translation, expected, atol=1e-12)
    back = reread(mech, model, constraints)
    assert {c.name for c in back.closures} == {"mimic_slide", "mimic_flap"}
    mm = pinmob.analyze(back).mechanism_mobility
    assert (mm.mechanism_dof, mm.redundant_constraints) == (1, 0)


@pytest.mark.parametrize(
    ("source", "dropped"),
    [
        ("third_party/menagerie_agility_cassie/cassie.xml", 0),
        ("third_party/menagerie_robotiq_2f85/2f85.xml", 1),  # Pinocchio's reader drops the <equality joint>
    ],
)
def test_pinocchio_mjcf_reader_through_from_pinocchio(source: str, dropped: int) -> None:
    """Pinocchio's own MJCF reader (its model and anchors, through from_pinocchio) against pinmob's (MuJoCo's).

    Two parsers of the same file: the same joints, the same connects, the same closure rank; the joint
    equality Pinocchio 4.1 leaves out frees one motion more.
    """
    model, points, frames = pin.buildModelAndConstraintsFromMJCF(str(DATA / source))
    theirs = pinmob.Mechanism.from_pinocchio(model, [*points, *frames])
    mine = load(source)
    assert [c.type for c in theirs.closures] == [c.type for c in mine.closures if not c.is_coupling]
    # the same joints in the same order (MuJoCo's compiler names an unnamed free joint '#0', Pinocchio after its body)
    assert [j.nq for j in model.joints] == [j.nq for j in mine.model.joints]
    assert sum(a != b for a, b in zip(model.names, mine.model.names)) <= 1
    first = pinmob.analyze(mine)
    a, b = first.mechanism_mobility, pinmob.analyze(theirs, first.state.q).mechanism_mobility
    assert (b.mechanism_dof, b.rank) == (a.mechanism_dof + dropped, a.rank - dropped)


def test_mimic_hint_only_for_joint_couplings() -> None:
    """The warning suggests ``mimic=True`` where a linear joint coupling was left out, and only there."""
    for source, hinted in (("unnamed_parts.xml", True), ("tendons/gripper.xml", False)):
        with pytest.warns(PinocchioExportWarning) as caught:
            load(source).to_pinocchio()
        assert ("`mimic=True`" in str(caught[0].message)) == hinted


def test_pinocchio_constrained_algorithms_refuse_mimic_joints() -> None:
    """Why couplings are left out by default: Pinocchio 4.1's constrained algorithms refuse a mimic joint.

    Should a later Pinocchio accept them, ``mimic=True`` could become the default (this test then fails).
    """
    mech = load("third_party/menagerie_robotiq_2f85/2f85.xml")
    model, constraints = exported(mech, "legacy", mimic=True)
    data, datas = model.createData(), pin.StdVec_RigidConstraintData()
    for c in constraints:
        datas.append(c.createData())
    zero = np.zeros(model.nv)
    with pytest.raises(RuntimeError, match="does not support Joint Mimic"):
        pin.initConstraintDynamics(model, data, constraints, datas)
        pin.constraintDynamics(model, data, pin.neutral(model), zero, zero, constraints, datas)
    model, constraints = exported(mech, "new", mimic=True)
    data, new_datas = model.createData(), pin.StdVec_ConstraintData()
    for c in constraints:
        new_datas.append(c.createData())
    pin.computeJointJacobians(model, data, pin.neutral(model))
    with pytest.raises(RuntimeError, match="does not support Joint Mimic"):
        for c, d in zip(constraints, new_datas):
            c.calc(model, data, d)
        pin.getConstraintsJacobian(model, data, constraints, new_datas)


def test_coupling_chains_and_cycles_as_mimic_joints() -> None:
    """Couplings written as mimic joints of their group's first joint (composed along a chain, inverted where the
    coupled joint comes first); a coupling that closes a cycle is left out and named."""
    model = pin.Model()
    a = model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), "a")
    b = model.addJoint(a, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([0.5, 0, 0])), "b")
    c = model.addJoint(b, pin.JointModelPrismaticUnaligned(np.array([0.0, -0.6, 0.8])), pin.SE3.Identity(), "c")
    for j in (a, b, c):
        model.appendBodyToJoint(j, pin.Inertia.FromSphere(1.0, 0.05), pin.SE3.Identity())
    model.addFrame(pin.Frame("tip", c, 0, pin.SE3(np.eye(3), np.array([0.3, 0.1, 0.0])), pin.FrameType.OP_FRAME))
    for j, name in ((a, "a"), (b, "b"), (c, "c")):
        model.addFrame(pin.Frame(name, j, 0, pin.SE3.Identity(), pin.FrameType.JOINT))
    couplings = [  # q_b = 2 q_a + 0.1 (written from b), q_a = 4 q_c - 0.2 (a comes first: inverted), q_c = q_b (a cycle)
        make_coupling(model, "ba", ("b", "a"), (0.1, 2.0), (0.0, 0.0)),
        make_coupling(model, "ac", ("a", "c"), (-0.2, 4.0), (0.0, 0.0)),
        make_coupling(model, "cb", ("c", "b"), (0.0, 1.0), (0.0, 0.0)),
    ]
    mech = pinmob.Mechanism.from_model(model, {}, closures=couplings)
    with pytest.warns(PinocchioExportWarning, match=r"'cb' \(joint coupling\): left out \(it closes a cycle"):
        mimicked, constraints = mech.to_pinocchio(mimic=True)
    assert len(constraints) == 0 and mimicked.nq == 1 and list(mimicked.mimicking_joints) == [b, c]
    data, mimic_data = model.createData(), mimicked.createData()
    for t in (-0.4, 0.0, 0.7):
        pin.framesForwardKinematics(model, data, np.array([t, 2 * t + 0.1, (t + 0.2) / 4]))
        pin.framesForwardKinematics(mimicked, mimic_data, np.array([t]))
        np.testing.assert_allclose(
            mimic_data.oMf[mimicked.getFrameId("tip")].homogeneous,
            data.oMf[model.getFrameId("tip")].homogeneous,
            atol=1e-12,
        )
