"""The 11 Extended URDF robots of LAAS-CNRS's example-parallel-robots, read as they are.

A copy of them, unchanged (``SHA256SUMS`` lists the upstream files' digests, checked
here), lives in ``tests/data/example-parallel-robots`` with its BSD-3-Clause licence, so
the tests need nothing outside the repository (URDF + YAML, meshes not included). Every
robot must load (missing meshes: a warning), close and be analysed. Identities checked on each: Grubler-Kutzbach
= nv - closure rows (hand count from the YAML and the joint types), mechanism
DoF = Grubler + redundant rows, idle <= locked <= mechanism DoF.
"""

from __future__ import annotations

import hashlib
import warnings
from pathlib import Path

import pytest
import yaml

import pinmob
from pinmob.closure import ClosureError, find_closed, find_closed_relaxed
from pinmob.constraints import analyze_mechanism

ROBOTS = [
    "5bar_linkage",
    "5bar_linkage_iso3d",
    "5bar_linkage_iso6d",
    "battobot_6d",
    "cassie_like",
    "digit_like",
    "disney_like",
    "kangaroo_like",
    "robot_delta",
    "talos_like",
    "wl16_like",
]


FOLDER = Path(__file__).resolve().parent / "data" / "example-parallel-robots"


def test_the_copy_is_unchanged():
    """Every file of the copy has the digest of the upstream file (read as they are, not edited)."""
    listed = {}
    for line in (FOLDER / "SHA256SUMS").read_text().splitlines():
        digest, name = line.split(maxsplit=1)
        listed[name.removeprefix("./")] = digest
    present = {p.relative_to(FOLDER).as_posix() for p in FOLDER.rglob("*") if p.is_file()} - {"SHA256SUMS"}
    assert present == set(listed)
    assert {f"{r}/robot.{ext}" for r in ROBOTS for ext in ("urdf", "yaml")} <= present
    for name, digest in listed.items():
        assert hashlib.sha256((FOLDER / name).read_bytes()).hexdigest() == digest, name


@pytest.fixture(scope="module")
def folder() -> Path:
    return FOLDER


@pytest.mark.parametrize("robot", ROBOTS)
def test_external_robot_loads_closes_and_is_analysed(folder, robot):
    path = folder / robot / "robot.yaml"
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mech = pinmob.load(path)
    assert any("geometry not loaded" in str(w.message) for w in caught), "missing meshes must cost a warning"
    doc = yaml.safe_load(path.read_text())
    assert len(mech.closures) == len(doc["closed_loop"]) and set(mech.actuated) == set(doc["name_mot"])
    if robot == "kangaroo_like":
        # as declared, its 6d loops over-constrain joints meant to be spherical: it cannot close
        with pytest.raises(ClosureError):
            find_closed(mech, restarts=2)
        mech, found, relaxed = find_closed_relaxed(mech, restarts=2)
        assert relaxed and all(c.type == "3d" for c in mech.closures if c.name in relaxed)
    else:
        found = find_closed(mech)
    assert found.residual < 1e-6
    mm = analyze_mechanism(mech, found.q)
    rows = sum({"6d": 6, "3d": 3}[c.type] for c in mech.closures)
    assert (mm.rows, mm.grubler) == (rows, mech.model.nv - rows)
    assert mm.mechanism_dof == mm.grubler + mm.redundant_constraints
    assert 0 <= mm.idle_dof <= mm.actuation.locked_dof <= mm.mechanism_dof


def test_planar_five_bars_have_two_dof(folder):
    """The three five-bars are planar loops: 2 DoF whatever the closure; the 6d one with 6 revolutes keeps a spin idle."""
    for robot, idle in (("5bar_linkage_iso3d", 0), ("5bar_linkage_iso6d", 0), ("5bar_linkage", 1)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            mech = pinmob.load(folder / robot / "robot.yaml")
        mm = analyze_mechanism(mech, find_closed(mech).q)
        assert mm.mechanism_dof - mm.idle_dof == 2 and mm.idle_dof == idle and mm.actuation.valid, robot
