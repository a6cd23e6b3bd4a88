"""The 11 Extended URDF robots of LAAS-CNRS's example-parallel-robots, read as they are.

They live outside the repository, in ``<repo>/../shared/external/example-parallel-robots``
(URDF + YAML, meshes not included). Every robot must load (missing meshes: a
warning), close and be analysed. Identities checked on each: Grubler-Kutzbach
= nv - closure rows (hand count from the YAML and the joint types), mechanism
DoF = Grubler + redundant rows, idle <= locked <= mechanism DoF.
"""

from __future__ import annotations

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


def external_dir() -> Path:
    """``shared/external/example-parallel-robots`` beside the repository (fails clearly when missing)."""
    root = Path(__file__).resolve().parent.parent
    for base in (root.parent, *root.parents):
        candidate = base / "shared" / "external" / "example-parallel-robots"
        if candidate.is_dir():
            return candidate
    pytest.fail(f"the external test robots are missing: expected shared/external/example-parallel-robots beside {root}")


@pytest.fixture(scope="module")
def folder() -> Path:
    return external_dir()


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
