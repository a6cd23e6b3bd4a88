"""Assembly: accuracy at singular solutions, symmetry, no winding, robust forward kinematics, modes, errors.

Every expected value comes from a hand derivation in the test's docstring (circle and sphere
intersections, the exact geometry of the flat 3-PUU, the Gough-Stewart pose written in its file),
or from a second computation (joint values instead of a pose), never from the solver's own output.
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from millimetres import in_millimetres
from numpy.testing import assert_allclose
from test_closed_chains import rocker_angles as rocker_angles_unwrapped

import pinmob
from pinmob import analyze_singularity
from pinmob.analysis.chain.actuation import default_end_frames
from pinmob.analysis.modes import assembly_modes, mode_distance, mode_signature
from pinmob.assembly.assemble import solve_actuated
from pinmob.assembly.coupling import polynomial_and_slope
from pinmob.assembly.residual import worst_residual
from pinmob.assembly.seeds import configuration_distance, random_configuration
from pinmob.exceptions import ClosureError, ConfigurationError
from pinmob.model.joints import outside_limits, wrap_angles
from pinmob.scan.scan_spec import platform_pose

DATA = Path(__file__).resolve().parent / "data"


def rocker_angles(crank: float) -> list[float]:
    """The two rocker angles closing the four-bar at a crank angle (circle intersection), in (-pi, pi]."""
    return [float(np.angle(np.exp(1j * a))) for a in rocker_angles_unwrapped(crank)]


def load(path: Path | str) -> pinmob.Mechanism:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the test models have no meshes
        return pinmob.load(path)


def joint(mech: pinmob.Mechanism, q: np.ndarray, name: str) -> float:
    return float(q[mech.model.joints[mech.model.getJointId(name)].idx_q])


# --------------------------------------------------------------------------- accuracy at singular solutions


def exact_flat_3puu() -> pinmob.Mechanism:
    """The flat 3-PUU (R = 0.3 m, r = 0.15 m, links R - r = 0.15 m) built from floats, not from rounded URDF text.

    Limb k at angle 2 pi k / 3 (radial e_k, tangent t_k): slider along z at R e_k; U joint (t_k, then z)
    there; link -0.15 e_k; U joint (z, then t_k); tip at a further -0.15 e_k = the platform centre.
    """
    model = pin.Model()
    for k, name in enumerate("ABC"):
        th = 2 * np.pi * k / 3
        e, t = np.array([np.cos(th), np.sin(th), 0.0]), np.array([-np.sin(th), np.cos(th), 0.0])
        j = model.addJoint(0, pin.JointModelPZ(), pin.SE3(np.eye(3), 0.3 * e), f"{name}_slider")
        j = model.addJoint(j, pin.JointModelRevoluteUnaligned(t), pin.SE3.Identity(), f"{name}_u1a")
        j = model.addJoint(j, pin.JointModelRZ(), pin.SE3.Identity(), f"{name}_u1b")
        j = model.addJoint(j, pin.JointModelRZ(), pin.SE3(np.eye(3), -0.15 * e), f"{name}_u2a")
        j = model.addJoint(j, pin.JointModelRevoluteUnaligned(t), pin.SE3.Identity(), f"{name}_u2b")
        model.addFrame(pin.Frame(f"{name}_tip", j, pin.SE3(np.eye(3), -0.15 * e), pin.FrameType.OP_FRAME))
    return pinmob.Mechanism.from_model(
        model, {n: f"{n}_tip" for n in "ABC"}, name="exact flat 3-PUU", actuated={n: [f"{n}_slider"] for n in "ABC"}
    )


def test_pose_assembly_is_polished_at_a_singular_solution():
    """Platform raised to z = 0.025 m, links horizontal (beta = 0): every limb is serially singular there.

    By hand: the closed configuration is sliders = z, every U angle 0 (each link horizontal and radial,
    length R - r exactly). Tilting a link by theta shortens its reach by 0.15 (1 - cos theta), so the
    residual grows as theta^2: a solve stopped at a residual of 1e-12 leaves theta ~ 1e-6, which is above
    the rank tolerance and turned 2 DoF 1T1R into 1 DoF 1T. Polished, theta must be below 1e-7 and the
    pose-assembled configuration must analyse like the joint-value one (a second route to the same pose).
    """
    mech = exact_flat_3puu()
    z = 0.025
    q = pinmob.assemble_pose(mech, pin.SE3(np.eye(3), np.array([0.0, 0.0, z])), mech.neutral(), max_iter=40)
    for name in "ABC":
        assert_allclose(joint(mech, q, f"{name}_slider"), z, atol=0.15 * 1e-7)  # link 0.15 m, tilt < 1e-7
        for u in ("u1a", "u1b", "u2a", "u2b"):
            assert abs(joint(mech, q, f"{name}_{u}")) < 1e-7, (name, u, joint(mech, q, f"{name}_{u}"))
    by_joints = mech.q_from_joints({f"{n}_slider": z for n in "ABC"})
    from_pose, direct = pinmob.analyze(mech, q), pinmob.analyze(mech, by_joints)
    assert (from_pose.dof, from_pose.motion_type) == (direct.dof, direct.motion_type) == (2, "1T1R")


def test_forward_kinematics_reaches_the_type2_pose():
    """6-UPS with the leg lengths of its Type II pose (z = 0.4 m, yaw = 1.57079632679 rad, written in the file).

    There the forward kinematics has a double root (the actuation singularity): the residual grows as the
    square of the distance, and the damped solver alone stopped ~1e-5 rad short, where the singularity was
    not seen. From the home configuration the platform must reach the written pose within 1e-7 and the
    singularity report must say actuation-singular.
    """
    mech = pinmob.load("6-UPS")
    conf = mech.configurations["type2"]
    legs = {n: joint(mech, pinmob.closed_configuration(mech, "type2"), n) for n in mech.actuated}
    sol = solve_actuated(mech, legs, pinmob.closed_configuration(mech, "home"), max_iter=40)
    gap = pin.log6(conf.pose.actInv(platform_pose(mech, sol.q))).vector
    assert np.max(np.abs(gap[3:])) < 1e-7 and np.max(np.abs(gap[:3])) < 1e-7 * mech.length_scale, gap
    assert analyze_singularity(mech, sol.q).actuation
    assert sol.residual < 1e-12


def test_projection_does_not_depend_on_units():
    """3-PUU projected onto the closed set from one perturbed configuration, in metres and in millimetres.

    The projection takes minimum-norm steps; measured in dimensionless rates (translations / L) the
    metric is the same in both units, so the same seed (sliders times 1000) must give the same angles
    and the sliders times 1000. (In raw joint units a 1 mm slider step would cost as much as 1 rad.)
    """
    mech = pinmob.load("3-PUU")
    mm = in_millimetres(mech)
    model = mm.model
    lin = np.array([model.joints[j].shortname().startswith("JointModelP") for j in range(1, model.njoints)])
    seed = pinmob.closed_configuration(mech, "generic") + np.random.default_rng(0).uniform(-0.05, 0.05, model.nq)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the URDF's slider limits are in metres
        q_m = pinmob.project(mech, seed).q
        q_mm = pinmob.project(mm, np.where(lin, 1000 * seed, seed)).q
    assert_allclose(q_mm, np.where(lin, 1000 * q_m, q_m), atol=1e-8)


# --------------------------------------------------------------------------- symmetry and winding


def test_symmetric_seed_gives_symmetric_solution_within_limits():
    """3-UPU at its constraint-singular pose, seeded A_u1a = B_u1a = C_u1a = 1.0 (symmetric under 120 deg).

    The limbs are copies of each other turned by 120 degrees, the seed and the pose are symmetric, and
    each limb is solved for the pose on its own: each joint must take the same value in the three limbs,
    inside the URDF limits [-pi, pi] (before: A_u1a = 17.742 = -1.107 + 6 pi, and B, C in another mode).
    """
    mech = pinmob.load("3-UPU")
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a joint outside its limits would warn
        q = pinmob.closed_configuration(mech, "constraint-singular")
    for label in ("u1a", "u1b", "leg", "u2a", "u2b"):
        values = [joint(mech, q, f"{n}_{label}") for n in "ABC"]
        assert_allclose(values, values[0], atol=1e-9, err_msg=label)
    assert not outside_limits(mech.model, q)
    assert np.all(np.abs(q[[mech.model.joints[mech.model.getJointId(f"{n}_u1a")].idx_q for n in "ABC"]]) <= np.pi)


def test_wrap_angles_respects_limits():
    """Revolutes with limits [-pi, pi], [0, 2 pi], none ([0, 0] as a URDF <limit> without bounds) and [2, 3].

    By hand: 7 -> 7 - 2 pi; -1 -> 2 pi - 1 (the (-pi, pi] value -1 is outside [0, 2 pi]); 4 -> 4 - 2 pi;
    2.5 + 2 pi -> 2.5. A prismatic coordinate is never wrapped.
    """
    model = pin.Model()
    for k in range(4):
        model.addJoint(0, pin.JointModelRZ(), pin.SE3.Identity(), f"r{k}")
    model.addJoint(0, pin.JointModelPX(), pin.SE3.Identity(), "p")
    model.lowerPositionLimit = np.array([-np.pi, 0.0, 0.0, 2.0, -1.0])
    model.upperPositionLimit = np.array([np.pi, 2 * np.pi, 0.0, 3.0, 1.0])
    q = wrap_angles(model, np.array([7.0, -1.0, 4.0, 2.5 + 2 * np.pi, 5.0]))
    assert_allclose(q, [7.0 - 2 * np.pi, 2 * np.pi - 1.0, 4.0 - 2 * np.pi, 2.5, 5.0], atol=1e-12)
    assert outside_limits(model, q) == ("p [-1, 1]",)


def test_joint_outside_its_limits_warns():
    """Four-bar (formats/fourbar) whose rocker is limited to [-0.1, 0.1] rad, crank at 0.4 rad.

    By hand (circle intersection, :func:`rocker_angles`) the rocker must turn by 0.46 or -1.35 rad:
    outside the limits either way, so the solution is returned with a warning naming the joint.
    """
    text = (DATA / "formats" / "fourbar" / "robot.urdf").read_text()
    head, tail = text.split('<joint name="R_rocker"', 1)
    tail = tail.replace('lower="-3.14159265359" upper="3.14159265359"', 'lower="-0.1" upper="0.1"', 1)
    model = pin.buildModelFromXML(head + '<joint name="R_rocker"' + tail)
    mech = pinmob.Mechanism.from_model(
        model, [], name="limited", closures=[pinmob.model.make_closure(model, "B", "L_tip", "R_tip", "3d")]
    )
    with pytest.warns(UserWarning, match="R_rocker"):
        sol = solve_actuated(mech, {"L_crank": 0.4})
    assert sol.outside_limits == ("R_rocker [-0.1, 0.1]",)
    assert min(abs(joint(mech, sol.q, "R_rocker") - a) for a in rocker_angles(0.4)) < 1e-9


# --------------------------------------------------------------------------- forward kinematics


def delta_platform_positions(motors: list[float]) -> list[np.ndarray]:
    """Platform centres of the delta of tests/data (R = 0.2, arm 0.2, rods 0.45, r = 0.05) with a level platform.

    Arm k turns about its tangent t_k by m_k: elbow E_k = R e_k + arm (cos m_k e_k - sin m_k z) (t_k x e_k
    = -z). With the platform level each parallelogram's mid-line joins E_k to P + r e_k and is a rod long:
    P lies on the three spheres |P - (E_k - r e_k)| = rod. Subtracting the first sphere from the others
    gives two planes; their line meets the sphere in the two solutions.
    """
    centres = []
    for k, m in enumerate(motors):
        th = 2 * np.pi * k / 3
        e = np.array([np.cos(th), np.sin(th), 0.0])
        centres.append(0.2 * e + 0.2 * (np.cos(m) * e - np.sin(m) * np.array([0, 0, 1.0])) - 0.05 * e)
    c = np.array(centres)
    a = 2 * (c[1:] - c[0])
    b = (c[1:] ** 2).sum(axis=1) - (c[0] ** 2).sum()
    p0 = np.linalg.lstsq(a, b, rcond=None)[0]
    n = np.cross(a[0], a[1])
    n /= np.linalg.norm(n)
    w = p0 - c[0]
    disc = (n @ w) ** 2 - (w @ w - 0.45**2)
    return [p0 + s * n for s in (-(n @ w) + np.sqrt(disc), -(n @ w) - np.sqrt(disc))]


def test_delta_forward_kinematics_from_random_seeds():
    """Delta with motors (0.2, 0.1, -0.1) rad from the neutral and 11 random seeds (all joints in +-pi).

    At least 10 of the 12 must converge (before: 2), each with the motors exactly at their values, and each
    solution with a level platform must put it at one of the two sphere intersections of
    :func:`delta_platform_positions` (other seeds may end in modes with twisted parallelograms).
    """
    mech = load(DATA / "delta.toml")
    motors = [0.2, 0.1, -0.1]
    values = dict(zip(mech.actuated, motors))
    expected = delta_platform_positions(motors)
    rng = np.random.default_rng(0)
    seeds = [mech.neutral()] + [random_configuration(mech, rng) for _ in range(11)]
    level = 0
    solved = 0
    for s in seeds:
        try:
            sol = solve_actuated(mech, values, s)
        except ClosureError:
            continue
        solved += 1
        assert sol.residual < 1e-12
        assert [joint(mech, sol.q, n) for n in mech.actuated] == motors
        pose = platform_pose(mech, sol.q)
        if np.linalg.norm(pin.log3(pose.rotation)) < 1e-6:
            level += 1
            assert min(np.linalg.norm(pose.translation - p) for p in expected) < 1e-9
    assert solved >= 10 and level >= 1


def test_failure_carries_closure_residuals_and_actuator_misses():
    """Four-bar (6d closure B) with crank 0 and rocker 1.5 rad held: the loop cannot close.

    By hand: the coupler end moves on the circle of radius |AB| = |(.3, .1)| about A = (0, 0.1); the rocker
    end is at O4 + R(1.5) (0, 0.2). The closest the solver can bring them is the gap between that point
    and the circle, with the orientations matched by the coupler-rocker hinge. The error must carry the
    closure residual (gap, 0) and each held joint's miss (0: they are held exactly). (The rotation part,
    1e-13 of the cost at that minimum, is left at ~1e-7 rad when the cost stops improving.)
    """
    mech = load(DATA / "fourbar.toml")
    with pytest.raises(ClosureError) as err:
        solve_actuated(mech, {"crank": 0.0, "rocker": 1.5})
    res = err.value.residuals
    end = np.array([0.3 - 0.2 * np.sin(1.5), 0.2 * np.cos(1.5)])
    gap = abs(np.linalg.norm(end - np.array([0.0, 0.1])) - np.hypot(0.3, 0.1))
    assert_allclose(res["B"], (gap, 0.0), atol=1e-6)
    assert res["joint crank"] == (0.0, 0.0) and res["joint rocker"] == (0.0, 0.0)
    assert "B:" in str(err.value)


@pytest.mark.parametrize("bad", [np.nan, np.inf])
def test_non_finite_pose_and_values_are_rejected_up_front(bad):
    """A NaN or infinite platform pose or actuator value is bad input (ConfigurationError), not a closure failure."""
    mech = pinmob.load("3-PUU")
    pose = pin.SE3(np.eye(3), np.array([0.0, bad, 0.2]))
    with pytest.raises(ConfigurationError, match="finite"):
        pinmob.assemble_pose(mech, pose)
    with pytest.raises(ConfigurationError, match="finite"):
        solve_actuated(mech, {"A_slider": bad})
    fourbar = load(DATA / "fourbar.toml")
    with pytest.raises(ConfigurationError, match="no platform"):
        pinmob.assemble_pose(fourbar, pin.SE3.Identity())


def test_one_residual_measure():
    """worst_residual divides lengths by L: 0.1 m at L = 1000 m (1e-4) is smaller than 1e-3 rad."""
    assert worst_residual({"a": (0.1, 0.0)}, 1000.0) == pytest.approx(1e-4)
    assert worst_residual({"a": (0.1, 0.0)}, 1000.0) < worst_residual({"b": (0.0, 1e-3)}, 1000.0)
    assert worst_residual({}, 1.0) == 0.0


# --------------------------------------------------------------------------- assembly modes


def spin_rod(mech: pinmob.Mechanism, q: np.ndarray, rod: str, angle: float) -> np.ndarray:
    """q with rod ``rod`` (three revolutes x, y, z at its top ball) turned by ``angle`` about its own axis.

    The rod's axis runs from its top ball centre to the end frame ``<rod>_end``. Its orientation relative
    to its parent, R_rel = Rx(a) Ry(b) Rz(c), becomes Rot(axis in the parent, angle) R_rel; since
    R_rel^T = Rz(-c) Ry(-b) Rx(-a), matrixToRpy(R_rel^T) returns (-a, -b, -c).
    """
    model = mech.model
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    jx = model.getJointId(f"{rod}_top_x")
    top, bottom = data.oMi[jx].translation, data.oMf[model.getFrameId(f"{rod}_end")].translation
    parent = data.oMi[int(model.parents[jx])].rotation
    axis = parent.T @ (bottom - top) / np.linalg.norm(bottom - top)
    rel = parent.T @ data.oMi[model.getJointId(f"{rod}_top_z")].rotation
    new = pin.AngleAxis(angle, axis).matrix() @ rel
    out = q.copy()
    for name, value in zip(("x", "y", "z"), -pin.rpy.matrixToRpy(new.T)):
        out[model.joints[model.getJointId(f"{rod}_top_{name}")].idx_q] = value
    return out


def test_idle_copies_are_one_mode():
    """Delta: a rod spun by 0.8 rad about its own axis (an idle motion, built by hand) is the same mode.

    The copy still closes (the rod's ends stay on its axis), is 0.8 rad away in joint space, and has the
    same joint centres, closure points and platform pose: mode distance ~0.
    """
    mech = load(DATA / "delta.toml")
    q0 = solve_actuated(mech, dict(zip(mech.actuated, [0.2, 0.1, -0.1]))).q
    q1 = spin_rod(mech, q0, "B_a", 0.8)
    pinmob.check_closed(mech, q1, tol=1e-12)
    assert configuration_distance(mech, q0, q1) > 0.5
    frames = default_end_frames(mech)
    held = list(mech.actuated)
    gap = mode_distance(mech, mode_signature(mech, q0, frames, held), mode_signature(mech, q1, frames, held), held)
    assert gap < 1e-9


def test_talos_leg_modes_modulo_idle_motions():
    """talos_like leg at the actuator values of a closed configuration: 2 modes (11 counted before).

    Two checks independent of the count: the modes' foot poses differ pairwise, and every solution from
    10 other seeds has the foot pose of one of the modes (none is missed, none counted twice); at least
    two of those solutions differ in joint space while sharing a mode (the idle copies that were counted).
    """
    mech = load(DATA / "example-parallel-robots" / "talos_like" / "robot.yaml")
    model = mech.model
    q0 = pinmob.find_closed(mech).q
    values = {a: joint(mech, q0, a) for a in mech.actuated}
    modes = assembly_modes(mech, values, seeds=10)
    foot = model.getFrameId("foot_part")
    data = model.createData()

    def foot_pose(q: np.ndarray) -> pin.SE3:
        pin.framesForwardKinematics(model, data, q)
        return data.oMf[foot].copy()

    def apart(a: pin.SE3, b: pin.SE3) -> float:
        return float(np.max(np.abs(pin.log6(a.actInv(b)).vector)))

    poses = [foot_pose(m.q) for m in modes]
    assert len(modes) == 2
    assert apart(poses[0], poses[1]) > 1e-3
    rng = np.random.default_rng(1)
    sols = []
    for _ in range(10):
        try:
            sols.append(solve_actuated(mech, values, random_configuration(mech, rng)).q)
        except ClosureError:
            continue
    assert len(sols) >= 8
    for q in sols:
        assert min(apart(foot_pose(q), p) for p in poses) < 1e-6
    same_foot = [
        (a, b)
        for a in sols
        for b in sols
        if apart(foot_pose(a), foot_pose(b)) < 1e-6 and configuration_distance(mech, a, b) > 1e-3
    ]
    assert same_foot


def test_fourbar_modes_and_continuum():
    """Four-bar (formats/fourbar): with the crank at 0.4 rad, the two circle intersections of
    :func:`rocker_angles`; with nothing held, its closed configurations form a continuum: refused."""
    mech = load(DATA / "formats" / "fourbar" / "fourbar.toml")
    modes = assembly_modes(mech, {"L_crank": 0.4}, seeds=8)
    found = sorted(joint(mech, m.q, "R_rocker") for m in modes)
    assert_allclose(found, sorted(rocker_angles(0.4)), atol=1e-9)
    with pytest.raises(ConfigurationError, match="continuum"):
        assembly_modes(mech, None, seeds=8)


def _out_of_reach(message: str) -> dict[str, tuple[float, float]]:
    """``{coordinate: (residual, nearest value reached)}`` of the sentence "out of reach along ..." of an error."""
    match = re.search(r"out of reach along (.*): the nearest closed configuration found has (.*)\.$", message)
    assert match, message
    residuals = dict(re.findall(r"(\w+) \(residual (\S+) (?:m|rad)\)", match.group(1)))
    reached = dict(re.findall(r"(\w+) = (\S+) (?:m|rad)", match.group(2)))
    assert residuals.keys() == reached.keys()
    return {k: (float(residuals[k]), float(reached[k])) for k in residuals}


@pytest.mark.parametrize(
    ("xyz", "rpy", "coordinate"),
    [([0.0, 0.0, -3.0], [0.0, 0.0, 0.0], "z"), ([0.04, -0.03, -0.47], [0.3, 0.0, 0.0], "roll")],
)
def test_an_unreachable_pose_names_the_coordinates_out_of_reach(xyz, rpy, coordinate):
    """The Delta (motors on R = 0.2 m, arms 0.3 m, rods 0.4 m, platform r = 0.05 m; by hand): its platform
    hangs at most arm + rod = 0.7 m below the motors, so z = -3 m is out of reach along z alone, by more than
    2.3 m; it only translates (3T), so a roll of 0.3 rad at a reachable position is out of reach along roll
    alone, by 0.3 rad. The error used to say "try another seed", which cannot help."""
    mech = pinmob.load("Delta")
    with pytest.raises(ClosureError) as err:
        pinmob.assemble_pose(mech, pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz)))
    (named,) = _out_of_reach(str(err.value)).items()
    residual, reached = named[1]
    assert named[0] == coordinate and "another seed" not in str(err.value)
    if coordinate == "z":
        assert residual > 2.3 and -0.7 < reached < 0
    else:
        assert residual == pytest.approx(0.3, abs=1e-3) and abs(reached) < 1e-6


def test_an_unreachable_named_pose_says_so_on_the_command_line(tmp_path, capsys):
    """A 3-PUU file (guides on R = 0.3 m, links 0.25 m, platform r = 0.15 m) whose configuration asks the
    platform at x = 0.9 m: a platform joint is at most 0.25 m from its guide, so the centre reaches at most
    x = 0.3 + 0.25 - 0.15 = 0.4 m (by hand): out of reach along x by at least 0.5 m, one error line."""
    from pinmob.cli import main
    from pinmob.io.builtin import builtin_models

    source = builtin_models()["3-PUU"]
    text = source.read_text()
    (tmp_path / "3puu.urdf").write_text(source.with_suffix(".urdf").read_text())
    path = tmp_path / "far.toml"
    path.write_text(
        text[: text.index("[configurations.")] + "[configurations.far]\npose = { xyz = [0.9, 0.0, -0.17] }\n"
    )
    assert main(["analyze", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    ((coordinate, (residual, reached)),) = _out_of_reach(err.strip()).items()
    assert coordinate == "x" and residual >= 0.5 and reached <= 0.4


def test_a_couplings_polynomial_and_its_slope_equal_numpys() -> None:
    """The coupling residual's ``P(x)`` and ``P'(x)`` (Horner's rule) against ``np.polynomial.Polynomial`` and its
    ``deriv()``, for MuJoCo's five coefficients and fewer, at points on both sides of the reference."""
    rng = np.random.default_rng(7)
    for n in range(1, 6):
        coefficients = tuple(float(c) for c in rng.normal(size=n))
        poly = np.polynomial.Polynomial(coefficients)
        for x in (-1.3, -0.2, 0.0, 0.4, 2.1):
            value, slope = polynomial_and_slope(coefficients, x)
            assert value == pytest.approx(float(poly(x)), rel=1e-14, abs=1e-15)
            assert slope == pytest.approx(float(poly.deriv()(x)), rel=1e-14, abs=1e-15)
