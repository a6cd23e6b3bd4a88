"""Limb twists against finite differences, and the two mobility methods against each other."""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.closure import compute_kinematics
from pinmob.mobility import limb_twists
from pinmob.screw import subspace_gap, twist_scaling


@pytest.mark.parametrize("name", ["3-PUU", "3-PUU-flat", "3-PUU-vertical"])
def test_limb_twists_match_finite_differences(name: str, rng: np.random.Generator) -> None:
    """Column j of a limb's twists = d(platform-origin velocity, world angular velocity)/dq_j.

    Differentiated numerically with pin.integrate and the tip's world pose, at a random
    (not necessarily closed) configuration, with the reference point at the platform origin.
    """
    mech = pinmob.load(name)
    model = mech.model
    q = pin.integrate(model, mech.neutral(), rng.uniform(-0.3, 0.3, model.nv))
    data = model.createData()
    compute_kinematics(model, data, q)
    twists = limb_twists(mech, data)
    p0 = data.oMf[mech.platform_id].translation.copy()
    eps = 1e-7
    for limb, t in zip(mech.limbs, twists):
        m0 = data.oMf[limb.tip_id].copy()
        for col, vi in enumerate(limb.v_indices):
            dv = np.zeros(model.nv)
            dv[vi] = eps
            d2 = model.createData()
            pin.framesForwardKinematics(model, d2, pin.integrate(model, q, dv))
            m1 = d2.oMf[limb.tip_id]
            w = pin.log3(m1.rotation @ m0.rotation.T) / eps
            v_tip = (m1.translation - m0.translation) / eps
            v_platform_point = v_tip + np.cross(w, p0 - m0.translation)
            assert_allclose(t[:, col], np.r_[v_platform_point, w], atol=1e-5)


@pytest.mark.parametrize(
    "name,config",
    [(n, c) for n in pinmob.builtin_models() for c in pinmob.load(n).configurations],
)
def test_closure_jacobian_method_agrees_with_limb_wrenches(name: str, config: str) -> None:
    """Global loop-closure Jacobian (null space mapped through limb A) = limb-wise wrench result."""
    mech = pinmob.load(name)
    q = mech.configuration(config)
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
