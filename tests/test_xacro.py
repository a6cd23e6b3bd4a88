"""xacro descriptions (issue 31, item 3): expanded by the PyPI xacro library under pinmob's evaluator, analysed.

2b-t/closed_loop (MIT, tests/data/xacro/closed_loop): ``$(find closed_loop)`` includes, properties, macros with
defaults, an argument, ``${-pi/2}``; the loop joint ``1_to_4`` is written for Gazebo inside ``<gazebo>``. By hand:
element_1 is fixed at (0, 0.35, 0.35); each next element hangs 0.7 along its parent's -y and turns -pi/2 about x,
so the four elements are the sides of a 0.7 m square in the y-z plane and element_4's end meets element_1's origin,
where the revolute loop joint about x is. Three continuous hinges about x (nv 3) and a revolute closure (5 rows) of
which the in-plane ones count (y, z, rotation about x): rank 2, DoF 1 (a parallelogram).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from test_cad_gaps import pinmob_cli

import pinmob
from pinmob.exceptions import MechanismFileError
from pinmob.io.xacro_file import expand_xacro

DATA = Path(__file__).parent / "data" / "xacro"
CLOSED_LOOP = DATA / "closed_loop" / "urdf" / "closed_loop.urdf.xacro"


def test_closed_loop_expands_and_analyses_as_a_parallelogram():
    done = pinmob_cli("analyze", str(CLOSED_LOOP), "--package-path", str(DATA), "--json")
    assert done.returncode == 0, done.stderr
    doc = json.loads(done.stdout)
    assert (doc["nv"], doc["closure_rows"], doc["closure_rank"], doc["mechanism_dof"]) == (3, 5, 2, 1)
    mech = pinmob.load(CLOSED_LOOP, package_dirs=[DATA])
    assert [(c.name, c.type) for c in mech.closures] == [("1_to_4", "revolute")]
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    corners = {f"element_{k}": data.oMf[mech.model.getFrameId(f"element_{k}")].translation for k in range(1, 5)}
    hand = {"element_1": (0, 0.35, 0.35), "element_2": (0, -0.35, 0.35), "element_3": (0, -0.35, 1.05)}
    hand["element_4"] = (0, 0.35, 1.05)
    for name, at in hand.items():
        np.testing.assert_allclose(corners[name], at, atol=1e-12)


def test_a_xacro_argument_and_the_package_path_are_used():
    """``is_gravity`` reaches the Gazebo tag; without a package folder $(find) names the way out."""
    text = expand_xacro(CLOSED_LOOP, {"is_gravity": "false"}, [DATA])
    assert "<turnGravityOff>True</turnGravityOff>" in text
    assert "<turnGravityOff>False</turnGravityOff>" in expand_xacro(CLOSED_LOOP, {}, [DATA])
    refused = pinmob_cli("analyze", str(CLOSED_LOOP))
    assert refused.returncode == 2 and refused.stderr.count("\n") == 1
    assert "$(find closed_loop): no package 'closed_loop'" in refused.stderr and "name the folder" in refused.stderr
    bad = pinmob_cli("analyze", str(CLOSED_LOOP), "--package-path", str(DATA), "--xacro-arg", "is_gravity=1")
    assert bad.returncode == 2 and "is not NAME:=VALUE" in bad.stderr


def test_ros_package_path_is_searched(monkeypatch):
    monkeypatch.setenv("ROS_PACKAGE_PATH", str(DATA))
    assert len(pinmob.load(CLOSED_LOOP).closures) == 1


def test_the_expressions_xacro_files_use_evaluate_as_xacro_says(tmp_path):
    """Properties, arithmetic, math (bare and math.), comparisons, conditionals, xacro:if, args with defaults."""
    (tmp_path / "m.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="r"><xacro:arg name="n" default="3"/>'
        '<xacro:property name="a" value="0.5"/><xacro:property name="b" value="${a*2 + sin(0) + math.cos(0)}"/>'
        '<xacro:if value="${b > 1 and not (a == 0)}"><link name="l_${b}_${int($(arg n))**2}_${a if b else 0}"/>'
        "</xacro:if></robot>"
    )
    assert '<link name="l_2.0_9_0.5"/>' in expand_xacro(tmp_path / "m.xacro", {})
    assert '<link name="l_2.0_16_0.5"/>' in expand_xacro(tmp_path / "m.xacro", {"n": "4"})


def test_a_xacro_without_a_loop_is_refused_as_a_plain_urdf(tmp_path):
    (tmp_path / "t.urdf.xacro").write_text(
        '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="t"><link name="a"/></robot>'
    )
    with pytest.raises(MechanismFileError, match="has no loop closure"):
        pinmob.load(tmp_path / "t.urdf.xacro")


ROBOTIQ = DATA / "robotiq" / "robotiq_2f_85_gripper_visualization" / "urdf" / "robotiq_arg2f_85_model.xacro"


def test_robotiq_2f85_expands_with_its_mimic_joints():
    """ros-industrial's Robotiq 2F-85 (BSD): two levels of $(find) includes and a macro with a prefix. By hand from
    robotiq_arg2f_85_model_macro.xacro: six revolute joints, finger_joint driving five mimics, multipliers
    1 (right_outer_knuckle), -1 (the two inner fingers), 1 (the two inner knuckles)."""
    from xml.etree import ElementTree

    root = ElementTree.fromstring(expand_xacro(ROBOTIQ, {}, [DATA / "robotiq"]))
    joints = {j.get("name"): j for j in root.findall("joint")}  # not the <transmission>'s <joint>
    moving = sorted(n for n, j in joints.items() if j.get("type") == "revolute")
    assert moving == sorted(
        ["finger_joint", "left_inner_finger_joint", "left_inner_knuckle_joint", "right_inner_knuckle_joint",
         "right_outer_knuckle_joint", "right_inner_finger_joint"]
    )  # fmt: skip
    mimics = {n: float(j.find("mimic").get("multiplier")) for n, j in joints.items() if j.find("mimic") is not None}
    assert mimics == {
        "right_outer_knuckle_joint": 1.0,
        "left_inner_finger_joint": -1.0,
        "right_inner_finger_joint": -1.0,
        "left_inner_knuckle_joint": 1.0,
        "right_inner_knuckle_joint": 1.0,
    }
    assert all(j.find("mimic").get("joint") == "finger_joint" for j in joints.values() if j.find("mimic") is not None)


def test_a_toml_file_may_name_a_xacro_file(tmp_path):
    """tests/data/fourbar (a planar four-bar of four hinges in the tree closed by a 6d weld: 6 rows of which the 3
    in the plane count, DoF 4 - 3 = 1 by hand) with its URDF written as xacro: ${...} for two offsets."""
    urdf = (DATA.parent / "fourbar.urdf").read_text()
    urdf = urdf.replace('<robot name="', '<robot xmlns:xacro="http://www.ros.org/wiki/xacro" name="', 1)
    urdf = urdf.replace('xyz="0.3 0.1 0"', 'xyz="${3 * c} ${c} 0"').replace('xyz="0 0.2 0"', 'xyz="0 ${2 * c} 0"')
    head = urdf.index(">", urdf.index("<robot")) + 1
    urdf = urdf[:head] + '<xacro:property name="c" value="0.1"/>' + urdf[head:]
    (tmp_path / "fourbar.urdf.xacro").write_text(urdf)
    toml = (DATA.parent / "fourbar.toml").read_text().replace('urdf = "fourbar.urdf"', 'urdf = "fourbar.urdf.xacro"')
    (tmp_path / "fourbar.toml").write_text(toml)
    report = pinmob.analyze(pinmob.load(tmp_path / "fourbar.toml"), "home")
    chain = report.mechanism_mobility
    assert (chain.nv, chain.rows, chain.rank, chain.mechanism_dof) == (4, 6, 3, 1)


def test_robotiq_2f85_xacro_is_analysed_with_its_mimic_couplings():
    """The expanded 2F-85: six hinges, five mimic rows (each q_j = k q_finger_joint, independent: each names its own
    joint), DoF 6 - 5 = 1 by hand; a mimic is a joint coupling named mimic_<joint>."""
    done = pinmob_cli("analyze", str(ROBOTIQ), "--package-path", str(DATA / "robotiq"), "--json")
    assert done.returncode == 0, done.stderr
    doc = json.loads(done.stdout)
    assert (doc["nv"], doc["closure_rows"], doc["closure_rank"], doc["mechanism_dof"]) == (6, 5, 5, 1)
    mech = pinmob.load(ROBOTIQ, package_dirs=[DATA / "robotiq"])
    assert sorted(c.name for c in mech.closures) == sorted(
        f"mimic_{j}" for j in ("right_outer_knuckle_joint", "left_inner_finger_joint", "right_inner_finger_joint",
                               "left_inner_knuckle_joint", "right_inner_knuckle_joint")
    )  # fmt: skip
