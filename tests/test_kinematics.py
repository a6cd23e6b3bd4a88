"""Limb twists against finite differences, the two mobility methods against each other, assembly modes
selected by the seed, and continuous joints."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from model_cases import model_configurations
from numpy.testing import assert_allclose

import pinmob
from pinmob.analysis.limbs import limb_rates, limb_twists
from pinmob.assembly.residual import compute_kinematics, stacked_error
from pinmob.screw.algebra import twist_scaling
from pinmob.screw.bases import subspace_gap
from pinmob.screw.rank import RTOL


def _tip_twist_fd(model: pin.Model, q: np.ndarray, dv: np.ndarray, tip: int, p0: np.ndarray, eps: float) -> np.ndarray:
    """(v of the point p0 carried by the tip, w) from a forward difference of the tip's world pose along dv."""
    d0, d1 = model.createData(), model.createData()
    pin.framesForwardKinematics(model, d0, q)
    pin.framesForwardKinematics(model, d1, pin.integrate(model, q, eps * dv))
    m0, m1 = d0.oMf[tip], d1.oMf[tip]
    w = pin.log3(m1.rotation @ m0.rotation.T) / eps
    v_tip = (m1.translation - m0.translation) / eps
    return np.r_[v_tip + np.cross(w, p0 - m0.translation), w]


@pytest.mark.parametrize("name", sorted(pinmob.builtin_models()))
def test_limb_twists_match_finite_differences(name: str, rng: np.random.Generator) -> None:
    """Column j of a limb's twists = d(platform-origin velocity, world angular velocity)/dq along its rates.

    Differentiated numerically with pin.integrate and the tip's world pose, with the reference point at
    the platform origin. A limb without loops: at a random (not necessarily closed) configuration, one
    joint rate per column. A limb with loops inside it (the Delta's parallelograms): at a closed
    configuration, along the column's joint rates, which must keep its loops closed to first order (the
    loop residual after a step eps is O(eps^2), checked against the O(eps) drift of a generic direction).
    """
    mech = pinmob.load(name)
    model = mech.model
    eps = 1e-7
    for limb in mech.limbs:
        if limb.closures:
            q = pinmob.closed_configuration(mech, "generic")
        else:
            q = pin.integrate(model, mech.neutral(), rng.uniform(-0.3, 0.3, model.nv))
        conf = pinmob.Configuration.unchecked(mech, q)
        data = conf.data
        t = limb_twists(conf, RTOL)[mech.limbs.index(limb)]
        idx, rates = limb_rates(conf, limb, RTOL)
        assert t.shape[1] == rates.shape[1]
        p0 = data.oMf[mech.platform_id].translation.copy()
        loops = tuple(c for c in mech.closures if c.name in limb.closures)
        for col in range(rates.shape[1]):
            dv = np.zeros(model.nv)
            dv[idx] = rates[:, col]
            assert_allclose(t[:, col], _tip_twist_fd(model, q, dv, limb.tip_id, p0, eps), atol=1e-5)
            if loops:
                step = 1e-4
                d1 = model.createData()
                compute_kinematics(model, d1, pin.integrate(model, q, step * dv / np.linalg.norm(dv)))
                assert np.linalg.norm(stacked_error(mech, model, d1, loops)[0]) < 10 * step**2
        if loops:  # the check above can fail: a generic direction of the same joints opens the loops at O(eps)
            dv = np.zeros(model.nv)
            dv[idx] = rng.standard_normal(idx.size)
            d1 = model.createData()
            compute_kinematics(model, d1, pin.integrate(model, q, 1e-4 * dv / np.linalg.norm(dv)))
            assert np.linalg.norm(stacked_error(mech, model, d1, loops)[0]) > 100 * 1e-8
            assert rates.shape[1] < idx.size


@pytest.mark.parametrize(
    "name,config",
    model_configurations(),
)
def test_closure_jacobian_method_agrees_with_limb_wrenches(name: str, config: str) -> None:
    """Global loop-closure Jacobian (null space mapped through limb A) = limb-wise wrench result."""
    mech = pinmob.load(name)
    q = pinmob.closed_configuration(mech, config)
    mob = pinmob.analyze(mech, q)
    other = pinmob.closure_jacobian_twists(mech, q)
    scale = twist_scaling(mech.length_scale)[:, None]
    assert other.shape[1] == mob.dof
    assert subspace_gap(scale * other, scale * mob.free_twists) < 1e-6


def test_free_twists_are_reciprocal_to_constraints(puu) -> None:
    mob = pinmob.analyze(puu, "offset")
    assert_allclose(mob.constraint_wrenches.T @ mob.free_twists, 0.0, atol=1e-9)
    for limb in mob.limbs:
        assert_allclose(limb.wrenches.T @ mob.free_twists, 0.0, atol=1e-9)


LIMBS_TOML = 'name = "seeds"\nurdf = "3puu.urdf"\n' + "".join(
    f'[[limbs]]\nname = "{x}"\ntip = "{x}_tip"\n' for x in "ABC"
)
SEEDS_TOML = (
    LIMBS_TOML
    + """
[configurations.above]
pose = { xyz = [0.03, -0.02, -0.17], rpy = [0.0, 0.0, 0.0] }
[configurations.below]
pose = { xyz = [0.03, -0.02, -0.17], rpy = [0.0, 0.0, 0.0] }
[configurations.below.seed]  # sliders low, links tilted up (u1a = 2 beta, beta = atan2(0.2, 0.15))
A_slider = -0.35
B_slider = -0.35
C_slider = -0.35
A_u1a = 1.855
B_u1a = 1.855
C_u1a = 1.855
A_u2b = -1.855
B_u2b = -1.855
C_u2b = -1.855
"""
)


def copy_model(tmp_path: Path, toml: str, urdf_edit=lambda text: text) -> pinmob.Mechanism:
    models = pinmob.io.builtin_dir()
    (tmp_path / "3puu.urdf").write_text(urdf_edit((models / "3puu.urdf").read_text()))
    (tmp_path / "m.toml").write_text(toml)
    return pinmob.load(tmp_path / "m.toml")


def test_seed_selects_the_assembly_mode(tmp_path: Path) -> None:
    """One platform pose, two seeds, two closed configurations (the 3-PUU copy's geometry, by hand).

    Platform centre c = (0.03, -0.02), z_p = -0.17, not rotated: vertex i at c + r e_i, z_p. Its guide is
    the vertical through R e_i; the link (l = 0.25) spans the horizontal distance h_i = |c + (r - R) e_i|,
    so the slider sits at z_p + s sqrt(l^2 - h_i^2) with s = +1 (above the vertex, the neutral-side mode)
    or s = -1 (below: the seed puts the sliders low and the links pointing up).
    Each configuration is checked closed here with Pinocchio directly, not with pinmob's closure check.
    """
    mech = copy_model(tmp_path, SEEDS_TOML)
    model, data = mech.model, mech.model.createData()
    c, z_p, big_r, small_r, link = np.array([0.03, -0.02, 0.0]), -0.17, 0.3, 0.15, 0.25
    found = {}
    for name, sign in (("above", 1.0), ("below", -1.0)):
        q = pinmob.closed_configuration(mech, name)
        pin.framesForwardKinematics(model, data, q)
        platform = data.oMf[mech.platform_id]
        assert_allclose(platform.translation, c + [0, 0, z_p], atol=1e-9)
        assert_allclose(platform.rotation, np.eye(3), atol=1e-9)
        for limb in mech.limbs:
            tip = data.oMf[limb.tip_id]
            assert_allclose(tip.translation, platform.translation, atol=1e-9)
            assert_allclose(tip.rotation, platform.rotation, atol=1e-9)
        for limb, theta in zip("ABC", (0.0, 2 * np.pi / 3, 4 * np.pi / 3)):
            e = np.array([np.cos(theta), np.sin(theta), 0.0])
            h = np.linalg.norm(c + (small_r - big_r) * e)
            slider = q[model.joints[model.getJointId(f"{limb}_slider")].idx_q]
            assert slider == pytest.approx(z_p + sign * np.sqrt(link**2 - h**2), abs=1e-9)
        found[name] = q
        assert pinmob.analyze(mech, q).motion_type == "3T"
    assert np.linalg.norm(found["above"] - found["below"]) > 0.5


def test_continuous_joint_takes_an_angle(tmp_path: Path) -> None:
    """A_u1a made continuous: its q is (cos x, sin x), a value by name is an angle x, and the analysis is
    that of the revolute original (same closed pose, same 3T)."""
    original = pinmob.load("3-PUU")
    q0 = pinmob.closed_configuration(original, "offset")
    model0 = original.model
    values = {name: float(q0[model0.joints[model0.getJointId(name)].idx_q]) for name in list(model0.names)[1:]}
    angle = values["A_u1a"]
    assert abs(angle) > 0.05  # a real angle, not zero
    joints = ", ".join(f"{k} = {v!r}" for k, v in values.items())
    toml = LIMBS_TOML + f"[configurations.offset]\njoints = {{ {joints} }}\n"
    mech = copy_model(
        tmp_path,
        toml,
        lambda text: text.replace('<joint name="A_u1a" type="revolute">', '<joint name="A_u1a" type="continuous">'),
    )
    joint = mech.model.joints[mech.model.getJointId("A_u1a")]
    assert (joint.nq, joint.nv, mech.model.nq) == (2, 1, model0.nq + 1)
    q = pinmob.closed_configuration(mech, "offset")  # checked closed: a wrong (cos, sin) would not close
    assert_allclose(q[joint.idx_q : joint.idx_q + 2], [np.cos(angle), np.sin(angle)], atol=1e-15)
    mob, mob0 = pinmob.analyze(mech, q), pinmob.analyze(original, q0)
    assert (mob.dof, mob.motion_type) == (mob0.dof, mob0.motion_type) == (3, "3T")
    assert_allclose(mob.free_twists, mob0.free_twists, atol=1e-9)
    assert [limb.twist_rank for limb in mob.limbs] == [limb.twist_rank for limb in mob0.limbs]
