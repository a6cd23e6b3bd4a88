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
from model_cases import model_configurations, models_with_closures
from numpy.testing import assert_allclose

import pinmob
from pinmob.catalog import bennett_theta2, dh
from pinmob.catalog.delta import ARM, BASE_R, PLAT_R, ROD
from pinmob.catalog.tripods import TILT
from pinmob.screw.algebra import twist_scaling
from pinmob.screw.bases import subspace_gap
from pinmob.testing import assert_mobility

X, Y, Z = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]
XYZ = [X, Y, Z]


@cache
def mech(name: str) -> pinmob.Mechanism:
    return pinmob.load(name)


@cache
def q_of(name: str, config: str) -> np.ndarray:
    return pinmob.closed_configuration(mech(name), config)


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


def platform_pose(name: str, config: str) -> pin.SE3:
    """World pose of the platform frame at a configuration."""
    m = mech(name)
    data = m.model.createData()
    pin.framesForwardKinematics(m.model, data, q_of(name, config))
    return data.oMf[m.platform_id].copy()


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


@pytest.mark.parametrize("name", ["3-RPS", "3-PRS"])
def test_rps_prs_generic_parasitic(name):
    """At a tilted pose the literature's 1T2R (Hunt 1983; Lee & Shah 1988; Carretero et al. 2000) and pinmob's
    1T1R1H describe one and the same 3-system of free twists; by hand:

    - each limb exerts a force along its revolute axis t_i (horizontal) through its sphere centre s_i, so the
      free twists F (at the platform origin) are the 3 twists reciprocal to these forces, and the translation
      along z is one of them (t_i . z = 0): 1T;
    - a free twist whose angular velocity w has a z component can be made a pure rotation by adding the free
      z translation: pitch (w.v + lambda w_z) / w.w = 0 for lambda = -w.v / w_z. So F has a basis {T z, two
      pure rotations with tilted axes}: the literature's 1T2R (checked below);
    - exactly one direction of F (mod T z) has a horizontal w (one linear condition w_z = 0 on the 2 non-translation
      dimensions); adding T z leaves its pitch w.v / w.w unchanged, and it is not zero: a screw, the parasitic
      motion. pinmob's principal screws (DESIGN.md: pitches that no free translation can change are kept) report
      it as H and the rest as R: 1T1R1H.

    The twists reciprocal to the hand forces (positions of the joints from the model) span pinmob's free twists;
    the pitch of their horizontal-w member equals the H motion's pitch, and it is not round-off."""
    mob = check(name, "generic", dof=3, motion_type="1T1R1H", directions={"T": [Z]})
    free, _ = _rps_hand_free_twists(name, "generic", "r")
    length = mech(name).length_scale
    scale = twist_scaling(length)[:, None]
    assert subspace_gap(scale * free, scale * mob.free_twists) < 1e-6
    row = free[5]  # w_z of a member F c is row . c
    k = np.linalg.svd(free[3:])[2][2]  # coefficients of T z, the member with w = 0
    n = np.cross(row, k)  # row . n = 0 and n is not along k: the member with horizontal w (mod T z)
    t = free @ n
    w, v = t[3:], t[:3]
    pitch = float(w @ v / (w @ w))
    screw = next(m for m in mob.motions if m.kind.value == "H")
    assert abs(screw.direction[2]) < 1e-9
    assert_allclose(screw.pitch, pitch, atol=1e-9)
    assert abs(pitch) > 1e-3 * length  # a real parasitic screw, not round-off
    rot = next(m for m in mob.motions if m.kind.value == "R")
    assert abs(rot.direction[2]) > 1e-3  # its axis is tilted: the parasitic turn about z is visible
    # the 1T2R basis: two members with w_z = 1, each made pitch 0 by adding -w.v along T z, span F with T z
    rotations = []
    for c in (row / (row @ row), row / (row @ row) + n / np.linalg.norm(n)):
        t = free @ c
        t[2] -= t[3:] @ t[:3]
        assert abs(t[3:] @ t[:3]) < 1e-12
        rotations.append(t)
    basis = np.column_stack([[0.0, 0.0, 1.0, 0.0, 0.0, 0.0], *rotations])
    assert np.linalg.matrix_rank(scale * basis, tol=1e-9) == 3
    assert subspace_gap(scale * basis, scale * free) < 1e-6


@pytest.mark.parametrize("name", ["3-RPS", "3-PRS"])
def test_rps_prs_tilted_x(name):
    """Closed form at the pose ``tilted-x``: platform turned by phi = 20 deg about x, centre c = (r (1 - cos phi)/2,
    0, h), sphere centres s_i = c + r Rx(phi) e_i. Both mechanisms only require t_i . s_i = 0 (each sphere centre
    in the vertical plane of its limb, through the z axis): limb A gives c_y = 0, limbs B and C both give
    c_x = r (1 - cos phi) / 2. The limb forces are f_i = t_i through s_i; a twist [v; w] at c is free iff
    t_i . (v + w x rho_i) = 0 with rho_i = r Rx(phi) e_i. With s = sin phi, k = cos phi, tau = tan(phi/2):
    limb A gives v_y = -r w_z; B + C give w_z = w_y tau; B - C give v_x = r w_x s / 2. So F = span{T z,
    S = [(r s / 2) x; x], R = [(0, -r tau, r); (0, 1, tau)]}. S is a screw about the x axis through c with pitch
    r sin(phi) / 2 (w = x, v = (r s/2) x; adding T z cannot change it): it is the derivative of the pose family
    (Rx(phi), c(phi)) itself, d c_x / d phi = r sin(phi) / 2, the parasitic shift. R has pitch 0 (the z
    translation r chosen to cancel it) and axis direction (0, cos(phi/2), sin(phi/2)) through
    c + (w x v) / w.w = c + (r, 0, 0) = s_A; the x axis through c also passes through s_A."""
    r = 0.12
    pose = platform_pose(name, "tilted-x")
    assert_allclose(pose.rotation, pin.utils.rotate("x", TILT), atol=1e-9)
    assert_allclose(pose.translation[:2], [r * (1 - np.cos(TILT)) / 2, 0.0], atol=1e-9)
    s_a = pose.translation + [r, 0.0, 0.0]
    assert_allclose(joint_point(name, "tilted-x", "A_sa"), s_a, atol=1e-9)
    mob = check(
        name,
        "tilted-x",
        dof=3,
        motion_type="1T1R1H",
        directions={"T": [Z], "H": [X], "R": [[0.0, np.cos(TILT / 2), np.sin(TILT / 2)]]},
        through=s_a,
    )
    screw = next(m for m in mob.motions if m.kind.value == "H")
    assert_allclose(screw.pitch, r * np.sin(TILT) / 2, atol=1e-9)


def test_3prs_home():
    """Carretero et al. (2000): 1T2R; by hand as for the 3-RPS at home (forces in the platform plane z = 0.25 m)."""
    check("3-PRS", "home", dof=3, motion_type="1T2R", directions={"T": [Z], "R": [X, Y]}, through=[0.0, 0.0, 0.25])


@pytest.mark.parametrize("name", ["3-RPS", "3-PRS"])
def test_a_pencil_of_rotations_is_printed_on_the_world_axes(name):
    """At home every horizontal line through the platform centre is a rotation axis (derivations above): the
    report names the canonical pair, x and y, in the platform mobility and in the platform frame's motion on
    the closed chain alike (they once printed two different noise-chosen pairs, e.g. R1 [1, -0.0145, 0])."""
    report = pinmob.analyze(mech(name), "home")
    assert [m.label for m in report.motions] == ["T1 z", "R1 x", "R2 y"]
    frame = report.platform_frame
    assert frame is not None and [m.label for m in frame.motions] == ["T1 z", "R1 x", "R2 y"]


# --------------------------------------------------------------------------- Delta (parallelograms), Delta-3RUU

#: hand derivation of the parallelogram Delta, shared by the tests below. Limb i (radial e_i, tangent t_i): the two
#: S-S rods of its parallelogram are parallel (direction d_i) and each transmits a force along itself; two parallel
#: forces 2 w apart along t_i span the force along d_i (through the mid-line) and the couple (2 w t_i) x d_i, i.e.
#: n_i = t_i x d_i, normal to the parallelogram. The motor's revolute about t_i through B_i is reciprocal to the
#: couple (n_i . t_i = 0) but not to the force, whose line misses the motor axis unless d_i lies in the plane of
#: the arm and t_i (the limb's serial singularity, arm and rods aligned): one couple n_i per limb, and then also
#: the force. The platform's free twists are those reciprocal to all of them.
DELTA_CONFIGS = {
    # generic: three independent couples n_i -> the three translations
    "generic": {"dof": 3, "motion_type": "3T", "directions": {"T": XYZ}},
    # arms stretched: three forces along the rods, concurrent on the z axis but not coplanar, span every force
    # through that point; with the three independent couples n_i they span all wrenches: rigid to first order
    "arms-stretched": {"dof": 0, "motion_type": "rigid"},
    # rods horizontal and radial (d_i = -e_i): n_i = t_i x (-e_i) = z for every limb, rank 1: free are the three
    # translations and the rotations about x and y
    "rods-horizontal": {"dof": 5, "motion_type": "3T2R", "directions": {"T": XYZ, "R": [X, Y]}},
}


def test_delta_parallelograms_limbwise():
    """The limb-wise method on the Delta whose parallelograms are real loops (a closure inside each limb),
    against the hand derivation above at every configuration. The limb's joint screws must be restricted to the
    velocities that keep its own closure closed; without that each limb (motor, S, S: 7 joint screws of rank 6)
    looks unconstrained and the platform reads 3T3R. This test fails until pinmob.analyze does that."""
    for config, expected in DELTA_CONFIGS.items():
        check("Delta", config, **expected)


@pytest.mark.parametrize("config", list(DELTA_CONFIGS))
def test_delta_parallelograms_whole_mechanism(config):
    """The same hand derivation (DELTA_CONFIGS) with the whole-mechanism method (every closure, the platform
    frame's motion): Clavel's Delta translates (3T); rigid with the arms stretched; 3T2R with the rods horizontal.
    Counting: nv = 3 x (1 + 3 + 3 + 3) = 30 joint rates; closures: 2 limb tips welded (12 rows) and 3 ball joints
    (9 rows), all independent at these poses, so the closed chain has 30 - 21 = 9 motions at generic poses: the
    platform's 3 and 6 idle rod spins (a rod between two balls turns about its own axis)."""
    check("Delta", config, method="mechanism", **DELTA_CONFIGS[config])
    mm = pinmob.analyze_mechanism(mech("Delta"), q_of("Delta", config))
    assert mm.idle_dof == 6 and mm.grubler == 9
    if config == "generic":
        assert mm.mechanism_dof == 9 and mm.redundant_constraints == 0 and mm.actuation.valid


def test_delta_special_poses_are_as_derived():
    """The model's special configurations are the hand ones: with the arms stretched the platform is at the
    bottom of the workspace, z = -sqrt((a + l)^2 - (R - r)^2), and every rod is aligned with its arm; with the
    rods horizontal the platform is at the elbows' height, z = -a sqrt(1 - ((l + r - R) / a)^2)."""
    bottom = -np.sqrt((ARM + ROD) ** 2 - (BASE_R - PLAT_R) ** 2)
    level = -ARM * np.sqrt(1 - ((ROD + PLAT_R - BASE_R) / ARM) ** 2)
    for config, height in (("arms-stretched", bottom), ("rods-horizontal", level)):
        pose = platform_pose("Delta", config)
        assert_allclose(pose.translation, [0.0, 0.0, height], atol=1e-9)
        assert_allclose(pose.rotation, np.eye(3), atol=1e-9)
    for limb in "ABC":
        base = joint_point("Delta", "arms-stretched", f"{limb}_motor")
        top_a, top_b = (joint_point("Delta", "arms-stretched", f"{limb}_{r}_topa") for r in "ab")
        arm = 0.5 * (top_a + top_b) - base  # to the middle of the parallelogram's top side
        rod = joint_point("Delta", "arms-stretched", f"{limb}_a_bota") - top_a
        assert_allclose(np.cross(arm, rod), 0.0, atol=1e-9)
        top = joint_point("Delta", "rods-horizontal", f"{limb}_b_topa")
        assert_allclose(top[2], level, atol=1e-9)


def test_delta_3ruu_generic():
    """Clavel (1988): the Delta translates (3T). Its 3-RUU equivalent has Tsai's translational limb
    (actuator and first U axis parallel, middle axes parallel, last axis parallel to the first): one couple
    t x n per limb, three independent couples: 3T."""
    check("Delta-3RUU", "generic", dof=3, motion_type="3T", directions={"T": XYZ})


def test_delta_3ruu_constraint_singular():
    """Hand derivation: the 3-RUU limb's couple is t x n with n = t x d, i.e. -d for a rod normal to t. With the
    rods horizontal and radial these couples are radial, all in the xy plane (rank 2): the 3-RUU gains the
    rotation about z (3T1R). The parallelogram Delta at the same kind of pose exerts n = t x d = z instead and
    gains the rotations about x and y (test_delta_parallelograms_*, rods-horizontal): the U-U equivalent has the
    same generic mobility but other constraint singularities."""
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
    """Grubler-Kutzbach (planar): the five-bar has 3 (5 - 1) - 2 x 5 = 2 DoF. Its end point E is carried by the
    model's virtual P-P chain V (a carriage that slides along x then y and cannot turn): 3 (7 - 1) - 2 x 8 = 2,
    unchanged. Hand derivation of the platform's (= the end point's) motion: limbs A and B (three revolutes
    about z each, non-collinear points) span the planar twists {T x, T y, R z}; V spans {T x, T y}; common:
    the two translations in the plane, 2T, and they are all the closed chain's motions (mechanism DoF 2, no idle
    motion). Second check, independent of the wrench analysis: the end point's position as a function of the
    two motor angles (planar trigonometry, circle intersection) has a rank-2 Jacobian here."""
    check("five-bar", "generic", dof=2, motion_type="2T", directions={"T": [X, Y]})
    mm = pinmob.analyze_mechanism(mech("five-bar"), q_of("five-bar", "generic"))
    assert mm.mechanism_dof == 2 and mm.idle_dof == 0
    a1, b1 = np.array([-0.1, 0.0]), np.array([0.1, 0.0])

    def end_point(t1: float, t2: float) -> np.ndarray:
        """E from the motor angles: elbows on circles of 0.2 m, E at 0.25 m from both (the upper intersection)."""
        ea = a1 + 0.2 * np.array([np.cos(t1), np.sin(t1)])
        eb = b1 + 0.2 * np.array([np.cos(t2), np.sin(t2)])
        d = np.linalg.norm(eb - ea)
        u = (eb - ea) / d
        return ea + d / 2 * u + np.sqrt(0.25**2 - (d / 2) ** 2) * np.array([-u[1], u[0]])

    elbow_a = joint_point("five-bar", "generic", "A_r2")[:2] - a1
    elbow_b = joint_point("five-bar", "generic", "B_r2")[:2] - b1
    t0 = np.array([np.arctan2(elbow_a[1], elbow_a[0]), np.arctan2(elbow_b[1], elbow_b[0])])
    assert_allclose(end_point(*t0), [0.0, 0.3], atol=1e-12)
    jac = np.column_stack([(end_point(*(t0 + h)) - end_point(*(t0 - h))) / 2e-6 for h in np.eye(2) * 1e-6])
    assert np.linalg.matrix_rank(jac, tol=1e-6) == 2


def test_five_bar_limb_b_stretched():
    """Hand derivation: limb B is stretched (B1, B2 and the end point E collinear, |E - B1| = 0.2 + 0.25 m), so its
    revolutes about z through three collinear points span only {R z through the line, the translation normal to
    it}: B exerts a force along the line B1 E. The carriage only translates, so it keeps the one translation
    normal to B1 E: 1T (1 DoF), a serial (type I) singularity of the five-bar (Gosselin & Angeles 1990)."""
    c = "limb-B-stretched"
    b1, b2, e = (joint_point("five-bar", c, j) for j in ("B_r1", "B_r2", "B_r3"))
    assert_allclose(np.linalg.norm(e - b1), 0.45, atol=1e-12)
    assert_allclose(np.cross(b2 - b1, e - b1), 0.0, atol=1e-12)
    check("five-bar", c, dof=1, motion_type="1T", directions={"T": [np.cross(Z, e - b1)]})


# --------------------------------------------------------------------------- Bennett


def test_bennett_geometry_is_bennett():
    """Bennett's conditions, checked on the model: a1/sin(alpha1) = a2/sin(alpha2) (opposite links equal by
    construction), and the DH loop with theta2 from Bennett's equation
    tan(theta1/2) tan(theta2/2) = sin((alpha2 + alpha1)/2) / sin((alpha2 - alpha1)/2) closes (the joints at
    both configurations satisfy it: the file's joint values are increments of theta1 and theta2)."""
    a1, al1, al2 = 0.2, np.deg2rad(40.0), np.deg2rad(70.0)
    a2 = a1 * np.sin(al2) / np.sin(al1)
    for theta1 in np.deg2rad([100.0, 140.0]):
        theta2 = bennett_theta2(theta1, al1, al2)
        loop = dh(theta1, a1, al1) @ dh(theta2, a2, al2) @ dh(-theta1, a1, al1) @ dh(-theta2, a2, al2)
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


# --------------------------------------------------------------------------- file expectations, both methods

CASES = model_configurations()
#: models with closures inside their limbs: the limb-wise check of their expectations is
#: test_delta_parallelograms_limbwise (it needs the closures taken into account limb by limb)
INNER_CLOSURES = models_with_closures()


@pytest.mark.parametrize("name,config", [(n, c) for n, c in CASES if n not in INNER_CLOSURES])
def test_file_expectation_agrees(name, config):
    """``pinmob analyze NAME --config C`` (limb-wise) agrees with the ``expected`` table of the model file."""
    m = mech(name)
    exp = m.expected[config]
    assert_mobility(m, q_of(name, config), dof=exp.dof, motion_type=exp.motion_type)
    assert exp.source


@pytest.mark.parametrize("name,config", CASES)
def test_whole_mechanism_agrees_with_file(name, config):
    """Second method: the platform frame's motion on the whole closed chain (every closure at once,
    :func:`pinmob.analyze_mechanism`) has the file's expected DoF and motion type."""
    m = mech(name)
    exp = m.expected[config]
    assert_mobility(m, q_of(name, config), dof=exp.dof, motion_type=exp.motion_type, method="mechanism")
