"""The same mechanism in metres and in millimetres gives the same answer (pitches and points x 1000)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.builder import MechanismBuilder
from pinmob.catalog import three_puu


def skew_pair(scale: float) -> MechanismBuilder:
    """One limb of two revolutes with skew axes: its twist system is a cylindroid (2 screws, pitches != 0)."""
    b = MechanismBuilder(f"skew-pair-{scale:g}")
    limb = b.limb("A")
    limb.revolute("r1", at=[0, 0, 0], axis=[0, 0, 1])
    limb.revolute("r2", at=[0, 0.1 * scale, 0], axis=[1, 0, 0])
    limb.tip(at=[0, 0, 0])
    return b


@pytest.mark.parametrize("factor", [1000.0, 0.001])
def test_three_puu_in_other_units(tmp_path: Path, factor: float) -> None:
    results = []
    for k, sub in ((1.0, "m"), (factor, "x")):
        b = three_puu("scaled", "", 0.3 * k, 0.15 * k, 0.2 * k, stroke=k)
        confs = {"offset": {"pose": {"xyz": [0.03 * k, -0.02 * k, -0.17 * k], "rpy": [0.0, 0.0, 0.0]}}}
        mech = pinmob.load(b.write(tmp_path / sub, "m", confs))
        results.append(pinmob.analyze(mech, "offset"))
    a, b_ = results
    assert (a.dof, a.motion_type, a.constraint_rank) == (b_.dof, b_.motion_type, b_.constraint_rank) == (3, "3T", 3)
    assert_allclose(a.singular_values, b_.singular_values, atol=1e-9)
    assert_allclose(b_.length_scale, a.length_scale * factor, rtol=1e-12)


@pytest.mark.parametrize("factor", [1000.0, 0.001])
def test_pitches_and_points_scale(tmp_path: Path, factor: float) -> None:
    mobs = []
    for k, sub in ((1.0, "m"), (factor, "x")):
        mech = pinmob.load(skew_pair(k).write(tmp_path / sub, "pair", {"home": {"joints": {"A_r1": 0.0}}}))
        mobs.append(pinmob.analyze(mech, "home"))
    a, b = mobs
    assert a.motion_type == b.motion_type == "2H"
    assert_allclose([m.pitch * factor for m in a.motions], [m.pitch for m in b.motions], rtol=1e-9)
    for ma, mb in zip(a.motions, b.motions):
        assert_allclose(ma.direction, mb.direction, atol=1e-9)
        assert_allclose(ma.point * factor, mb.point, atol=1e-9 * factor)


def test_skew_pair_principal_pitches_by_hand(tmp_path: Path) -> None:
    """Cylindroid of two zero-pitch screws on perpendicular skew axes at distance c (Hunt 1978, ch. 12).

    S1 = [0; z] (the z axis), S2 = [(0, c, 0) x x; x] = [(0, 0, -c); x] (the x line through (0, c, 0)).
    For alpha S1 + beta S2: w = (beta, 0, alpha), v = (0, 0, -beta c), so the pitch is
    h = w.v / w.w = -alpha beta c / (alpha^2 + beta^2), stationary at alpha = +-beta:
    h = -c/2 about (1, 0, 1)/sqrt2 and +c/2 about (1, 0, -1)/sqrt2, both axes through
    the midpoint (0, c/2, 0) of the common perpendicular.
    """
    c = 0.1
    mech = pinmob.load(skew_pair(1.0).write(tmp_path, "pair", {"home": {"joints": {"A_r1": 0.0}}}))
    mob = pinmob.analyze(mech, "home")
    assert mob.motion_type == "2H"
    lo, hi = mob.motions
    assert_allclose([lo.pitch, hi.pitch], [-c / 2, c / 2], atol=1e-12)
    assert_allclose(lo.direction, np.array([1, 0, 1]) / np.sqrt(2), atol=1e-12)
    assert_allclose(hi.direction, np.array([1, 0, -1]) / np.sqrt(2), atol=1e-12)
    for m in mob.motions:
        assert_allclose(m.point, [0, c / 2, 0], atol=1e-12)
