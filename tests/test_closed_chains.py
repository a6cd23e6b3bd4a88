"""Closed chains described by closures: loaders, assembly, whole-mechanism mobility, actuation.

Expected numbers are derived by hand in each test's docstring (Grubler-Kutzbach
``nv - rows``, the planar-loop rank 3 of a spatial closure, the idle spin of
each rod between two ball joints, the Bennett closure relation, the four-bar's
circle intersection), never copied from pinmob's output.
"""

from __future__ import annotations

import dataclasses
import json
import sys
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob import actuator_sets, analyze_mechanism, frame_mobility
from pinmob.analysis.generic import generic_twist_ranks
from pinmob.analysis.modes import assembly_modes
from pinmob.analysis.motion import Method
from pinmob.assembly.assemble import project, solve_actuated
from pinmob.assembly.seeds import find_closed
from pinmob.cli import main
from pinmob.exceptions import ClosureError
from pinmob.model.closure import make_closure
from pinmob.model.mechanism import Mechanism
from pinmob.screw.bases import subspace_gap

sys.path.insert(0, str(Path(__file__).resolve().parent))
from millimetres import in_millimetres, q_in_millimetres  # noqa: E402

DATA = Path(__file__).resolve().parent / "data"


def load(name: str) -> pinmob.Mechanism:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the test models have no meshes
        return pinmob.load(DATA / name)


def closed(mech: pinmob.Mechanism) -> np.ndarray:
    return find_closed(mech).q


# --------------------------------------------------------------------------- four-bar


def rocker_angles(crank: float) -> list[float]:
    """Rocker rotations closing the four-bar of tests/data (O1 = 0, A = (0, .1), B = (.3, .2), O4 = (.3, 0)).

    Crank end A(t) = R(t) (0, 0.1); B lies on the circles |B - A| = |(.3, .1)| and
    |B - O4| = 0.2; the rocker angle is the rotation of (0, 0.2) onto B - O4.
    """
    a = np.array([-0.1 * np.sin(crank), 0.1 * np.cos(crank)])
    o4, r1, r2 = np.array([0.3, 0.0]), np.hypot(0.3, 0.1), 0.2
    d = np.linalg.norm(o4 - a)
    x = (d**2 + r1**2 - r2**2) / (2 * d)
    h = np.sqrt(r1**2 - x**2)
    u = (o4 - a) / d
    out = []
    for s in (1, -1):
        b = a + x * u + s * h * np.array([-u[1], u[0]])
        v = b - o4
        out.append(float(np.arctan2(v[1], v[0]) - np.pi / 2))
    return out


def test_fourbar_6d_closure_counts():
    """4 revolutes, one 6d weld: Grubler 4 - 6 = -2; a planar loop has rank 3, so DoF 1 and 3 redundant rows."""
    mech = load("fourbar.toml")
    mm = analyze_mechanism(mech, "home")
    assert (mm.nv, mm.rows, mm.rank) == (4, 6, 3)
    assert mm.mechanism_dof == 1 and mm.grubler == -2 and mm.redundant_constraints == 3
    assert mm.redundant_by_closure == {"B": 3}
    assert mm.idle_dof == 0 and mm.actuation.valid and mm.actuation.locked_dof == 0


def test_fourbar_lower_closures_and_mjcf():
    """Revolute closure (5 rows, 3 joints): Grubler -2, DoF 1. MJCF connect (3 rows): Grubler 0, 1 redundant; weld: as the 6d one."""
    for name, grubler, redundant in (
        ("fourbar_revolute.toml", -2, 3),
        ("fourbar_connect.xml", 0, 1),
        ("fourbar_weld.xml", -2, 3),
    ):
        mech = load(name)
        mm = analyze_mechanism(mech, closed(mech))
        assert (mm.mechanism_dof, mm.grubler, mm.redundant_constraints) == (1, grubler, redundant), name
        assert mech.actuated == ("crank",) and mm.actuation.valid


def test_fourbar_forward_kinematics_and_assembly_modes():
    """Crank at 0.4 rad: the rocker angle from the circle intersection, and both assembly modes are found as distinct."""
    mech = load("fourbar.toml")
    sol = solve_actuated(mech, {"crank": 0.4}, mech.neutral())
    rocker = sol.q[mech.model.joints[mech.model.getJointId("rocker")].idx_q]
    assert_allclose(rocker, rocker_angles(0.4)[0], atol=1e-9)
    modes = assembly_modes(mech, {"crank": 0.4}, seeds=12)
    found = sorted(
        float(np.angle(np.exp(1j * m.q[mech.model.joints[mech.model.getJointId("rocker")].idx_q]))) for m in modes
    )
    assert len(found) == 2
    assert_allclose(found, sorted(np.angle(np.exp(1j * np.array(rocker_angles(0.4))))), atol=1e-8)
    for m in modes:
        assert m.residual < 1e-9


def test_projection_and_failure_report_residuals():
    """Projection from a perturbed configuration closes; an unreachable crank-rocker pair is a ClosureError with residuals."""
    mech = load("fourbar.toml")
    q0 = pin.integrate(mech.model, mech.neutral(), np.array([0.05, -0.02, 0.03, 0.01]))
    sol = project(mech, q0)
    assert sol.residual < 1e-9 and "B" in sol.residuals
    with pytest.raises(ClosureError) as err:
        solve_actuated(mech, {"crank": 0.0, "rocker": 1.5})
    res = err.value.residuals  # the gap itself is checked against the circles in test_assembly.py
    assert set(res) == {"B", "joint crank", "joint rocker"} and res["B"][0] > 0.1


def test_fourbar_actuation_variants():
    """No actuator: the one motion remains (not idle). Crank and rocker: one of them is implied by the other."""
    mech = load("fourbar.toml")
    q = pinmob.closed_configuration(mech, "home")
    none = analyze_mechanism(mech, q, actuated=[]).actuation
    assert not none.valid and none.locked_dof == 1 and len(none.remaining) == 1
    two = analyze_mechanism(mech, q, actuated=["crank", "rocker"]).actuation
    assert not two.valid and two.redundant_actuators == 1 and two.locked_dof == 0
    # every joint of a non-singular four-bar moves in its one motion: each alone is a valid actuator
    assert sorted(x[0] for x in actuator_sets(mech, q, 1)) == ["coupler", "coupler_rocker", "crank", "rocker"]


# --------------------------------------------------------------------------- five-bar, Bennett


@pytest.mark.parametrize(("folder", "nv", "rows", "redundant"), [("fivebar", 4, 3, 1), ("fivebar6d", 5, 6, 3)])
def test_fivebar(folder, nv, rows, redundant):
    """Planar five-bar: 2 DoF; a planar loop ranks 2 of a point closure and 3 of a weld."""
    mech = load(f"{folder}/robot.yaml")
    mm = analyze_mechanism(mech, closed(mech))
    assert (mm.nv, mm.rows, mm.mechanism_dof, mm.grubler, mm.redundant_constraints) == (
        nv,
        rows,
        2,
        nv - rows,
        redundant,
    )
    assert mm.actuation.valid and set(mech.actuated) == {"mot1", "mot2"}


def test_bennett_linkage():
    """Bennett: theta3 = -theta1, theta4 = -theta2, tan(t1/2) tan(t2/2) = sin((b+a)/2) / sin((b-a)/2); 1 DoF, Grubler -2."""
    mech = load("bennett.toml")
    alpha, beta, t1 = np.pi / 6, np.pi / 3, 0.7
    t2 = 2 * np.arctan(np.sin((beta + alpha) / 2) / np.sin((beta - alpha) / 2) / np.tan(t1 / 2))
    q = mech.q_from_joints({"J1": t1, "J2": t2, "J3": -t1, "J4": -t2})
    pinmob.check_closed(mech, q, tol=1e-9)
    mm = analyze_mechanism(mech, q)
    assert (mm.mechanism_dof, mm.grubler, mm.redundant_constraints) == (1, -2, 3)
    assert mm.actuation.valid


# --------------------------------------------------------------------------- delta, Gough-Stewart, 3-PUU


def test_delta_parallelograms():
    """Delta: 24 joint freedoms, five ball closures (15 rows) -> 9 = 3 platform translations + 6 rod spins (idle)."""
    mech = load("delta.toml")
    mm = analyze_mechanism(mech, "home")
    assert (mm.mechanism_dof, mm.grubler, mm.redundant_constraints, mm.idle_dof) == (9, 9, 0, 6)
    platform = mm.frames[0]
    assert (platform.frame, platform.dof, platform.motion_type) == ("platform", 3, "3T")
    assert mm.actuation.valid and mm.actuation.locked_dof == 6 and mm.actuation.frame_dof == {"platform": 0}
    assert ("A_motor", "B_motor", "C_motor") in actuator_sets(
        mech,
        pinmob.closed_configuration(mech, "home"),
        3,
        candidates=["A_motor", "B_motor", "C_motor", "A_a_top_x", "B_a_top_x"],
    )


@pytest.mark.parametrize(("stem", "dof", "idle"), [("gough_stewart_ups", 6, 0), ("gough_stewart_sps", 12, 6)])
def test_gough_stewart(stem, dof, idle):
    """6-UPS: 6 x 6 joints - 5 x 6 rows = 6. 6-SPS: 42 - 30 = 12 = 6 platform DoF + one spin per leg (idle).

    The platform's free motion equals the limb-wise wrench result (6 DoF, 3T3R).
    """
    mech = load(f"{stem}.toml")
    q = pinmob.closed_configuration(mech, "home")
    mm = analyze_mechanism(mech, q)
    assert (mm.mechanism_dof, mm.grubler, mm.idle_dof) == (dof, dof, idle)
    limbwise = pinmob.analyze(mech, q)
    assert (mm.frames[0].dof, mm.frames[0].motion_type) == (limbwise.dof, limbwise.motion_type) == (6, "3T3R")
    assert mm.actuation.valid and mm.actuation.frame_dof == {"platform": 0}


@pytest.mark.parametrize(
    ("name", "config"),
    [
        ("3-PUU", "generic"),
        ("3-PUU", "offset"),
        ("3-PUU-flat", "flat"),
        ("3-PUU-vertical", "vertical"),
        ("3-PUU-vertical", "generic"),
    ],
)
def test_limbs_meeting_at_platform_match_limbwise_wrenches(name, config):
    """Limb tips welded to the platform are 6d closures: the platform motion of the closure Jacobian equals the wrench result."""
    mech = pinmob.load(name)
    q = pinmob.closed_configuration(mech, config)
    limbwise = pinmob.analyze(mech, q)
    mm = analyze_mechanism(mech, q)
    plat = mm.frames[0]
    assert (plat.dof, plat.motion_type) == (limbwise.dof, limbwise.motion_type)
    assert (
        subspace_gap(
            plat.free_twists / np.r_[np.full(3, mech.length_scale), np.ones(3)][:, None],
            limbwise.free_twists / np.r_[np.full(3, mech.length_scale), np.ones(3)][:, None],
        )
        < 1e-8
    )
    # 15 joints, limb B and C tips welded to the platform on limb A: 12 rows -> Grubler 3
    assert mm.grubler == 3


# --------------------------------------------------------------------------- loops inside limbs

#: delta geometry of tests/data/make_models.py: base radius, arm, rod, platform radius
DELTA_R, DELTA_ARM, DELTA_ROD, DELTA_SMALL_R = 0.2, 0.2, 0.45, 0.05
DELTA_H = float(np.sqrt(DELTA_ROD**2 - (DELTA_R + DELTA_ARM - DELTA_SMALL_R) ** 2))


def scaled(twists: np.ndarray, length: float) -> np.ndarray:
    return twists / np.r_[np.full(3, length), np.ones(3)][:, None]


def test_delta_written_as_limbs_is_3t():
    """The delta as three limbs, each parallelogram closed inside its limb by a 3d closure, is 3T.

    Limb k: motor about t_k (tangent), rod a (two spheres) to the platform piece, and
    rod b (in no limb) closed onto the piece. With the loop closed, the piece moves
    relative to the arm with the 4 freedoms two parallel S-S rods of direction rho
    leave (translations normal to rho, rotations about t_k and rho); the motor adds a
    fifth, so the limb's twist rank is 5 and its one wrench is reciprocal to all of them:
    the couple along t_k x rho (normal to the parallelogram's plane). Limb A (t = y,
    rho = (-0.35, 0, -h)): couple along (-h, 0, 0.35). Three such couples span every
    rotation: 3T. The same answer as the whole-mechanism closure Jacobian, and as the
    same delta written with closures only (tests/data/delta.toml).
    """
    mech = load("delta_limbs.toml")
    q = pinmob.closed_configuration(mech, "home")
    mob = pinmob.analyze(mech, q)
    assert (mob.dof, mob.motion_type, mob.method) == (3, "3T", Method.LIMB_WISE)
    for limb in mob.limbs:
        assert (limb.twist_rank, limb.generic_twist_rank, limb.wrench_count) == (5, 5, 1)
        assert limb.closures == (f"pi_{limb.name}",)
        assert limb.loop_joints == tuple(f"{limb.name}_b_top_{a}" for a in "xyz")
    w = mob.limbs[0].wrenches[:, 0]
    couple = np.array([-DELTA_H, 0.0, 0.35]) / DELTA_ROD
    assert_allclose(w[:3], 0.0, atol=1e-9)
    assert_allclose(w[3:] / np.linalg.norm(w[3:]) * np.sign(w[5]), couple, atol=1e-9)
    platform = analyze_mechanism(mech, q).frames[0]
    assert (platform.frame, platform.dof, platform.motion_type) == ("A_tip", 3, "3T")
    length = mech.length_scale
    assert subspace_gap(scaled(platform.free_twists, length), scaled(mob.free_twists, length)) < 1e-8
    same = pinmob.analyze(load("delta.toml"), "home")
    assert (same.dof, same.motion_type, same.method) == (3, "3T", Method.CLOSURE_JACOBIAN)
    assert subspace_gap(scaled(same.free_twists, length), scaled(mob.free_twists, length)) < 1e-8


def one_delta_limb() -> tuple[Mechanism, np.ndarray]:
    """Limb A of the delta alone (tip = platform), with every closure of the file, and its folded configuration.

    Folded: both rods turned about y by beta = atan2(h, 0.35) at their top spheres (and
    the piece turned back at rod a's bottom sphere), so that they point along -x,
    collinear with the arm; the piece translates, the parallelogram stays closed.
    """
    full = load("delta_limbs.toml")
    mech = Mechanism.from_model(
        full.model, {"A": "A_tip"}, name="delta limb A", closures=full.closures, actuated={"A": ["A_motor"]}
    )
    beta = float(np.arctan2(DELTA_H, 0.35))
    return mech, mech.q_from_joints({"A_a_top_y": beta, "A_b_top_y": beta, "A_a_bottom_y": -beta})


def test_delta_limb_at_its_serial_singularity():
    """A parallelogram limb is serially singular when its rods are collinear with the arm.

    Relative to the arm the piece keeps {v normal to rho (at the rods' mid-bottom B),
    w in span(y, rho)}; the motor twist there is w = y, v_B = y x (B - M). With the rods
    along -x: B = (-0.05, 0, 0), M = (0.2, 0, 0), v_B = 0.25 z, normal to rho: the motor
    adds nothing, rank 4 < 5 (generic, at home v_B . rho != 0). The wrenches reciprocal to
    the 4 twists: the force along rho = x through B, and the couple t x rho = -z. The tip
    is then at (-0.1, 0, 0), on the force's line: at the tip origin the force has no
    moment. Free: translations y, z and rotations about x and y: 2T2R. Closures pi_B and
    pi_C involve no joint of limb A: detached, they change nothing.
    """
    mech, folded = one_delta_limb()
    assert mech.coupling_closures == {} and mech.limbs[0].closures == ("pi_A",)
    assert generic_twist_ranks(mech)[0] == 5  # the limb's generic rank, estimated by the analysis
    home = pinmob.analyze(mech, mech.neutral())
    assert (home.dof, home.limbs[0].twist_rank, home.serially_singular_limbs) == (5, 5, ())
    mob = pinmob.analyze(mech, folded)
    assert mob.serially_singular_limbs == ("A",) and mob.limbs[0].twist_rank == 4
    assert (mob.dof, mob.motion_type) == (4, "2T2R")
    expected = np.zeros((6, 2))
    expected[0, 0] = expected[5, 1] = 1.0
    w = mob.constraint_wrenches * np.r_[np.full(3, mech.length_scale), np.ones(3)][:, None]
    assert subspace_gap(w, expected) < 1e-8
    whole = frame_mobility(mech, folded, "A_tip")
    assert (whole.dof, whole.motion_type) == (4, "2T2R")


def test_closure_coupling_two_limbs_uses_the_whole_mechanism():
    """Rod b of limb C closed onto limb A's platform piece (a frame added where C_pf is): the same delta.

    The pieces are welded by the limb tips, so the mechanism is unchanged (3T), but the
    closure now involves limb A's joints and limb C's motor: no limb has the loop to
    itself. analyze says so and uses the closure Jacobian; the limbs are not reported.
    """
    full = load("delta_limbs.toml")
    model = pin.Model(full.model)
    pf = model.getFrameId("A_pf")
    piece = model.frames[pf].parentJoint
    data = model.createData()
    pin.framesForwardKinematics(model, data, pin.neutral(model))
    where = data.oMi[piece].actInv(data.oMf[model.getFrameId("C_pf")])
    model.addFrame(pin.Frame("A_holds_C_b", piece, pf, where, pin.FrameType.OP_FRAME))
    closures = [c for c in full.closures if c.name != "pi_C"]
    closures.append(make_closure(model, "pi_C_on_A", "A_holds_C_b", "C_b_end", "3d"))
    mech = Mechanism.from_model(model, {b.name: b.tip for b in full.limbs}, name="coupled", closures=closures)
    assert mech.coupling_closures == {"pi_C_on_A": ("A", "C")}
    mob = pinmob.analyze(mech, mech.neutral())
    assert (mob.dof, mob.motion_type, mob.method, mob.limbs) == (3, "3T", Method.CLOSURE_JACOBIAN, ())
    assert "pi_C_on_A" in mob.method_note and "A, C" in mob.method_note
    doc = mob.to_dict()
    assert doc["method"] == "closure Jacobian" and "pi_C_on_A" in doc["method_note"]
    assert "method: closure Jacobian" in str(mob)


def test_analyze_needs_a_platform():
    """The report of a mechanism without a platform has no platform mobility: asking for it says why."""
    with pytest.raises(pinmob.ConfigurationError, match="no platform"):
        _ = pinmob.analyze(load("fourbar.toml"), "home").dof


def test_puu_limbs_are_unchanged_by_the_loop_handling():
    """The 3-PUU limbs have no closure: screws are the tip Jacobian columns, generic twist rank 5, 3T at 'generic'."""
    mech = pinmob.load("3-PUU")
    assert all(limb.closures == () and limb.loop_joints == () for limb in mech.limbs)
    mob = pinmob.analyze(mech, "generic")
    assert (mob.dof, mob.motion_type, mob.method) == (3, "3T", Method.LIMB_WISE)
    assert [(b.twist_rank, b.generic_twist_rank, b.wrench_count) for b in mob.limbs] == [(5, 5, 1)] * 3


# --------------------------------------------------------------------------- outputs, redundancy, units


def test_reported_frames_do_not_change_the_actuation_verdict(capsys):
    """Reporting rod A_a's frame keeps the platform as the output: 6 idle rod spins, valid.

    Were the rod an output, its spin (which moves it) would not be idle: 5 idle, one
    non-idle motion left with the motors locked, not valid. That is what ``outputs`` asks.
    """
    mech = load("delta.toml")
    plain = analyze_mechanism(mech, "home")
    named = analyze_mechanism(mech, "home", frames=["A_a_rod"])
    assert (named.idle_dof, named.actuation.valid, named.end_frames) == (6, True, ("platform",))
    assert named.actuation.to_dict() | {"frame_dof_locked": {}} == plain.actuation.to_dict() | {"frame_dof_locked": {}}
    assert [f.frame for f in named.frames] == ["platform", "A_a_rod"]
    rod_out = analyze_mechanism(mech, "home", outputs=["platform", "A_a_rod"])
    assert (rod_out.idle_dof, rod_out.actuation.locked_dof, rod_out.actuation.valid) == (5, 6, False)
    docs = []
    for extra in ([], ["--frame", "A_a_rod"]):
        assert main(["analyze", str(DATA / "delta.toml"), "--json", "--search-actuators", "3", *extra]) == 0
        docs.append(json.loads(capsys.readouterr().out))
    for key in ("idle_dof", "actuation", "valid_actuator_sets", "end_frames"):
        left, right = docs[0][key], docs[1][key]
        if key == "actuation":
            left, right = left | {"frame_dof_locked": {}}, right | {"frame_dof_locked": {}}
        assert left == right, key
    assert docs[1]["platform"]["frame"] == "platform" and docs[1]["actuation"]["valid"]


def test_named_configuration_prints_its_real_residual(tmp_path, capsys):
    """A four-bar configuration closed by the solver, then the coupler nudged by 1e-7 rad.

    The weld's residual is log6 of the rocker end in the coupler end; the largest
    dimensionless residual is max(|position| / L, |rotation|), computed here with
    Pinocchio directly; the CLI must print it, not 0.
    """
    mech = load("fourbar.toml")
    q = solve_actuated(mech, {"crank": 0.4}, mech.neutral()).q.copy()
    q[mech.model.joints[mech.model.getJointId("coupler")].idx_q] += 1e-7
    model, data = mech.model, mech.model.createData()
    pin.framesForwardKinematics(model, data, q)
    e = pin.log6(data.oMf[model.getFrameId("coupler_end")].actInv(data.oMf[model.getFrameId("rocker_end")])).vector
    expected = max(np.linalg.norm(e[:3]) / mech.length_scale, np.linalg.norm(e[3:]))
    assert 1e-8 < expected < 1e-6
    values = ", ".join(f"{model.names[j]} = {float(q[model.joints[j].idx_q])!r}" for j in range(1, model.njoints))
    toml = (DATA / "fourbar.toml").read_text().replace('urdf = "fourbar.urdf"', f'urdf = "{DATA / "fourbar.urdf"}"')
    path = tmp_path / "nudged.toml"
    path.write_text(toml.replace("joints = {}", f"joints = {{ {values} }}"))
    assert main(["analyze", str(path)]) == 0
    assert f"(largest residual {expected:.1e})" in capsys.readouterr().out
    assert main(["analyze", str(path), "--json"]) == 0
    assert_allclose(json.loads(capsys.readouterr().out)["closed_configuration"]["residual"], expected, rtol=1e-6)


def test_overdetermined_actuation_is_reported(tmp_path, capsys):
    """Four-bar with crank and rocker actuated: its one motion moves both, so one rate is implied by the other.

    Locked, nothing is left (0 motions) but the actuators over-determine it: 1 redundant
    actuator, not valid; the text report and the JSON say so.
    """
    toml = (DATA / "fourbar.toml").read_text().replace('urdf = "fourbar.urdf"', f'urdf = "{DATA / "fourbar.urdf"}"')
    path = tmp_path / "two_motors.toml"
    path.write_text(toml.replace('actuated = ["crank"]', 'actuated = ["crank", "rocker"]'))
    assert main(["analyze", str(path)]) == 0
    text = capsys.readouterr().out
    assert "actuation NOT valid" in text and "1 actuator(s) over-determine the chain" in text
    assert main(["analyze", str(path), "--json"]) == 0
    act = json.loads(capsys.readouterr().out)["actuation"]
    assert (act["valid"], act["locked_dof"], act["redundant_actuators"], act["overdetermined"]) == (False, 0, 1, True)


def fourbar_two_closures(order: tuple[str, str]) -> Mechanism:
    full = load("fourbar.toml")
    made = {
        "B": make_closure(full.model, "B", "coupler_end", "rocker_end", "6d"),
        "B2": make_closure(full.model, "B2", "coupler_end", "rocker_end", "3d"),
    }
    return Mechanism.from_model(
        full.model, {}, name="four-bar twice closed", closures=[made[n] for n in order], actuated={"": ["crank"]}
    )


@pytest.mark.parametrize("order", [("B", "B2"), ("B2", "B")])
def test_redundancy_per_closure_does_not_depend_on_the_order(order):
    """The four-bar closed twice at B: a 6d weld and a 3d ball on the same frames (9 rows).

    All four axes are parallel to z: the loop's closure Jacobian has rank 3 (x, y and
    rotation about z). The ball alone gives rank 2 (its z row is zero), the weld alone 3.
    So rank K = 3; without the weld 2: the weld is needed (essential 1, redundant 6 - 1 =
    5); without the ball 3: the ball adds nothing (essential 0, redundant 3, not needed).
    In either order of declaration.
    """
    mm = analyze_mechanism(fourbar_two_closures(order), np.zeros(4))
    assert (mm.rows, mm.rank, mm.redundant_constraints, mm.mechanism_dof) == (9, 3, 6, 1)
    assert mm.redundant_by_closure == {"B": 5, "B2": 3} and list(mm.redundant_by_closure) == list(order)
    ranks = {c.name: (c.rank, c.essential, c.needed) for c in mm.closures}
    assert ranks == {"B": (3, 1, True), "B2": (2, 0, False)}


@pytest.mark.parametrize(
    ("name", "frames"),
    [
        ("delta.toml", ["A_a_rod"]),
        ("fourbar.toml", ["coupler_end"]),
        ("delta_limbs.toml", []),
        ("gough_stewart_sps.toml", []),
    ],
)
def test_millimetres_give_the_same_answer(name, frames):
    """The same closed chain drawn in millimetres (lengths x 1000, prismatic values x 1000).

    Every count and verdict is the same; the dimensionless closure Jacobian (rows per L,
    prismatic rates times L) has the same singular values; axis points are 1000 times
    farther in millimetres; joint rates of the motions left unactuated are the same
    (revolute rates, and prismatic ones per L).
    """
    mech = load(name)
    q = pinmob.closed_configuration(mech, "home")
    milli = in_millimetres(mech)
    assert_allclose(milli.length_scale, 1000 * mech.length_scale, rtol=1e-12)
    results, numbers = [], []
    for m, qm in ((mech, q), (milli, q_in_millimetres(mech, q))):
        mm = analyze_mechanism(m, qm, frames=frames)
        free = analyze_mechanism(m, qm, actuated=[]).actuation
        results.append(
            (
                mm.mechanism_dof,
                mm.idle_dof,
                mm.idle_joints,
                mm.redundant_constraints,
                mm.redundant_by_closure,
                mm.actuation.valid,
                mm.actuation.locked_dof,
                mm.actuation.frame_dof,
                free.locked_dof,
                [(f.dof, f.motion_type, [mo.label for mo in f.motions]) for f in mm.frames],
                list(generic_twist_ranks(m)),
            )
        )
        points = [mo.point / m.length_scale for f in mm.frames for mo in f.motions if mo.point is not None]
        numbers.append((mm.singular_values / mm.singular_values[0], points))
        if m.has_platform:
            mob = pinmob.analyze(m, qm)
            results[-1] += (mob.dof, mob.motion_type, [b.twist_rank for b in mob.limbs])
            numbers[-1] += (mob.singular_values,)
    assert results[0] == results[1]
    for a, b in zip(numbers[0], numbers[1]):
        assert_allclose(np.asarray(a, float), np.asarray(b, float), atol=1e-9)


# --------------------------------------------------------------------------- command line


@pytest.mark.parametrize("name", ["fivebar/robot.yaml", "fourbar_connect.xml"])
def test_cli_json_without_configuration(name, capsys):
    assert main(["analyze", str(DATA / name), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("mechanism_dof", "idle_dof", "redundant_constraints", "redundant_by_closure", "grubler", "actuation"):
        assert key in out
    assert set(out["actuation"]) >= {"valid", "locked_dof", "remaining"}
    method = "named configuration 'reference'" if name.endswith(".xml") else "neutral"  # MJCF: MuJoCo's qpos0
    assert out["closed_configuration"]["method"] == method and "platform" not in out


def test_cli_limb_model_keeps_its_keys(capsys):
    assert main(["analyze", "3-PUU", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert (out["dof"], out["motion_type"], out["mechanism_dof"], out["grubler"], out["actuation"]["valid"]) == (
        3,
        "3T",
        3,
        3,
        True,
    )


def test_cli_error_is_one_line(capsys):
    assert main(["analyze", str(DATA / "fourbar.toml"), "--frame", "nowhere"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pinmob: error:") and err.count("\n") == 1 and "valid frames" in err


def test_negative_restarts_is_a_one_line_error(capsys):
    # it was an AssertionError traceback
    assert main(["analyze", str(DATA / "fivebar" / "robot.yaml"), "--restarts", "-3"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--restarts" in err and "-3" in err


def _remaining(mech: Mechanism, q: str | np.ndarray) -> list[dict[str, float]]:
    return [dict(m) for m in analyze_mechanism(mech, q).actuation.remaining]


def test_remaining_motions_do_not_depend_on_the_order_of_the_limbs_or_the_unit():
    """The motions left with the actuators locked are printed on one canonical basis of their space.

    Each is a closed-chain motion with the actuated joints still (checked on the closure residual's
    Jacobian by Pinocchio: K dq = 0 to first order), and the same joint rates with the limbs declared in
    the reverse order and in millimetres (revolute joints only here: a prismatic rate is printed in the
    file's unit). They once came out on whatever basis the SVD gave: A_u2a -1 or +1 at 3-PUU-flat's flat,
    a different mix at 3-PUU-vertical's vertical.
    """
    from pinmob.assembly.residual import stacked_error

    checked = 0
    for name, config in [("3-PUU-flat", "flat"), ("3-PUU-vertical", "vertical"), ("3-PUU-vertical", "generic"),
                         ("3-UPU", "constraint-singular"), ("4-RUU", "parallel-axes"), ("Delta", "rods-horizontal"),
                         ("Delta-3RUU", "constraint-singular")]:  # fmt: skip
        mech = pinmob.load(name)
        reference = _remaining(mech, config)
        assert reference, (name, config)
        reversed_limbs = dataclasses.replace(mech, limbs=tuple(reversed(mech.limbs)))
        q = pinmob.closed_configuration(mech, config)
        in_mm = _remaining(in_millimetres(mech), q_in_millimetres(mech, q))
        for other in (_remaining(reversed_limbs, config), in_mm):
            assert [sorted(m) for m in other] == [sorted(m) for m in reference], (name, config)
            for a, b in zip(other, reference):
                assert_allclose([a[k] for k in sorted(a)], [b[k] for k in sorted(a)], atol=2e-6)
        data = mech.model.createData()
        pin.computeJointJacobians(mech.model, data, q)
        pin.updateFramePlacements(mech.model, data)
        _, k = stacked_error(mech, mech.model, data, mech.all_closures)
        for motion in reference:
            dq = np.zeros(mech.model.nv)
            for joint, rate in motion.items():
                dq[mech.model.joints[mech.model.getJointId(joint)].idx_v] = rate
            assert not any(motion.get(a) for a in mech.actuated)
            assert np.abs(k @ dq).max() < 1e-4 * np.abs(k).max()  # rates printed to 6 decimals, small ones dropped
            checked += 1
    assert checked >= 7
