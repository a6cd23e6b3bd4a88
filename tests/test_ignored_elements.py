"""Nothing dropped silently (issue 31, item 7): the loop and coupling elements pinmob does not read are named in one
warning, in the DoF line and in the JSON (``ignored``), across formats.

- URDF: a ``<constraint>`` element (the loop closures proposed in ros/urdfdom#264) beside a loop pinmob reads
  (a ``<gazebo><joint>``);
- MJCF: an inactive equality (``active="false"``), left out as MuJoCo leaves it out at the start;
- SDF: an ``<axis><mimic>`` (tests/test_sdf.py).
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import pytest
from test_cad_gaps import pinmob_cli

import pinmob

DATA = Path(__file__).parent / "data"

URDF = """<robot name="fourbar">
  <link name="world"/><link name="crank"/><link name="coupler"/><link name="rocker"/>
  <joint name="crank" type="revolute"><parent link="world"/><child link="crank"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="coupler" type="revolute"><parent link="crank"/><child link="coupler"/><origin xyz="0 0.1 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="rocker" type="revolute"><parent link="world"/><child link="rocker"/><origin xyz="0.3 0 0"/>
    <axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <gazebo><joint name="tip" type="revolute"><parent>coupler</parent><child>rocker</child>
    <pose>0 0.1 0 0 0 0</pose><axis><xyz>0 0 1</xyz></axis></joint></gazebo>
  <constraint name="extra" type="ball"><parent link="coupler"/><child link="rocker"/></constraint>
</robot>"""


def test_a_urdf_constraint_is_named_once_and_in_the_dof_line(tmp_path):
    """The parallelogram (crank 0.1, coupler 0.3, rocker 0.1 pivoted at x 0.3) closes by the Gazebo joint: DoF 1 by
    hand (3 hinges, a planar revolute closure of rank 2); its <constraint> is not read and the DoF says so."""
    path = tmp_path / "fourbar.urdf"
    path.write_text(URDF)
    with pytest.warns(UserWarning, match="not read: <constraint> 'extra'"):
        mech = pinmob.load(path)
    assert mech.ignored == ("<constraint> 'extra'",)
    done = pinmob_cli("analyze", str(path))
    assert done.returncode == 0, done.stderr
    assert done.stderr.count("not read: <constraint> 'extra'") == 1
    dof = next(line for line in done.stdout.splitlines() if "mechanism DoF" in line)
    assert "mechanism DoF 1" in dof and "ignoring what pinmob does not read: <constraint> 'extra'" in dof
    doc = json.loads(pinmob_cli("analyze", str(path), "--json").stdout)
    assert doc["ignored"] == ["<constraint> 'extra'"] and doc["mechanism_dof"] == 1
    assert "ignoring what pinmob does not read" in pinmob_cli("analyze", str(path), "--brief").stdout


def test_an_inactive_mjcf_equality_is_named_in_the_dof_line(tmp_path):
    text = (
        (DATA / "fourbar_connect.xml")
        .read_text()
        .replace(
            "</equality>",
            '<connect name="off" body1="crank" body2="rocker" anchor="0 0.1 0" active="false"/></equality>',
        )
    )
    path = tmp_path / "inactive.xml"
    path.write_text(text)
    with pytest.warns(UserWarning, match="inactive"):
        mech = pinmob.load(path)
    assert mech.ignored == ("inactive equality 'off'",)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        report = pinmob.analyze(mech)
    assert "ignoring what pinmob does not read: inactive equality 'off'" in str(report)
    assert report.to_dict()["ignored"] == ["inactive equality 'off'"]


def test_a_file_with_nothing_ignored_says_nothing(tmp_path):
    doc = json.loads(pinmob_cli("analyze", str(DATA / "fourbar_connect.xml"), "--json").stdout)
    assert doc["ignored"] == []
    assert "ignoring" not in pinmob_cli("analyze", str(DATA / "fourbar_connect.xml")).stdout


def test_an_extended_urdf_names_the_urdf_loops_its_sidecar_does_not_give(tmp_path):
    """An Extended URDF reads its loops from the YAML sidecar: the URDF's <constraint> and <gazebo> loop joint are
    named as not read (the four-bar's closure comes from the sidecar's 3d pair: DoF 1 by hand, as above)."""
    urdf = URDF.replace('<link name="rocker"/>', '<link name="rocker"/><link name="a"/><link name="b"/>').replace(
        "</robot>",
        '<joint name="fa" type="fixed"><parent link="coupler"/><child link="a"/><origin xyz="0.3 0 0"/></joint>'
        '<joint name="fb" type="fixed"><parent link="rocker"/><child link="b"/><origin xyz="0 0.1 0"/></joint></robot>',
    )
    (tmp_path / "robot.urdf").write_text(urdf)
    (tmp_path / "robot.yaml").write_text("closed_loop: [['a', 'b']]\ntype: ['3d']\nname_mot: ['crank']\n")
    with pytest.warns(UserWarning, match="not read \\(the YAML sidecar gives the loops\\)"):
        mech = pinmob.load(tmp_path / "robot.yaml")
    assert mech.ignored == ("<constraint> 'extra'", "<gazebo> loop joint 'tip'")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        report = pinmob.analyze(mech)
    assert report.mechanism_mobility.mechanism_dof == 1
    assert report.to_dict()["ignored"] == ["<constraint> 'extra'", "<gazebo> loop joint 'tip'"]
