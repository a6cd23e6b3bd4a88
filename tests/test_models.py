"""Regression tests of the built-in models against the literature and hand derivations.

One test per model and configuration. Each asserts the DoF, the counts of
translations (T), rotations (R) and screws (H) through the motion type, and the
directions (and axis points) that the source states; the docstring gives the
source or the derivation. Expected values are never taken from pinmob's output.
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.catalog import bennett_theta2
from pinmob.screw import subspace_gap, twist_scaling
from pinmob.testing import assert_mobility

X, Y, Z = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]
XYZ = [X, Y, Z]


@cache
def mech(name: str) -> pinmob.Mechanism:
    return pinmob.load(name)


@cache
def q_of(name: str, config: str) -> np.ndarray:
    return mech(name).configuration(config)


def joint_point(name: str, config: str, joint: str) -> np.ndarray:
    """World position of a joint's origin (on its axis) at a configuration [m]."""
    m = mech(name)
    data = m.model.createData()
    pin.forwardKinematics(m.model, data, q_of(name, config))
    return data.oMi[m.model.getJointId(joint)].translation.copy()


def joint_axis(name: str, config: str, joint: str) -> np.ndarray:
    """World direction of a one-DoF joint's axis (angular part of its Jacobian column)."""
    m = mech(name)
    data = m.model.createData()
    pin.computeJointJacobians(m.model, data, q_of(name, config))
    jid = m.model.getJointId(joint)
    col = pin.getJointJacobian(m.model, data, jid, pin.LOCAL_WORLD_ALIGNED)[:, m.model.joints[jid].idx_v]
    return col[3:] / np.linalg.norm(col[3:])


def check(name: str, config: str, **kw):
    return assert_mobility(mech(name), q_of(name, config), **kw)


# --------------------------------------------------------------------------- 3-UPU (Tsai)


def test_3upu_generic():
    """Tsai (1996): with parallel inner and parallel outer U axes, each limb exerts one couple along t x n;
    three independent couples leave exactly the three translations (3T)."""
    check("3-UPU", "generic", dof=3, motion_type="3T", directions={"T": XYZ})


def test_3upu_constraint_singular():
    """Hand derivation: with the platform in the base plane every leg is horizontal and radial (d = -e_i),
    the inner U axes become vertical (n = t x d ~ z) and the couples t x n ~ e_i all lie in the xy plane: rank 2.
    The free twists are the reciprocal of {couples in xy}: 3T plus the rotation about z. This is the kind of
    constraint singularity of Zlatanov, Bonev & Gosselin (2002), where the 3-UPU gains a rotation."""
    check("3-UPU", "constraint-singular", dof=4, motion_type="3T1R", directions={"T": XYZ, "R": [Z]})


# --------------------------------------------------------------------------- 3-UPU wrist


@pytest.mark.parametrize("config", ["generic", "home"])
def test_3upu_wrist(config):
    """Karouia & Herve (2000): first base axis and last platform axis through O, inner axes parallel; each limb
    exerts a force through O along its inner axes, three independent forces through O leave the three rotations
    about O (3R, every axis through O = (0, 0, 0.5) m)."""
    check("3-UPU-wrist", config, dof=3, motion_type="3R", directions={"R": XYZ}, through=[0.0, 0.0, 0.5])


# --------------------------------------------------------------------------- 3-RPS, 3-PRS


def test_3rps_home():
    """Hunt (1983), Lee & Shah (1988): 1T2R. By hand: each limb exerts a force through its sphere centre parallel
    to its base revolute axis; at home the three force lines lie in the platform plane z = 0.3 m, so the free
    twists are the translation along z and the rotations about every line of that plane (R x, R y through the
    platform centre)."""
    check("3-RPS", "home", dof=3, motion_type="1T2R", directions={"T": [Z], "R": [X, Y]}, through=[0.0, 0.0, 0.3])


def _rps_hand_free_twists(name: str, config: str, joint: str) -> tuple[np.ndarray, np.ndarray]:
    """Free twists at the platform origin reciprocal to the hand-derived limb forces (sphere centre, R axis)."""
    m = mech(name)
    data = m.model.createData()
    q = q_of(name, config)
    pin.framesForwardKinematics(m.model, data, q)
    origin = data.oMf[m.platform_id].translation
    rows = []
    for limb in "ABC":
        centre = joint_point(name, config, f"{limb}_sa") - origin
        f = joint_axis(name, config, f"{limb}_{joint}")
        rows.append(np.concatenate([f, np.cross(centre, f)]))
    w = np.array(rows)
    return np.linalg.svd(w)[2][3:].T, origin  # (6, 3) null space, twists [v; w]


@pytest.mark.parametrize("name,joint", [("3-RPS", "r"), ("3-PRS", "r")])
def test_rps_prs_generic_parasitic(name, joint):
    """At a tilted pose the literature's 1T2R (Hunt 1983; Lee & Shah 1988; Carretero et al. 2000) counts independent
    outputs: heave and two tilts, with x, y and the turn about z as parasitic motions. Instantaneously, by hand:
    the limb forces are horizontal (along the base revolute axes t_i) through the sphere centres, so the
    translation along z is always free (1T). Among the free twists exactly one family has a horizontal angular
    velocity w; its pitch w.v / w.w cannot be changed by adding the z translation, and it is not zero: the
    parasitic motion is a screw (H). The other direction has a z component, so a z translation makes it a pure
    rotation (R). Hence 1T1R1H, checked here against the twists reciprocal to the hand-derived forces."""
    mob = check(name, "generic", dof=3, motion_type="1T1R1H", directions={"T": [Z]})
    free, _ = _rps_hand_free_twists(name, "generic", joint)
    length = mech(name).length_scale
    scale = twist_scaling(length)[:, None]
    assert subspace_gap(scale * free, scale * mob.free_twists) < 1e-6
    # the hand twist with horizontal angular velocity: combination c with (w)_z = 0, other than the z translation
    w_part = free[3:]
    c = np.linalg.svd(np.vstack([w_part[2:3], np.zeros((0, 3))]))[2][1:].T  # coefficients with w_z = 0
    twists = free @ c
    horizontal = [t for t in twists.T if np.linalg.norm(t[3:]) > 1e-6]
    t = horizontal[0]
    pitch = float(t[3:] @ t[:3] / (t[3:] @ t[3:]))
    screw = [m for m in mob.motions if m.kind.value == "H"][0]
    assert abs(screw.direction[2]) < 1e-9
    assert_allclose(screw.pitch, pitch, atol=1e-9)
    assert abs(pitch) > 1e-3 * length  # a real parasitic screw, not round-off
    rot = [m for m in mob.motions if m.kind.value == "R"][0]
    assert abs(rot.direction[2]) > 1e-3  # its axis is tilted: the parasitic turn about z is visible


def test_3prs_home():
    """Carretero et al. (2000): 1T2R; by hand as for the 3-RPS at home (forces in the platform plane z = 0.25 m)."""
    check("3-PRS", "home", dof=3, motion_type="1T2R", directions={"T": [Z], "R": [X, Y]}, through=[0.0, 0.0, 0.25])


# --------------------------------------------------------------------------- Delta (3-RUU)


def test_delta_generic():
    """Clavel (1988): the Delta translates (3T). Its 3-RUU equivalent has Tsai's translational limb
    (actuator and first U axis parallel, middle axes parallel, last axis parallel to the first): one couple
    t x n per limb, three independent couples: 3T."""
    check("Delta-3RUU", "generic", dof=3, motion_type="3T", directions={"T": XYZ})


def test_delta_constraint_singular():
    """Hand derivation: with the rods horizontal and radial, n = t x d is vertical and the couples t x n are
    radial, all in the xy plane (rank 2): the 3-RUU gains the rotation about z (3T1R). The parallelogram Delta
    has two couples per limb and no such singularity; this is a property of the U-U equivalent."""
    check("Delta-3RUU", "constraint-singular", dof=4, motion_type="3T1R", directions={"T": XYZ, "R": [Z]})


# --------------------------------------------------------------------------- 4-RUU Schoenflies


def test_4ruu_generic():
    """Kong & Gosselin (2007), 3T1R limbs: actuator, first and last U axes vertical, middle axes horizontal (n);
    each limb exerts one horizontal couple z x n. Four horizontal couples of rank 2 leave 3T and the rotation
    about z (Schoenflies motion)."""
    check("4-RUU", "generic", dof=4, motion_type="3T1R", directions={"T": XYZ, "R": [Z]})


def test_4ruu_parallel_axes():
    """Hand derivation: all four middle axes along x, so every couple is along z x x = y (rank 1); the free
    rotations are those normal to y: about x and z (3T2R)."""
    check("4-RUU", "parallel-axes", dof=5, motion_type="3T2R", directions={"T": XYZ, "R": [X, Z]})


# --------------------------------------------------------------------------- 3-RRR spherical


def test_3rrr_spherical_generic():
    """Gosselin & Angeles (1990): all axes through O, each limb exerts three forces through O; the platform
    turns about O (3R, every axis through O = origin)."""
    check("3-RRR-spherical", "generic", dof=3, motion_type="3R", directions={"R": XYZ}, through=[0.0, 0.0, 0.0])


def test_3rrr_spherical_limb_a_stretched():
    """Hand derivation: limb A's three axes are coplanar (serial, type I singularity of Gosselin & Angeles 1990):
    its joint screws span only the rotations about O within that plane, so the platform keeps 2R, both axes in
    the plane of limb A's axes and through O."""
    plane = [joint_axis("3-RRR-spherical", "limb-A-stretched", f"A_r{i}") for i in (1, 3)]
    check(
        "3-RRR-spherical", "limb-A-stretched", dof=2, motion_type="2R", directions={"R": plane}, through=[0.0, 0.0, 0.0]
    )


# --------------------------------------------------------------------------- 3-RRR planar


def test_3rrr_planar_generic():
    """Gosselin & Angeles (1990): a planar 3-RRR moves in its plane, 2T1R (T x, y; R about z)."""
    check("3-RRR-planar", "generic", dof=3, motion_type="2T1R", directions={"T": [X, Y], "R": [Z]})


def test_3rrr_planar_limb_a_stretched():
    """Hand derivation: limb A's joints lie on the x axis; rotations about z through collinear points span
    {R z, translation normal to the line} = {R z, T y}, and that is all the platform keeps (1T1R)."""
    check("3-RRR-planar", "limb-A-stretched", dof=2, motion_type="1T1R", directions={"T": [Y], "R": [Z]})


# --------------------------------------------------------------------------- five-bar


def test_five_bar_generic():
    """Grubler-Kutzbach (planar): 3 (5 - 1) - 2 x 5 = 2 DoF. The platform is limb A's distal link (tip frame at
    the end point). Hand derivation of its motion type: its twists are the rotations about z through A1 and A2,
    i.e. through any point of line A1A2 -- one translation normal to A1A2 (the centre at infinity) and one
    rotation about z: 1T1R. The end point itself moves in 2T: the velocities of the free twists at the end point
    span the xy plane."""
    a1 = joint_point("five-bar", "generic", "A_r1")
    a2 = joint_point("five-bar", "generic", "A_r2")
    normal = np.cross(Z, a2 - a1)
    mob = check("five-bar", "generic", dof=2, motion_type="1T1R", directions={"T": [normal], "R": [Z]})
    velocities = mob.free_twists[:3]  # linear velocity of the platform origin = the end point
    assert np.linalg.matrix_rank(velocities, tol=1e-9) == 2
    assert subspace_gap(velocities, np.array([X, Y]).T) < 1e-9


def test_five_bar_limb_b_stretched():
    """Hand derivation: limb B is stretched (B1, B2 and the end point collinear), so its screws span only the
    rotations about z through points of that line; limb A's span the rotations through points of line A1A2.
    Common: the rotation about z through the intersection P of the two lines (1R, 1 DoF): a serial singularity
    of the five-bar (Gosselin & Angeles 1990)."""
    c = "limb-B-stretched"
    a1, a2 = joint_point("five-bar", c, "A_r1"), joint_point("five-bar", c, "A_r2")
    b1, e = joint_point("five-bar", c, "B_r1"), joint_point("five-bar", c, "B_r3")
    # P = a1 + s (a2 - a1) = b1 + r (e - b1)
    s, _ = np.linalg.solve(np.column_stack([(a2 - a1)[:2], -(e - b1)[:2]]), (b1 - a1)[:2])
    p = a1 + s * (a2 - a1)
    check("five-bar", c, dof=1, motion_type="1R", directions={"R": [Z]}, through=p)


# --------------------------------------------------------------------------- Bennett


def test_bennett_geometry_is_bennett():
    """Bennett's conditions, checked on the model: a1/sin(alpha1) = a2/sin(alpha2) (opposite links equal by
    construction), and the DH loop with theta2 from Bennett's equation
    tan(theta1/2) tan(theta2/2) = sin((alpha2 + alpha1)/2) / sin((alpha2 - alpha1)/2) closes (the joints at
    both configurations satisfy it: the file's joint values are increments of theta1 and theta2)."""
    from pinmob.catalog import _dh

    a1, al1, al2 = 0.2, np.deg2rad(40.0), np.deg2rad(70.0)
    a2 = a1 * np.sin(al2) / np.sin(al1)
    for theta1 in np.deg2rad([100.0, 140.0]):
        theta2 = bennett_theta2(theta1, al1, al2)
        loop = _dh(theta1, a1, al1) @ _dh(theta2, a2, al2) @ _dh(-theta1, a1, al1) @ _dh(-theta2, a2, al2)
        assert_allclose(loop, np.eye(4), atol=1e-12)
    m = mech("Bennett")
    pinmob.check_closed(m, q_of("Bennett", "theta1-140deg"))


def _bennett_fd_twist(config_theta1: float, d: float = 1e-6) -> np.ndarray:
    """Coupler twist [v; w] at the platform origin by central finite differences along Bennett's closure curve."""
    m = mech("Bennett")
    al1, al2 = np.deg2rad(40.0), np.deg2rad(70.0)
    ref1 = np.deg2rad(100.0)
    ref2 = bennett_theta2(ref1, al1, al2)
    poses = []
    for t1 in (config_theta1 - d, config_theta1 + d):
        d1, d2 = t1 - ref1, bennett_theta2(t1, al1, al2) - ref2
        q = m.q_from_joints({"X_j1": d1, "X_j2": d2})  # limb X alone: the coupler pose
        data = m.model.createData()
        pin.framesForwardKinematics(m.model, data, q)
        poses.append(data.oMf[m.platform_id].copy())
    rel = pin.log6(poses[0].actInv(poses[1])).vector / (2 * d)  # body twist of the coupler
    mid = pin.SE3.Interpolate(poses[0], poses[1], 0.5)
    v_world = mid.rotation @ rel[:3]
    w_world = mid.rotation @ rel[3:]
    return np.concatenate([v_world, w_world])


@pytest.mark.parametrize("config,theta1_deg", [("generic", 100.0), ("theta1-140deg", 140.0)])
def test_bennett(config, theta1_deg):
    """Bennett (1903): a 4R loop with 1 DoF although Grubler-Kutzbach gives 6 (4 - 4 - 1) + 4 = -2. The coupler
    moves relative to the opposite (ground) link on a screw (Baker 1988): 1H. Second method: the coupler's twist
    by finite differences along Bennett's closure equation (independent of pinmob's wrench analysis) has the
    same axis and pitch."""
    mob = check("Bennett", config, dof=1, motion_type="1H")
    t = _bennett_fd_twist(np.deg2rad(theta1_deg))
    w = t[3:]
    pitch = float(w @ t[:3] / (w @ w))
    motion = mob.motions[0]
    assert_allclose(abs(motion.direction @ w) / np.linalg.norm(w), 1.0, atol=1e-8)
    assert_allclose(motion.pitch, pitch, atol=1e-7)
    assert abs(pitch) > 1e-3


# --------------------------------------------------------------------------- Sarrus


def test_sarrus_generic():
    """Sarrus (1853): 1T along the common normal of the two hinge directions. By hand: limb A (axes x) spans
    {R x, T y, T z}, limb B (axes y) spans {R y, T x, T z}; common: T z. Grubler-Kutzbach gives 0."""
    check("Sarrus", "generic", dof=1, motion_type="1T", directions={"T": [Z]})


def test_sarrus_stretched():
    """Hand derivation: with both limbs straight (top dead centre) limb A spans only {R x, T y} and limb B
    {R y, T x}: nothing in common, the platform is first-order rigid there."""
    check("Sarrus", "stretched", dof=0, motion_type="rigid")


# --------------------------------------------------------------------------- 3-PRRR


def test_3prrr_generic():
    """Kim & Tsai (2003), Kong & Gosselin (2002): each PRRR limb with revolutes parallel to its slider exerts two
    couples normal to the slider; sliders along x, y, z: all three couples, 3T."""
    check("3-PRRR", "generic", dof=3, motion_type="3T", directions={"T": XYZ})


def test_3prrr_limb_a_flat():
    """Hand derivation: limb A's three revolute axes (along x) are coplanar, in the plane containing x and the
    line l through their points; the limb then also exerts a force along l, so the platform loses the
    translation along l and keeps 2T: along x and along n = x x l."""
    c = "limb-A-flat"
    line = joint_point("3-PRRR", c, "A_r3") - joint_point("3-PRRR", c, "A_r1")
    line[0] = 0.0
    check("3-PRRR", c, dof=2, motion_type="2T", directions={"T": [X, np.cross(X, line)]})


# --------------------------------------------------------------------------- three UR5 arms


def test_3ur5_generic():
    """Hand derivation: each UR5 arm away from its singularities has six independent joint screws and exerts no
    constraint, so the held object keeps its six DoF (3T3R)."""
    check("3-UR5", "generic", dof=6, motion_type="3T3R", directions={"T": XYZ, "R": XYZ})


def test_3ur5_wrist_singular():
    """Hand derivation: with wrist_2_joint = 0 arm A's joints 2, 3, 4 and 6 are parallel (direction u); their
    screws span only {R u, two translations normal to u}, the arm's screws have rank 5 and its one reciprocal
    wrench is a force f along u (f . v = 0 for v normal to u, tau . u = 0). The object keeps the five twists
    reciprocal to a force: the two translations normal to u and the three rotations about lines meeting the
    force line (2T3R)."""
    u = joint_axis("3-UR5", "wrist-singular", "A_shoulder_lift_joint")
    for j in ("A_elbow_joint", "A_wrist_1_joint", "A_wrist_3_joint"):
        assert_allclose(abs(joint_axis("3-UR5", "wrist-singular", j) @ u), 1.0, atol=1e-9)
    normal = np.linalg.svd(u[None, :])[2][1:]
    check("3-UR5", "wrist-singular", dof=5, motion_type="2T3R", directions={"T": normal, "R": XYZ})


def test_3ur5_meshes_load():
    """The arms keep their meshes: the visual model holds every UR5 link mesh, resolved to existing files."""
    import os

    m = mech("3-UR5")
    assert m.visual_model is not None and m.visual_model.ngeoms == 21
    assert all(os.path.exists(g.meshPath) for g in m.visual_model.geometryObjects)


# --------------------------------------------------------------------------- second method, file expectations

CASES = [(name, c) for name in sorted(pinmob.builtin_models()) for c in pinmob.load(name).configurations]


@pytest.mark.parametrize("name,config", CASES)
def test_closure_jacobian_agrees(name, config):
    """Independent method: free platform twists from the global loop-closure Jacobian span the same space as the
    limb-wise wrench analysis (compared dimensionless)."""
    m, q = mech(name), q_of(name, config)
    mob = pinmob.analyze(m, q)
    other = pinmob.closure_jacobian_twists(m, q)
    scale = twist_scaling(m.length_scale)[:, None]
    assert other.shape[1] == mob.dof
    assert subspace_gap(scale * mob.free_twists, scale * other) < 1e-6


@pytest.mark.parametrize("name,config", CASES)
def test_file_expectation_agrees(name, config):
    """``pinmob analyze NAME --config C`` agrees with the ``expected`` table of the model file."""
    m = mech(name)
    exp = m.expected[config]
    assert_mobility(m, q_of(name, config), dof=exp.dof, motion_type=exp.motion_type)
    assert exp.source
