"""SDFormat with loops (issue 31, item 4): real files and hand counts.

- gz-physics' ``anchored_loop.sdf`` (Apache-2.0, tests/data/sdf/gz_physics): links posed in the model frame, joints
  at their child links (SDFormat 1.6). By hand: every axis is world x (each link turns about x, its joint axis is x
  in its frame); the joints sit at (y, z) = J1 (0, 0.2), J2 (-0.3, 0.6), J3 (-0.8, 0.6) and J4 = link3's origin +
  R_x(2.4981) (0, 0, 0.5) = (-1.1, 0.2): a planar four-bar (ground 1.1, links 0.5, 0.5, 0.5). joint4 closes the
  loop (link3 has a parent already): a revolute closure, 5 rows of which 2 are independent (the y and z
  translations and the rotation about x are moved, the rest are zero rows): nv 3, rank 2, DoF 1.
- gz-physics' ``closed_loop_four_bar_linkage.sdf``: a world (a ground plane without joints, left out), frames
  attached to frames, poses in degrees, a link posed relative to a joint. The base link has no joint: it floats
  (6); the four-bar's four hinges are about x: 3 + 6 = 9 rates, the closure's rank 2, DoF 7 (the base held: 1).
  The frame ``upper_left_link_lower_mount`` by hand: model at (-4.7, 1, 0) turned 180 deg about z;
  base_pole_top at (-0.175, 0, 3.91); the left mount 0.3 to -y and 0.05 down; the upper link 0.15 along x, turned
  -155 deg about x; its lower mount 0.5 along the link's z: (-0.025, -0.3 + 0.5 sin 155, 3.86 + 0.5 cos 155) in
  the model, (-4.675, 1.0887, 3.4068) in the world.
- Drake's ``four_bar.sdf`` (BSD-3-Clause, tests/data/sdf/drake) closes its loop with a bushing in C++, not in the
  file: a tree, refused in one line. Drake's ``dev/four_bar_loop.sdf`` ("aspirational" by its own comment) names
  frames as joint parents and leaves its links at the model origin: by the specification each joint sits at its
  child frame, so world_driver, driver_coupler and world_rocker are on the z axis through the origin and
  coupler_rocker at Rc (0, 2, 0): the coupler and the rocker turn together (phi_coupler = theta_rocker), the
  driver idles: nv 3, rank 1, DoF 2, with a warning naming the joints whose parent frame is elsewhere.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from test_cad_gaps import pinmob_cli

import pinmob
from pinmob.exceptions import MechanismFileError

DATA = Path(__file__).parent / "data" / "sdf"
ANCHORED = DATA / "gz_physics" / "anchored_loop.sdf"
GZ_FOUR_BAR = DATA / "gz_physics" / "closed_loop_four_bar_linkage.sdf"


def counts(path: Path) -> tuple[int, int, int, int]:
    """(nv, closure rows, closure rank, mechanism DoF) that ``pinmob analyze --json`` prints."""
    done = pinmob_cli("analyze", str(path), "--json")
    assert done.returncode == 0, done.stderr
    doc = json.loads(done.stdout)
    return doc["nv"], doc["closure_rows"], doc["closure_rank"], doc["mechanism_dof"]


def test_anchored_loop_is_a_planar_four_bar():
    assert counts(ANCHORED) == (3, 5, 2, 1)
    mech = pinmob.load(ANCHORED)
    assert [(c.name, c.type, c.rows) for c in mech.closures] == [("joint4", "revolute", 5)]
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    at = {name: data.oMf[mech.model.getFrameId(name)].translation[1:] for name in ("joint1", "joint2", "joint3")}
    at["joint4"] = data.oMf[mech.model.getFrameId("joint4#b")].translation[1:]
    hand = {"joint1": (0, 0.2), "joint2": (-0.3, 0.6), "joint3": (-0.8, 0.6), "joint4": (-1.1, 0.2)}
    for name, yz in hand.items():
        np.testing.assert_allclose(at[name], yz, atol=1e-4)  # the file's angles are given to 4-5 digits


@pytest.mark.parametrize(
    ("kind", "extra", "rows", "rank", "dof"),
    [
        ("revolute", "", 5, 2, 1),
        ("continuous", "", 5, 2, 1),
        ("ball", "", 3, 2, 1),
        ("universal", "<axis2><xyz>0 1 0</xyz></axis2>", 4, 2, 1),
        ("prismatic", "", 5, 3, 0),
        ("fixed", "", 6, 3, 0),
    ],
)
def test_each_loop_joint_type_is_a_closure_of_its_own_rows(tmp_path, kind, extra, rows, rank, dof):
    """anchored_loop with joint4 of each type. The motion is planar in (y, z) about x axes: a row is moved when it
    is a y or z translation or a rotation about x. Ball: y, z of 3 (x translation still): rank 2. Universal (x in
    the world, y in link3): 3 translations and the angle between the axes (a rotation about z): y, z: rank 2.
    Prismatic along x: y, z translations, rotation about x: rank 3 (locked). Fixed: the same 3 of 6."""
    text = ANCHORED.read_text().replace('<joint name="joint4" type="revolute">', f'<joint name="joint4" type="{kind}">')
    text = text.replace("</axis>\n      </joint>\n    </model>", f"</axis>{extra}\n      </joint>\n    </model>")
    path = tmp_path / f"loop_{kind}.sdf"
    path.write_text(text)
    assert counts(path) == (3, rows, rank, dof)


def test_gz_physics_four_bar_reads_frames_degrees_and_a_pose_relative_to_a_joint():
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no joint's parent is a frame away from it: no warning
        mech = pinmob.load(GZ_FOUR_BAR)
    assert mech.name == "four_bar_linkage"
    assert [(c.name, c.type) for c in mech.closures] == [("lower_left_joint", "revolute")]
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    mount = data.oMf[mech.model.getFrameId("upper_left_link_lower_mount")].translation
    s, c = np.sin(np.radians(155)), np.cos(np.radians(155))
    np.testing.assert_allclose(mount, [-4.7 + 0.025, 1 - (-0.3 + 0.5 * s), 3.86 + 0.5 * c], atol=1e-12)
    assert counts(GZ_FOUR_BAR) == (9, 5, 2, 7)


def test_drake_four_bar_without_a_loop_joint_is_refused_in_one_line():
    refused = pinmob_cli("analyze", str(DATA / "drake" / "four_bar.sdf"))
    assert refused.returncode == 2 and "Traceback" not in refused.stderr
    assert refused.stderr.count("\n") == 1 and "no joint closes a loop" in refused.stderr


def test_drake_four_bar_loop_is_read_by_the_specification_and_says_so():
    with pytest.warns(UserWarning, match="SDFormat places a joint at its child frame") as said:
        mech = pinmob.load(DATA / "drake" / "four_bar_loop.sdf")
    text = str(said[0].message)
    assert all(j in text for j in ("world_driver", "world_rocker", "driver_coupler", "coupler_rocker"))
    assert [(c.name, c.type) for c in mech.closures] == [("coupler_rocker", "revolute")]
    assert counts(DATA / "drake" / "four_bar_loop.sdf") == (3, 5, 1, 2)


def write(tmp_path: Path, body: str, name: str = "m.sdf") -> Path:
    path = tmp_path / name
    path.write_text(f'<sdf version="1.9"><model name="m">{body}</model></sdf>')
    return path


LOOP = (
    '<link name="a"/><link name="b"/>'
    '<joint name="ja" type="revolute"><parent>world</parent><child>a</child><axis><xyz>0 0 1</xyz></axis></joint>'
    '<joint name="jb" type="revolute"><parent>a</parent><child>b</child><axis><xyz>0 0 1</xyz></axis></joint>'
    '<joint name="jc" type="revolute"><parent>world</parent><child>b</child><axis><xyz>0 0 1</xyz></axis></joint>'
)


@pytest.mark.parametrize(
    ("body", "said"),
    [
        (LOOP + '<model name="inner"><link name="c"/></model>', "a nested <model> ('inner') is not read"),
        (LOOP + "<include><uri>model://arm</uri></include>", "an <include> ('model://arm') is not read"),
        (LOOP.replace('name="jc" type="revolute"', 'name="jc" type="screw"'), "type 'screw' is not read; valid:"),
        (
            LOOP.replace('<link name="a"/>', '<link name="a"><pose relative_to="b"/></link><frame name="x"/>').replace(
                '<link name="b"/>', '<link name="b"><pose relative_to="a"/></link>'
            ),
            "relative to each other in a cycle",
        ),
        (LOOP.replace("<parent>a</parent>", "<parent>nowhere</parent>"), "unknown frame 'nowhere'; valid:"),
        (LOOP + '<frame name="a"/>', "the name of frame 'a' is also a link"),
    ],
)
def test_what_pinmob_does_not_read_is_refused_in_one_line(tmp_path, body, said):
    refused = pinmob_cli("analyze", str(write(tmp_path, body)))
    assert refused.returncode == 2 and "Traceback" not in refused.stderr, refused.stderr
    assert refused.stderr.count("\n") == 1 and said in refused.stderr, refused.stderr


def test_a_mimic_is_named_as_ignored_once_and_in_the_dof_line(tmp_path):
    """An SDFormat 1.11 ``<mimic>`` couples two joints; pinmob does not read it: one warning, and the DoF line and
    the JSON say so (item 7)."""
    body = LOOP.replace(
        '<axis><xyz>0 0 1</xyz></axis></joint><joint name="jc"',
        '<axis><xyz>0 0 1</xyz><mimic joint="ja"><multiplier>1</multiplier></mimic></axis></joint><joint name="jc"',
    )
    path = write(tmp_path, body)
    with pytest.warns(UserWarning, match=r"not read: <mimic> of joint 'jb'"):
        mech = pinmob.load(path)
    assert mech.ignored == ("<mimic> of joint 'jb'",)
    done = pinmob_cli("analyze", str(path), "--json")
    assert json.loads(done.stdout)["ignored"] == ["<mimic> of joint 'jb'"]
    text = pinmob_cli("analyze", str(path))
    assert text.stderr.count("not read: <mimic> of joint 'jb'") == 1
    assert "ignoring what pinmob does not read: <mimic> of joint 'jb'" in text.stdout.splitlines()[1]
    with pytest.raises(MechanismFileError):
        pinmob.load(write(tmp_path, "<link name='a'/>", "empty.sdf"))


def test_anchored_loop_counts_agree_with_a_planar_computation_without_pinmob():
    """The loop's velocity equations written from the hand positions: the point J4 of link3, moved by the three
    hinges about x through J1, J2, J3, must stay still (the loop hinge allows the turn about x): K = [x (J4 - Ji)]
    in (y, z), shape (2, 3); DoF = 3 - rank K, as pinmob counts."""
    hinge = {"J1": (0.0, 0.2), "J2": (-0.3, 0.6), "J3": (-0.8, 0.6)}
    tip = np.array([-1.1, 0.2])
    k = np.column_stack([[-(tip - np.array(j))[1], (tip - np.array(j))[0]] for j in hinge.values()])  # x cross r
    rank = np.linalg.matrix_rank(k, tol=1e-9)
    nv, rows, closure_rank, dof = counts(ANCHORED)
    assert (nv - rank, rank) == (dof, closure_rank) == (1, 2)
