"""Closed chains described by closures: loaders, assembly, whole-mechanism mobility, actuation.

Expected numbers are derived by hand in each test's docstring (Grubler-Kutzbach
``nv - rows``, the planar-loop rank 3 of a spatial closure, the idle spin of
each rod between two ball joints, the Bennett closure relation, the four-bar's
circle intersection), never copied from pinmob's output.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.cli import main
from pinmob.closure import ClosureError, assembly_modes, find_closed, project, solve_actuated
from pinmob.constraints import actuator_sets, analyze_mechanism
from pinmob.screw import subspace_gap

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
    q = mech.configuration("home")
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
        mech, mech.configuration("home"), 3, candidates=["A_motor", "B_motor", "C_motor", "A_a_top_x", "B_a_top_x"]
    )


@pytest.mark.parametrize(("stem", "dof", "idle"), [("gough_stewart_ups", 6, 0), ("gough_stewart_sps", 12, 6)])
def test_gough_stewart(stem, dof, idle):
    """6-UPS: 6 x 6 joints - 5 x 6 rows = 6. 6-SPS: 42 - 30 = 12 = 6 platform DoF + one spin per leg (idle).

    The platform's free motion equals the limb-wise wrench result (6 DoF, 3T3R).
    """
    mech = load(f"{stem}.toml")
    q = mech.configuration("home")
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
    q = mech.configuration(config)
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


# --------------------------------------------------------------------------- command line


@pytest.mark.parametrize("name", ["fivebar/robot.yaml", "fourbar_connect.xml"])
def test_cli_json_without_configuration(name, capsys):
    assert main(["analyze", str(DATA / name), "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for key in ("mechanism_dof", "idle_dof", "redundant_constraints", "redundant_by_closure", "grubler", "actuation"):
        assert key in out
    assert set(out["actuation"]) >= {"valid", "locked_dof", "remaining"}
    assert out["closed_configuration"]["method"] == "neutral" and "platform" not in out


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
