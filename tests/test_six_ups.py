"""6-UPS Gough-Stewart: free mobility and Fichter's actuation singularity, against hand-coded line geometry."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob import analyze_singularity
from pinmob.screw.algebra import twist_scaling, wrench_scaling
from pinmob.screw.bases import subspace_gap

BASE_R, PLAT_R, HALF, HEIGHT = 0.5, 0.3, np.deg2rad(10.0), 0.4


def hand_points() -> tuple[np.ndarray, np.ndarray]:
    """Base points b_i and platform points p_i (platform frame) of the design, by hand."""
    b, p = [], []
    for i in range(6):
        k, s = i // 2, (-1 if i % 2 == 0 else 1)
        a = 2 * np.pi / 3 * k + s * HALF
        c = 2 * np.pi / 3 * k + s * (np.pi / 3 - HALF)
        b.append([BASE_R * np.cos(a), BASE_R * np.sin(a), 0.0])
        p.append([PLAT_R * np.cos(c), PLAT_R * np.sin(c), 0.0])
    return np.array(b), np.array(p)


def rz(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def pluecker(rotation: np.ndarray, position: np.ndarray) -> np.ndarray:
    """(6, 6) rows: unit leg line [s; b x s] (a force along the leg, moment about the world origin)."""
    b, p = hand_points()
    rows = []
    for bi, pi in zip(b, p):
        s = rotation @ pi + position - bi
        s /= np.linalg.norm(s)
        rows.append(np.concatenate([s, np.cross(bi, s)]))
    return np.array(rows)


def rel_sigma_min(m: np.ndarray) -> float:
    s = np.linalg.svd(m, compute_uv=False)
    return float(s[-1] / s[0])


@pytest.fixture(scope="module")
def ups() -> pinmob.Mechanism:
    return pinmob.load("6-UPS")


def test_model_matches_hand_geometry(ups):
    data = ups.model.createData()
    q = pinmob.closed_configuration(ups, "home")
    pin.forwardKinematics(ups.model, data, q)
    b, p = hand_points()
    for i, limb in enumerate("ABCDEF"):
        assert_allclose(data.oMi[ups.model.getJointId(f"{limb}_ua")].translation, b[i], atol=1e-12)
        assert_allclose(data.oMi[ups.model.getJointId(f"{limb}_sa")].translation, p[i] + [0, 0, HEIGHT], atol=1e-12)


def test_fichter_pose_is_singular_by_line_geometry():
    # Fichter (1986): turned by +-90 deg about the vertical, singular at any height; not at home
    for h in (0.3, 0.4, 0.7):
        assert rel_sigma_min(pluecker(rz(np.pi / 2), np.array([0, 0, h]))) < 1e-12
        assert rel_sigma_min(pluecker(rz(-np.pi / 2), np.array([0, 0, h]))) < 1e-12
        assert rel_sigma_min(pluecker(np.eye(3), np.array([0, 0, h]))) > 1e-2


@pytest.mark.parametrize("config", ["generic", "home", "type2"])
def test_free_mobility_is_3t3r(ups, config):
    mob = pinmob.analyze(ups, config)
    assert (mob.dof, mob.motion_type, mob.constraint_rank) == (6, "3T3R", 0)
    exp = ups.expected[config]
    assert (exp.dof, exp.motion_type) == (6, "3T3R")


def test_type2_pose_is_actuation_singular_with_the_hand_null_twist(ups):
    q = pinmob.closed_configuration(ups, "type2")
    data = ups.model.createData()
    pin.framesForwardKinematics(ups.model, data, q)
    pose = data.oMf[ups.platform_id]
    assert_allclose(pose.rotation, rz(np.pi / 2), atol=1e-9)
    assert_allclose(pose.translation, [0, 0, HEIGHT], atol=1e-9)
    sing = analyze_singularity(ups, q)
    assert sing.actuation is True and not sing.constraint and sing.limbs == ()
    assert sing.locked_dof == 1 and sing.distance < 1e-9
    # null twist of the hand Pluecker matrix (twist [v; w] at the world origin), carried to the platform origin
    m = pluecker(rz(np.pi / 2), np.array([0, 0, HEIGHT]))
    t0 = np.linalg.svd(m)[2][-1]
    t = np.concatenate([t0[:3] + np.cross(t0[3:], [0, 0, HEIGHT]), t0[3:]])
    scale = twist_scaling(ups.length_scale)[:, None]
    assert subspace_gap(scale * sing.uncontrolled_twists, scale * t[:, None]) < 1e-6


def test_actuation_wrenches_are_the_leg_lines(ups):
    q = pinmob.closed_configuration(ups, "generic")
    sing = analyze_singularity(ups, q)
    assert sing.actuation is False and sing.locked_dof == 0 and sing.distance > 0.05
    data = ups.model.createData()
    pin.framesForwardKinematics(ups.model, data, q)
    pose = data.oMf[ups.platform_id]
    lines = pluecker(pose.rotation, pose.translation).T  # wrenches at the world origin
    p = pose.translation
    lines[3:] -= np.cross(p, lines[:3], axis=0)  # moments about the platform origin
    sw = wrench_scaling(ups.length_scale)[:, None]
    assert sing.actuation_wrenches.shape == (6, 6)
    # each actuation wrench is one leg's line: parallel to exactly one row
    for w in (sw * sing.actuation_wrenches).T:
        cos = np.abs((sw * lines).T @ w) / np.linalg.norm(sw * lines, axis=0) / np.linalg.norm(w)
        assert np.sum(cos > 1 - 1e-9) == 1


@pytest.mark.parametrize("config,singular", [("generic", False), ("home", False), ("type2", True)])
def test_cli_reports_the_type2_singularity(capsys, config, singular):
    """``pinmob analyze 6-UPS --config C`` shows the free mobility the file expects (3T3R everywhere) and the
    actuation (Type II) singularity exactly at Fichter's 90-degree twist, where the six leg lines are dependent
    (test_fichter_pose_is_singular_by_line_geometry); home and generic are not singular (same line geometry)."""
    from pinmob.cli import main

    assert main(["analyze", "6-UPS", "--config", config, "--check"]) == 0
    out = capsys.readouterr().out
    assert f"6-UPS at '{config}': 6 DoF, 3T3R" in out and "analysis agrees with it" in out
    assert ("actuation (Type II): SINGULAR" in out) is singular
    assert ("actuation (Type II): no" in out) is not singular
