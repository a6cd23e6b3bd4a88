"""The motion subgroup of a mechanism's joint screws, and the Grubler-Kutzbach count it explains (issue 34).

Truths: screws drawn by hand for each subgroup (rotations about parallel axes and in-plane translations,
rotations through one point, ...), random screws (no subgroup), and the planar and spherical Grubler-Kutzbach
counts of textbook mechanisms, ``3 (n - 1) - 2 j`` for n links and j revolute joints.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import pinmob
from pinmob.screw.subgroup import motion_subgroup


def rotation(axis, point) -> np.ndarray:
    w = np.asarray(axis, float) / np.linalg.norm(axis)
    return np.r_[np.cross(point, w), w]  # [v; w] at the origin of a rotation about the line (point, w)


def translation(direction) -> np.ndarray:
    return np.r_[np.asarray(direction, float) / np.linalg.norm(direction), 0.0, 0.0, 0.0]


RNG = np.random.default_rng(7)
N = np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])  # a plane normal not along an axis
IN_PLANE = np.cross(N, [1.0, 0.0, 0.0])
CENTRE = np.array([0.2, -0.1, 0.4])
CASES = {
    "planar": [rotation(N, RNG.normal(size=3)) for _ in range(5)] + [translation(IN_PLANE)],
    "spherical": [rotation(RNG.normal(size=3), CENTRE) for _ in range(5)],
    "translational": [translation(RNG.normal(size=3)) for _ in range(4)],
    "cylindrical": [rotation(N, CENTRE), translation(N), rotation(N, CENTRE) + 0.3 * translation(N)],
    "Schoenflies": [rotation(N, RNG.normal(size=3)) for _ in range(4)] + [translation(RNG.normal(size=3))],
}
DIMENSIONS = {
    "planar": (3, 2),
    "spherical": (3, 0),
    "translational": (3, 3),
    "cylindrical": (2, 1),
    "Schoenflies": (4, 3),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_each_subgroup_is_named_wherever_it_stands(name):
    twists = np.array(CASES[name]).T
    for move in (pin.SE3.Identity(), pin.SE3(pin.exp3(np.array([0.4, -1.0, 2.0])), np.array([3.0, -7.0, 1.0]))):
        moved = move.toActionMatrix() @ twists  # the same mechanism placed elsewhere
        group = motion_subgroup(moved)
        assert group is not None and (group.name, (group.dimension, group.translations)) == (name, DIMENSIONS[name])


def test_screws_that_span_no_subgroup():
    assert motion_subgroup(RNG.normal(size=(6, 9))) is None  # all of SE(3)
    three_lines = np.array([rotation(RNG.normal(size=3), RNG.normal(size=3)) for _ in range(3)]).T
    assert motion_subgroup(three_lines) is None  # 3 skew rotations: their brackets leave the span
    helical = np.array([np.r_[0.0, 0.0, 0.5, 0.0, 0.0, 1.0], translation([1, 0, 0]), translation([0, 1, 0])]).T
    group = motion_subgroup(helical)  # a screw about the normal of the translations' plane: a group, not planar
    assert group is not None and group.name == "3-dimensional"


@pytest.mark.parametrize(
    ("name", "links", "joints", "subgroup"),
    [("3-RRR-planar", 8, 9, "planar"), ("3-RRR-spherical", 8, 9, "spherical")],
)
def test_the_count_by_own_ranks_is_the_planar_or_spherical_grubler_count(name, links, joints, subgroup):
    """Base, two links a limb and the platform; nine revolute joints: ``3 (8 - 1) - 2 x 9 = 3`` in the plane or on the
    sphere, where the spatial count gives ``6 (8 - 1) - 5 x 9 = -3``."""
    report = pinmob.analyze(pinmob.load(name), "generic")
    doc = report.to_dict()
    assert doc["grubler"] == 6 * (links - 1) - 5 * joints
    assert doc["grubler_by_own_rank"] == 3 * (links - 1) - 2 * joints
    assert doc["motion_subgroup"] == {"dimension": 3, "translations": DIMENSIONS[subgroup][1], "name": subgroup}
    assert f"every joint screw lies in a {subgroup} motion subgroup of dimension 3" in str(report)
    assert "counted by those ranks, nv 9 - 6 = 3" in str(report)


@pytest.mark.parametrize("name", ["6-UPS", "Delta", "3-PUU"])
def test_spatial_mechanisms_have_no_subgroup_and_no_note(name):
    report = pinmob.analyze(pinmob.load(name), "generic")
    doc = report.to_dict()
    assert doc["motion_subgroup"] is None
    assert doc["grubler_by_own_rank"] == doc["grubler"]  # no closure's own rows are dependent
    assert "the spatial count" not in str(report)
