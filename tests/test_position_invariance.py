"""Answers do not depend on where a mechanism stands, nor on where along its axes a file puts a joint frame (issue 22).

Every built-in model is redrawn with every revolute joint frame slid along its own axis to the point
nearest all its axes (:func:`one_point.slid`: the same kinematics; a spherical mechanism's frames all
land on its centre), then moved rigidly by up to 10 m. The independent truths: the built-in's own
answer (counts, types, classes, actuation) and the rigid move itself: the free twists and constraint
wrenches at the platform origin turn with the move (``[R v; R w]``), and every printed axis or line,
rebuilt as a screw from its direction, world point and pitch, lies in the moved span. Spherical
mechanisms with every joint frame and the platform frame at the centre (no length at all: the
3-RRR-spherical so redrawn, and ``tests/data/spherical_fivebar``, a CAD-style file whose origins are
1e-17 m of round-off) keep their hand-derived answers at the origin and 10 m away, with L = 1 m
(:data:`~pinmob.model.length_scale.NO_LENGTH`) and no sub-round-off coordinate printed.
"""

from __future__ import annotations

import functools
import re
import sys
import zlib
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose
from scipy.linalg import subspace_angles

import pinmob

sys.path.insert(0, str(Path(__file__).parent))
from millimetres import in_units, placed  # noqa: E402
from model_cases import model_configurations  # noqa: E402
from one_point import axes_meet, slid, tips_at  # noqa: E402
from test_invariance import model as builtin  # noqa: E402

DATA = Path(__file__).parent / "data"
NO_LENGTH = 1.0  # [m] L of a mechanism without any length (pinmob.model.length_scale.NO_LENGTH, documented)
FIVE_BAR = DATA / "spherical_fivebar.toml"


@functools.cache
def redrawn(name: str) -> pinmob.Mechanism:
    """The built-in with its revolute joint frames, limb tips and platform frame at the point nearest all its axes."""
    mech = builtin(name)
    centre = axes_meet(mech)
    return tips_at(slid(mech, centre), centre, sorted(mech.configurations)[0])


@functools.cache
def analysed(name: str, config: str, slide: bool) -> pinmob.Report:
    return pinmob.analyze(redrawn(name) if slide else builtin(name), config)


def move(case: str) -> pin.SE3:
    """A rigid move drawn for ``case``: any rotation, a translation of up to 10 m along each axis."""
    rng = np.random.default_rng(zlib.crc32(case.encode()))
    return pin.SE3(pin.exp3(rng.uniform(-np.pi, np.pi, 3)), rng.uniform(-10.0, 10.0, 3))


def verdicts(d: dict[str, Any]) -> dict[str, Any]:
    """Counts, types, classes and the actuation verdict: what neither a move nor a redrawing may change."""
    s, a = d["singularity"], d["actuation"] or {}
    return {
        "dof": d["dof"],
        "motion_type": d["motion_type"],
        "motions": [m["kind"] for m in d["motions"]],
        "constraint_rank": d["constraint_rank"],
        "constraints": [c["kind"] for c in d["constraints"]],
        "mechanism_dof": d["mechanism_dof"],
        "redundant_constraints": d["redundant_constraints"],
        "redundant_by_closure": d["redundant_by_closure"],
        "idle_dof": d["idle_dof"],
        "grubler_by_own_rank": d["grubler_by_own_rank"],
        "motion_subgroup": d["motion_subgroup"],
        "limbs": [(limb["name"], limb["twist_rank"], limb["serially_singular"]) for limb in d["limbs"]],
        "frames": [(f["frame"], f["dof"], f["motion_type"]) for f in d["frames"]],
        "classes": s["classes"],
        "generic_rank": s["generic_rank"],
        "locked_dof": s["locked_dof"],
        "rank_gap": s["rank_gap"],
        "near_singular": s["near_singular"],
        "actuation": {k: a.get(k) for k in ("locked_dof", "redundant_actuators", "overdetermined")},
        "actuation_valid": a.get("valid"),
        "actuation_idle_dof": a.get("idle_dof"),
        "remaining": len(a.get("remaining", [])),
        "frame_dof_locked": a.get("frame_dof_locked"),
    }


def gap(a: Any, b: Any) -> float:
    """Largest principal angle [rad] between the column spans of two (6, k) arrays (0 for two empty ones)."""
    a, b = np.asarray(a, float).reshape(-1, 6).T, np.asarray(b, float).reshape(-1, 6).T
    assert a.shape == b.shape
    return float(subspace_angles(a, b).max()) if a.shape[1] else 0.0


def screw_at(
    kind: str, direction: Any, point: Any, pitch: float | None, origin: np.ndarray, wrench: bool
) -> np.ndarray:
    """The unit screw of a printed axis (twist ``[v; w]``) or line of action (wrench ``[f; tau]``) at ``origin``.

    A line through ``point`` along ``u`` with pitch ``h``: its moment at ``origin`` is ``(point - origin) x u + h u``.
    """
    u = np.asarray(direction, float)
    if point is None:  # a translation or a couple: a free vector
        return np.concatenate([np.zeros(3), u]) if wrench else np.concatenate([u, np.zeros(3)])
    moment = np.cross(np.asarray(point, float) - origin, u) + (pitch or 0.0) * u
    return np.concatenate([u, moment]) if wrench else np.concatenate([moment, u])


def same_answers(got: pinmob.Report, ref: pinmob.Report, placement: pin.SE3, redrawn: bool = False) -> None:
    """``got`` is ``ref`` moved by ``placement``: the same verdicts, the spans and printed lines turned and moved.

    ``redrawn``: ``got`` is ``ref`` redrawn (:func:`redrawn`): the verdicts (the idle motions too: a joint's
    centre does not depend on where its frame sits on its axis, :mod:`pinmob.analysis.chain.joint_centres`), and the
    pitches (the distances, which L scales, and the twists, referred to another platform origin, differ).
    """
    g, r = got.to_dict(), ref.to_dict()
    vg, vr = verdicts(g), verdicts(r)
    assert vg == vr
    if not redrawn:
        sg, sr = g["singularity"]["distances"], r["singularity"]["distances"]
        assert_allclose([sg[k] for k in sr], list(sr.values()), atol=1e-6)
    assert_allclose([m["pitch"] or 0.0 for m in g["motions"]], [m["pitch"] or 0.0 for m in r["motions"]], atol=1e-9)
    if redrawn:
        return  # the platform origin moved to the common point: the twists are referred to another point
    turn = np.kron(np.eye(2), placement.rotation)  # twists and wrenches at the (moved) platform origin
    assert_allclose(got.platform_origin, placement.act(np.asarray(ref.platform_origin)), atol=1e-9)
    twists = turn @ np.asarray(r["free_twists"], float).reshape(-1, 6).T
    wrenches = turn @ np.asarray(r["constraint_wrenches"], float).reshape(-1, 6).T
    assert gap(g["free_twists"], twists.T) < 1e-6
    assert gap(g["constraint_wrenches"], wrenches.T) < 1e-6
    origin = np.asarray(got.platform_origin, float)
    for items, span, wrench in ((g["motions"], twists, False), (g["constraints"], wrenches, True)):
        for m in items:
            s = screw_at(m["kind"], m["direction"], m.get("world_point"), m["pitch"], origin, wrench)
            s = s / np.linalg.norm(s)
            assert np.linalg.norm(s - span @ np.linalg.lstsq(span, s, rcond=None)[0]) < 1e-6, m


@pytest.mark.parametrize(("name", "config"), model_configurations())
def test_a_redrawn_builtin_moved_by_up_to_10_m_keeps_every_answer(name: str, config: str) -> None:
    """Joint frames slid along their axes: the built-in's verdicts; moved rigidly: every answer moved with it."""
    ref = analysed(name, config, False)
    here = analysed(name, config, True)
    same_answers(here, ref, pin.SE3.Identity(), redrawn=True)
    placement = move(f"{name}/{config}")
    same_answers(pinmob.analyze(placed(redrawn(name), placement), config), here, placement)
    same_answers(pinmob.analyze(placed(builtin(name), placement), config), ref, placement)


def spherical_3rrr() -> pinmob.Mechanism:
    """The built-in spherical 3-RRR with its nine joint frames, limb tips and platform frame at the centre."""
    mech = builtin("3-RRR-spherical")
    return tips_at(slid(mech, np.zeros(3)), np.zeros(3), "generic")


def spherical_five_bar() -> pinmob.Mechanism:
    return pinmob.load(FIVE_BAR)


#: hand-derived answers: every axis through the centre; the 3-RRR's limb A stretched loses one rotation
SPHERICAL = {
    "3-RRR": (spherical_3rrr, {"generic": (3, "3R", 3), "limb-A-stretched": (2, "2R", 4)}),
    "five-bar": (spherical_five_bar, {"reference": (2, "2R", 4), "turned": (2, "2R", 4)}),
}


@pytest.mark.parametrize("case", [(m, c) for m, (_, configs) in SPHERICAL.items() for c in configs])
def test_a_spherical_mechanism_with_every_frame_at_its_centre_at_the_origin_and_10_m_away(
    case: tuple[str, str],
) -> None:
    """No length at all: L = 1 m; the hand answer at the origin; moved up to 10 m, the same answer moved."""
    which, config = case
    make, configs = SPHERICAL[which]
    mech = make()
    assert mech.length_scale == NO_LENGTH
    here = pinmob.analyze(mech, config)
    dof, motion_type, rank = configs[config]
    assert (here.dof, here.motion_type, here.constraint_rank) == (dof, motion_type, rank)
    d = here.to_dict()
    assert d["actuation"]["valid"] and d["actuation"]["locked_dof"] == 0  # the actuators hold every motion
    centre = np.zeros(3)
    for item in d["motions"] + d["constraints"]:  # every axis and every force's line passes through the centre
        if item["world_point"] is not None:
            assert item["world_point"] == [0.0, 0.0, 0.0]
    for k in (1, 2, 3):
        placement = move(f"{which}/{config}/{k}")
        moved = placed(mech, placement)
        assert moved.length_scale == NO_LENGTH
        got = pinmob.analyze(moved, config)
        same_answers(got, here, placement)
        for item in got.to_dict()["motions"] + got.to_dict()["constraints"]:
            if item["world_point"] is not None:
                assert_allclose(item["world_point"], placement.act(centre), atol=1e-12)


def test_the_spherical_five_bar_locked_by_its_actuators_and_its_limb_constraints() -> None:
    """Hand truth: limb A (axes u1, u2 through the centre) is constrained by the couple along u1 x u2 and three forces."""
    mech = spherical_five_bar()
    for config in ("reference", "turned"):
        for placement in (pin.SE3.Identity(), move(f"couple/{config}")):
            moved = placed(mech, placement)
            conf = pinmob.Configuration(moved, config)
            model, data = moved.model, moved.model.createData()
            pin.forwardKinematics(model, data, conf.q)
            u1, u2 = (data.oMi[model.getJointId(j)].rotation[:, 2] for j in ("A_r1", "A_r2"))  # axes: z of each frame
            couple = np.cross(u1, u2) / np.linalg.norm(np.cross(u1, u2))
            report = pinmob.analyze(moved, config)
            couples = [c for c in report.constraints if c.kind.value == "couple"]
            assert len(couples) == 1 and abs(abs(float(couples[0].direction @ couple)) - 1.0) < 1e-9
            assert report.to_dict()["actuation"]["locked_dof"] == 0


#: a coordinate printed in the text: a number in a bracketed vector after "through" or "meet at"
POINT_TEXT = re.compile(r"(?:through|meet at) \[([^\]]*)\]")


@pytest.mark.parametrize("which", sorted(SPHERICAL))
def test_a_spherical_mechanism_at_the_origin_prints_no_sub_round_off_coordinate(which: str) -> None:
    """Every printed point (text and JSON) is the centre, [0, 0, 0]: no 1e-17 or 7e-30 m left of the round-off."""
    make, configs = SPHERICAL[which]
    mech = make()
    for config in configs:
        report = pinmob.analyze(mech, config)
        text = str(report)
        points = POINT_TEXT.findall(text)
        assert points, text
        for p in points:
            assert [float(x) for x in p.split(",")] == [0.0, 0.0, 0.0], text
        d = report.to_dict()
        for item in d["motions"] + d["constraints"] + [m for f in d["frames"] for m in f["motions"]]:
            for key in ("point", "world_point"):
                if item.get(key) is not None:
                    assert item[key] == [0.0, 0.0, 0.0], item


def test_a_micrometre_mechanism_10_m_away_prints_no_round_off_of_its_position() -> None:
    """The 3-RRR-spherical in micrometres (L = 1.6e-6 m) 10 m along x, turned about x: its centre is (10, 0, 0).

    A coordinate that is round-off of the 10 m (5e-16 m, far below L too) prints as 0; the true
    micrometre offsets of the axis points from the centre (1.5e-6 m) still print.
    """
    mech = in_units(builtin("3-RRR-spherical"), 1e-5, configurations=True)
    placement = pin.SE3(pin.rpy.rpyToMatrix(0.7, 0.0, 0.0), np.array([10.0, 0.0, 0.0]))
    report = pinmob.analyze(placed(mech, placement), "generic")
    coordinates = [abs(float(x)) for p in POINT_TEXT.findall(str(report)) for x in p.split(",")]
    assert coordinates and all(x == 0.0 or x > 1e-9 for x in coordinates), str(report)
    assert any(1e-7 < x < 1e-5 for x in coordinates)
    d = report.to_dict()
    points = [m["world_point"] for m in d["motions"] + d["constraints"] if m.get("world_point") is not None]
    assert all(x == 0.0 or abs(x) > 1e-9 for p in points for x in p), points


SHAFT = """<mujoco model="shaft">
  <worldbody>
    <body name="shaft" pos="{x} {y} {z}">
      <joint name="j1" type="hinge" axis="0.3 0.5 0.8"/><geom type="sphere" size="0.01"/>
      <site name="on_axis" pos="0.06 0.1 0.16"/>
    </body>
    <site name="bearing" pos="{bx} {by} {bz}"/>
  </worldbody>
  <equality><connect site1="on_axis" site2="bearing"/></equality>
  <keyframe><key name="at" qpos="0.7"/></keyframe>
</mujoco>"""


@pytest.mark.parametrize("where", [(0.0, 0.0, 0.0), (6.0, -8.0, 0.5)])
def test_a_closure_of_round_off_only_adds_no_constraint_wherever_it_stands(where, tmp_path):
    """A shaft held by a ball on its own axis (a second bearing, as CAD draws it): the closure's rows are 0 up to
    round-off, the shaft keeps its 1 DoF (by hand; MuJoCo's equality rows are 0 too). At the origin the round-off
    (1e-17) was counted against a tolerance relative to itself: 'mechanism DoF 0', and DoF 1 when moved."""
    x, y, z = where
    path = tmp_path / "shaft.xml"
    path.write_text(SHAFT.format(x=x, y=y, z=z, bx=x + 0.06, by=y + 0.1, bz=z + 0.16))
    doc = pinmob.analyze(pinmob.load(path), "at").to_dict()
    assert (doc["mechanism_dof"], doc["closure_rank"], doc["redundant_constraints"]) == (1, 0, 3)
