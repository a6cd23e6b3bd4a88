"""Generated geometry: every built-in model drawn as links between consecutive joint origins."""

from __future__ import annotations

import coal
import numpy as np
import pinocchio as pin
import pytest
from millimetres import in_millimetres
from numpy.testing import assert_allclose

import pinmob
from pinmob.viewer.skeleton import skeleton_geometry, visual_geometry


@pytest.mark.parametrize("name", ["3-PUU", "3-PUU-flat", "3-PUU-vertical"])
def test_builtin_models_get_a_stick_figure(name):
    mech = pinmob.load(name)
    q = pinmob.closed_configuration(mech, next(iter(mech.configurations)))
    geom, generated = visual_geometry(mech, q)
    assert generated
    names = [g.name for g in geom.geometryObjects]
    # per limb: slider block + rail, 4 revolute markers, links: slider->u2 (one), u2->tip (one)
    for limb in "ABC":
        assert f"{limb}_slider/slider" in names and f"{limb}_slider/rail" in names
        assert sum(n.startswith(f"{limb}_u") and n.endswith("/joint") for n in names) == 4
        assert sum(n.startswith(f"{limb}_") and "/link" in n for n in names) == 2
    assert "platform/disc" in names


def test_links_join_consecutive_joint_origins():
    mech = pinmob.load("3-PUU-flat")
    q = pinmob.closed_configuration(mech, "flat")
    geom = skeleton_geometry(mech, q)
    data = mech.model.createData()
    gdata = pin.GeometryData(geom)
    pin.updateGeometryPlacements(mech.model, data, geom, gdata, q)
    # hand geometry of 3-PUU-flat at beta = 0: guide of limb A at (R, 0, 0), platform vertex
    # at (r, 0, 0), centre at 0, with R = 0.3 m, r = 0.15 m.
    big_r, small_r = 0.3, 0.15
    ends = {}
    for i, g in enumerate(geom.geometryObjects):
        if g.name.startswith("A_") and "/link" in g.name:
            m = gdata.oMg[i]
            half = g.geometry.halfLength
            axis = m.rotation[:, 2]
            ends[g.name] = sorted([tuple(np.round(m.translation + s * half * axis, 9)) for s in (-1, 1)])
    segments = sorted(ends.values())
    assert_allclose(
        segments, [[(0.0, 0.0, 0.0), (small_r, 0.0, 0.0)], [(small_r, 0.0, 0.0), (big_r, 0.0, 0.0)]], atol=1e-9
    )
    disc = geom.geometryObjects[geom.getGeometryId("platform/disc")].geometry
    assert isinstance(disc, coal.Cylinder)
    assert_allclose(disc.radius, small_r, atol=1e-12)


def test_sizes_scale_with_units():
    # The same stick figure for a model in millimetres: every size times 1000.
    mech = pinmob.load("3-PUU")
    q = pinmob.closed_configuration(mech, "generic")
    idx = [mech.model.joints[mech.model.getJointId(f"{x}_slider")].idx_q for x in "ABC"]
    q_mm = q.copy()
    q_mm[idx] *= 1000
    mm = in_millimetres(mech)
    g_m, g_mm = skeleton_geometry(mech, q), skeleton_geometry(mm, q_mm)
    for a, b in zip(g_m.geometryObjects, g_mm.geometryObjects, strict=True):
        assert a.name == b.name
        assert_allclose(1000 * a.placement.translation, b.placement.translation, atol=1e-6)
        if isinstance(a.geometry, coal.Cylinder):
            assert_allclose(1000 * a.geometry.radius, b.geometry.radius, rtol=1e-9)
            assert_allclose(1000 * a.geometry.halfLength, b.geometry.halfLength, rtol=1e-9)
