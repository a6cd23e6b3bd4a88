"""Names a report shows for MJCF and URDF files: the file's own, or labels no name of the file takes (issue 22).

The truth is MuJoCo's: its names and ids of each kind of object (``mj_id2name``, ``mj_name2id``), its
positions of bodies (``xpos``, ``xmat``) and its equality residuals (``efc_pos``) at the joint values pinmob
reports. The fixture ``tests/data/unnamed_parts.xml`` has an unnamed free joint, unnamed hinges, an unnamed
body and site, an unnamed connect, an unnamed joint equality, an unnamed keyframe, and a body and a joint
(and a site and a body) sharing names.
"""

from __future__ import annotations

import json
import re
import shutil
import warnings
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.cli import main
from pinmob.exceptions import MechanismFileError
from pinmob.model.joints import frame_id

FIXTURE = Path(__file__).parent / "data" / "unnamed_parts.xml"
KINDS = {"joint": "njnt", "body": "nbody", "site": "nsite", "equality": "neq", "key": "nkey"}


def mj_names(m, kind: str) -> list[str]:
    """MuJoCo's name of each object of ``kind`` ("" when unnamed)."""
    obj = getattr(mujoco.mjtObj, f"mjOBJ_{kind.upper()}")
    return [mujoco.mj_id2name(m, obj, i) or "" for i in range(getattr(m, KINDS[kind]))]


def mj_id(m, kind: str, name: str) -> int:
    """The MuJoCo id a shown name stands for: MuJoCo's own lookup, else ``#k`` / ``<kind>#k`` of unnamed object k."""
    i = mujoco.mj_name2id(m, getattr(mujoco.mjtObj, f"mjOBJ_{kind.upper()}"), name)
    if i >= 0:
        return i
    match = re.fullmatch(("" if kind == "joint" else kind) + r"#(\d+)", name)
    assert match, f"{kind} {name!r} is neither a name in the file nor a label"
    k = int(match.group(1))
    assert mj_names(m, kind)[k] == "", f"{name!r}: {kind} {k} has a name of its own"
    return k


def analyze_json(capsys, *args: str) -> dict:
    assert main(["analyze", *args, "--json"]) == 0
    return json.loads(capsys.readouterr().out)


def test_every_name_shown_is_the_files_or_a_label(capsys):
    """Joints, closures and the configuration are named as in the file or labelled with their MuJoCo id:
    each name stands for one object (the old names: ``joint0`` for the free joint and the joint coupling
    ``joint1`` beside hinge ``joint1``, ``connect1``, ``key0``)."""
    m = mujoco.MjModel.from_xml_path(str(FIXTURE))
    doc = analyze_json(capsys, str(FIXTURE))
    assert doc["configuration"] == "key#0" and mj_id(m, "key", doc["configuration"]) == 0
    joints = list(doc["joint_values"])
    assert sorted(mj_id(m, "joint", j) for j in joints) == list(range(m.njnt))  # one name per joint
    closures = [c["name"] for c in doc["closures"]]
    assert sorted(mj_id(m, "equality", c) for c in closures) == list(range(m.neq))
    assert list(doc["redundant_by_closure"]) == closures
    assert not set(joints) & set(closures)  # no name stands for two things in one report
    assert "#0" in joints and "equality#2" in closures  # the unnamed free joint and joint coupling
    held = doc["actuation"]["base_held"]
    assert held == ["#0"] and m.jnt_type[mj_id(m, "joint", held[0])] == mujoco.mjtJoint.mjJNT_FREE
    for motion in doc["actuation"]["remaining"]:
        assert set(motion) <= set(joints)
    text = capsys.readouterr().out if main(["analyze", str(FIXTURE)]) == 0 else ""
    assert "floating base '#0' held" in text and "per closure: equality#1: 1" in text
    assert not re.search(r"\bjoint\d|connect\d|_2\b", text)


def test_frames_are_the_files_bodies_and_sites(capsys):
    """Every frame a user can name is a body, joint or site of the file (``site:<name>`` for a site named as
    a body), a label, or a closure's frame: no ``left-elbow_2`` (the old name of body left-elbow, whose name
    went to its hinge's frame), ``follower_2``, ``connect1_a``."""
    m = mujoco.MjModel.from_xml_path(str(FIXTURE))
    assert main(["analyze", str(FIXTURE), "--frame", "nowhere"]) == 2
    listed = re.findall(r"'([^']*)'", capsys.readouterr().err.split("valid frames:")[1])
    bodies, joints, sites = mj_names(m, "body"), mj_names(m, "joint"), mj_names(m, "site")
    closures = ["pin", "equality#1"]  # equality 2 couples joints: its frames are theirs
    allowed = {n or f"body#{i}" for i, n in enumerate(bodies[1:], 1)} | {n or f"#{i}" for i, n in enumerate(joints)}
    allowed |= {(f"site:{n}" if n in bodies + joints else n) if n else f"site#{i}" for i, n in enumerate(sites)}
    allowed |= {f"{c}#{side}" for c in closures for side in "ab"} | {"universe"}
    assert set(listed) == allowed and len(listed) == len(set(listed))
    assert "site:crank" in listed and "left-elbow" in listed and "body#6" in listed


@pytest.mark.parametrize(
    ("kind", "name", "frame"),
    [
        ("body", "follower", "follower"),
        ("body", "left-elbow", "left-elbow"),
        ("body", "crank", "crank"),
        ("body", "body#6", "body#6"),
        ("site", "crank", "site:crank"),
        ("site", "site#3", "site#3"),
        ("site", "tip", "tip"),
    ],
)
def test_a_frame_is_mujocos_object_of_that_name(kind, name, frame):
    """The frame a body's (or a site's) name stands for is where MuJoCo puts that body (site) at the keyframe.

    Body ``follower`` shares its name with its hinge, which is 0.2 off the body's origin: on the old code the
    name was the hinge's frame (0.2 away) and the body was ``follower_2``.
    """
    m = mujoco.MjModel.from_xml_path(str(FIXTURE))
    d = mujoco.MjData(m)
    d.qpos[:] = m.key_qpos[0]
    mujoco.mj_forward(m, d)
    i = mj_id(m, kind, name)
    pos, rot = (d.xpos[i], d.xmat[i]) if kind == "body" else (d.site_xpos[i], d.site_xmat[i])
    mech = pinmob.load(FIXTURE)
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, np.array(mech.configurations["key#0"].vector))
    placement = data.oMf[frame_id(mech.model, frame)]
    assert_allclose(placement.translation, pos, atol=1e-12)
    assert_allclose(placement.rotation, rot.reshape(3, 3), atol=1e-12)


def mujoco_at(m, joint_values: dict) -> mujoco.MjData:
    """MuJoCo's data at pinmob's joint values (each name resolved by MuJoCo, ``#k`` as joint id k), mj_forward."""
    d = mujoco.MjData(m)
    d.qpos[:] = np.nan
    for name, value in joint_values.items():
        d.joint(mj_id(m, "joint", name)).qpos[:] = value
    assert np.isfinite(d.qpos).all()  # every coordinate was given
    mujoco.mj_forward(m, d)
    return d


@pytest.mark.parametrize("joints", [None, "#1=0.5", "#5=-0.3,left-elbow=0.2"])
def test_joint_values_feed_back_into_mujoco(joints, capsys):
    """pinmob's ``joint_values`` set MuJoCo's qpos by name (``#k``: joint id k): at the keyframe they are the
    keyframe's qpos, and at configurations pinmob solves (``--joints``) MuJoCo's equality residuals vanish
    and the held joints have their values. On the old code the free joint's ``joint0`` resolved to nothing."""
    m = mujoco.MjModel.from_xml_path(str(FIXTURE))
    doc = analyze_json(capsys, str(FIXTURE), *(["--joints", joints] if joints else []))
    d = mujoco_at(m, doc["joint_values"])
    rows = np.flatnonzero(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    assert rows.size == 7 and np.abs(d.efc_pos[rows]).max() < 1e-9  # pin 3, connect 3, joint coupling 1
    if joints is None:
        assert_allclose(d.qpos, m.key_qpos[0], atol=1e-12)
    else:
        for item in joints.split(","):
            name, value = item.split("=")
            assert d.qpos[m.jnt_qposadr[mj_id(m, "joint", name)]] == pytest.approx(float(value), abs=1e-12)


CLASHES = {
    # a file's name that is pinmob's label of another object: refused, naming both
    "joint #2": (
        ('<joint name="left-elbow"', '<joint name="#1"'),
        "joint 2 is named '#1', the name pinmob gives unnamed joint 1",
    ),
    "equality": (('<connect name="pin"', '<connect name="equality#1"'), "equality 0 is named 'equality#1'"),
    "closure frame": (('<site name="crank"', '<site name="pin#a"'), "equality 'pin': its frame name 'pin#a'"),
    "site": (('<site name="crank"', '<site name="site:tip"'), "site 'site:tip': its frame name 'site:tip'"),
}


@pytest.mark.parametrize("case", sorted(CLASHES))
def test_a_name_that_is_a_label_is_refused(case, tmp_path, capsys):
    (old, new), message = CLASHES[case]
    text = FIXTURE.read_text().replace(old, new)
    if case == "site":  # a body called tip: site tip is the frame site:tip, which is another site's name
        text = text.replace('<body name="follower"', '<body name="tip"')
    path = tmp_path / "model.xml"
    path.write_text(text)
    mujoco.MjModel.from_xml_path(str(path))  # MuJoCo takes it
    with pytest.raises(MechanismFileError, match=re.escape(message)):
        pinmob.load(path)
    assert main(["analyze", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err and "rename it" in err


def test_a_keyframe_called_reference_keeps_its_name(tmp_path):
    """MuJoCo's qpos0 (which closes here) is ``#reference`` beside a keyframe the file calls ``reference``."""
    text = (
        FIXTURE.read_text()
        .replace(' euler="0 0 -20"', "")
        .replace('polycoef="0.1', 'polycoef="0')
        .replace("<key ", '<key name="reference" ')
    )
    path = tmp_path / "model.xml"
    path.write_text(text)
    mech = pinmob.load(path)
    assert list(mech.configurations) == ["#reference", "reference"]
    m = mujoco.MjModel.from_xml_path(str(path))
    assert_allclose(mech.configurations["reference"].vector[7:], m.key_qpos[0, 7:], atol=1e-15)


# --------------------------------------------------------------------------- URDF


def four_bar_urdf(robot: str) -> str:
    """A parallelogram four-bar (unit links) in onshape-to-robot's convention: closing_tip_1/_2 meet at (1, 1, 0)."""
    joint = '<joint name="{n}" type="revolute"><parent link="{p}"/><child link="{c}"/><origin xyz="{o}"/>'
    joint += '<axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>'
    links = "".join(
        f'<link name="{n}"/>' for n in ("base", "crank", "coupler", "rocker", "closing_tip_1", "closing_tip_2")
    )
    return (
        f'<robot name="{robot}">{links}'
        + joint.format(n="crank", p="base", c="crank", o="0 0 0")
        + joint.format(n="coupler", p="crank", c="coupler", o="0 1 0")
        + joint.format(n="rocker", p="base", c="rocker", o="1 0 0")
        + '<joint name="t1" type="fixed"><parent link="coupler"/><child link="closing_tip_1"/>'
        '<origin xyz="1 0 0"/></joint><joint name="t2" type="fixed"><parent link="rocker"/>'
        '<child link="closing_tip_2"/><origin xyz="0 1 0"/></joint></robot>'
    )


@pytest.mark.parametrize("where", ["here", "folder"])
def test_urdf_mechanism_is_named_as_the_robot(where, tmp_path, monkeypatch, capsys):
    """``<robot name="robot">`` exported as ``robot.urdf``: the mechanism is ``robot`` in the JSON and the text,
    whichever way the path is written (the old name was the path's folder: empty for ``robot.urdf``)."""
    (tmp_path / "export").mkdir()
    (tmp_path / "export" / "robot.urdf").write_text(four_bar_urdf("robot"))
    monkeypatch.chdir(tmp_path / "export" if where == "here" else tmp_path)
    path = "robot.urdf" if where == "here" else "export/robot.urdf"
    doc = analyze_json(capsys, path)
    assert doc["mechanism"] == "robot" and doc["mechanism_dof"] == 1  # a four-bar
    assert main(["analyze", path]) == 0
    assert capsys.readouterr().out.splitlines()[1].startswith("robot: mechanism DoF 1 ")


def test_extended_urdf_is_named_after_its_folder_from_inside_it(tmp_path, monkeypatch, capsys):
    """``robot.yaml`` given from its own folder is named after that folder, as from outside (it was ``""``)."""
    shutil.copytree(Path(__file__).parent / "data" / "example-parallel-robots" / "5bar_linkage", tmp_path / "5bar")
    monkeypatch.chdir(tmp_path / "5bar")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # no meshes
        assert analyze_json(capsys, "robot.yaml")["mechanism"] == "5bar"
