"""Loaders: one mechanism in three formats, MJCF read in place, equalities matched, clear loader errors.

The three formats of each test mechanism (tests/data/formats, written by tests/data/make_models.py from
one URDF) must give the same mechanism; the counts are derived by hand in each docstring.
"""

from __future__ import annotations

import shutil
import struct
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob import analyze_mechanism
from pinmob.assembly.assemble import solve_actuated
from pinmob.cli import main
from pinmob.exceptions import PinmobError
from pinmob.screw.algebra import twist_scaling
from pinmob.screw.bases import subspace_gap

DATA = Path(__file__).resolve().parent / "data"
FORMATS = DATA / "formats"


def load(path: Path) -> pinmob.Mechanism:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # no meshes
        return pinmob.load(path)


# --------------------------------------------------------------------------- one mechanism, three formats

CASES = {
    # name: actuated values, (nv, rows, mechanism DoF, idle, redundant, Grubler), platform (DoF, type)
    "fourbar": ({"L_crank": 0.4}, (3, 3, 1, 0, 1, 0), (1, "1R")),
    "fivebar": ({"L_mot": 0.3, "R_mot": -0.2}, (4, 3, 2, 0, 1, 1), (2, "1T1R")),
    "delta": ({"A_motor": 0.2, "B_motor": 0.1, "C_motor": -0.1}, (24, 15, 9, 6, 0, 9), (3, "3T")),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_three_formats_give_one_mechanism(name):
    """TOML [[closures]], Extended URDF and MJCF <connect> of one mechanism: same counts and frame mobility.

    By hand (all closures 3d, 3 rows each):
    - four-bar: 3 revolutes, one point closure; the loop is planar so the z row is always 0: rank 2,
      DoF 3 - 2 = 1, 1 redundant row, Grubler 3 - 3 = 0; the coupler (frame ``platform``) turns about its
      instantaneous centre: 1R.
    - five-bar: 4 revolutes, rank 2: DoF 2, 1 redundant, Grubler 1; the left distal link moves in a
      2-dimensional subspace of the plane's twists (vx, vy, wz), which meets wz = 0: 1T1R.
    - delta: 3 motors + 7 balls of 3 revolutes = 24, five ball closures (15 rows, independent): DoF 9 =
      3 platform translations + 6 rod spins (idle); the platform: 3T.
    """
    values, counts, (dof, kind) = CASES[name]
    results = []
    for path in (FORMATS / name / f"{name}.toml", FORMATS / name / "robot.yaml", FORMATS / name / f"{name}.xml"):
        mech = load(path)
        assert mech.actuated == tuple(values), path.name
        sol = solve_actuated(mech, values)
        mm = analyze_mechanism(mech, sol.q, frames=["platform"])
        assert (mm.nv, mm.rows, mm.mechanism_dof, mm.idle_dof, mm.redundant_constraints, mm.grubler) == counts
        assert (mm.frames[0].dof, mm.frames[0].motion_type) == (dof, kind), path.name
        assert mm.actuation.valid, path.name
        results.append((mech, sol.q, mm.frames[0].free_twists))
    (m0, q0, t0), rest = results[0], results[1:]
    w = twist_scaling(m0.length_scale)[:, None]
    for mech, q, t in rest:
        for j in range(1, m0.model.njoints):  # same joints, same solution
            name_j = m0.model.names[j]
            assert_allclose(
                q[mech.model.joints[mech.model.getJointId(name_j)].idx_q], q0[m0.model.joints[j].idx_q], atol=1e-9
            )
        assert subspace_gap(w * t0, w * t) < 1e-7  # its floor is sqrt(eps) ~ 1.5e-8


def test_fourbar_coupler_turns_about_its_instantaneous_centre():
    """Four-bar, crank 0.4 rad: the coupler's one motion is a rotation about z through the intersection of
    the crank line O1 A and the rocker line O4 B (Kennedy's theorem), with B from the circle intersection."""
    mech = load(FORMATS / "fourbar" / "fourbar.xml")
    sol = solve_actuated(mech, {"L_crank": 0.4})
    rocker = sol.q[mech.model.joints[mech.model.getJointId("R_rocker")].idx_q]
    a = np.array([-0.1 * np.sin(0.4), 0.1 * np.cos(0.4)])
    o4 = np.array([0.3, 0.0])
    b = o4 + np.array([-0.2 * np.sin(rocker), 0.2 * np.cos(rocker)])
    assert_allclose(np.linalg.norm(b - a), np.hypot(0.3, 0.1), atol=1e-9)  # B closes the loop
    s = np.linalg.solve(np.column_stack([a, o4 - b]), o4)  # s0 a = o4 + s1 (b - o4)
    centre = s[0] * a
    (motion,) = analyze_mechanism(mech, sol.q, frames=["platform"]).frames[0].motions
    assert motion.kind.value == "R"
    assert_allclose(np.abs(motion.direction), [0, 0, 1], atol=1e-9)
    assert_allclose(b + motion.point[:2], centre, atol=1e-9)  # the point is given from the frame's origin (B)


# --------------------------------------------------------------------------- MJCF


def test_mjcf_connect_anchor_is_in_body1_frame():
    """formats/fourbar/fourbar.xml joins the bodies L_tip and R_tip (no joint: merged into their parents,
    at B = (0.3, 0.2, 0) at the reference configuration) with anchor 0: the closure frames are at B."""
    mech = load(FORMATS / "fourbar" / "fourbar.xml")
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, mech.neutral())
    (c,) = mech.closures
    assert_allclose(data.oMf[c.frame_a_id].translation, [0.3, 0.2, 0], atol=1e-12)
    assert_allclose(data.oMf[c.frame_b_id].translation, [0.3, 0.2, 0], atol=1e-12)


def binary_stl() -> bytes:
    """A binary STL (the only kind MuJoCo reads): a tetrahedron of 1 cm (MuJoCo wants 4 vertices at least)."""
    o, x, y, z = (0, 0, 0), (0.01, 0, 0), (0, 0.01, 0), (0, 0, 0.01)
    faces = [(o, y, x), (o, x, z), (o, z, y), (x, y, z)]
    return (
        b"\0" * 80 + struct.pack("<I", 4) + b"".join(struct.pack("<12fH", 0, 0, 0, *a, *b, *c, 0) for a, b, c in faces)
    )


def test_mjcf_includes_and_relative_meshdir(tmp_path):
    """A four-bar whose rocker body and equality sit in included files, with meshes under meshdir="meshes".

    MuJoCo's compiler expands them (relative to the main file) and finds the meshes: one closure (the connect), the mesh loaded from <folder>/meshes, DoF 1 (as the four-bar above),
    and the user's folder left as it was.
    """
    (tmp_path / "sub").mkdir()
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "t.stl").write_bytes(binary_stl())
    (tmp_path / "sub" / "rocker.xml").write_text(
        '<mujoco><body name="rocker" pos="0.3 0 0"><joint name="rocker" type="hinge" axis="0 0 1"/>'
        '<geom type="sphere" size="0.01"/></body></mujoco>'
    )
    (tmp_path / "sub" / "eq.xml").write_text(
        '<mujoco><equality><connect name="B" body1="coupler" body2="rocker" anchor="0.3 0.1 0"/></equality></mujoco>'
    )
    (tmp_path / "main.xml").write_text(
        '<mujoco model="included"><compiler meshdir="meshes"/><asset><mesh name="t" file="t.stl"/></asset>'
        '<worldbody><body name="crank"><joint name="crank" type="hinge" axis="0 0 1"/><geom type="mesh" mesh="t"/>'
        '<body name="coupler" pos="0 0.1 0"><joint name="coupler" type="hinge" axis="0 0 1"/></body></body>'
        '<include file="sub/rocker.xml"/></worldbody><include file="sub/eq.xml"/>'
        '<actuator><motor joint="crank"/></actuator></mujoco>'
    )
    before = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*"))
    mech = load(tmp_path / "main.xml")
    assert [c.name for c in mech.closures] == ["B"] and mech.actuated == ("crank",)
    assert mech.visual_model is not None
    assert str(tmp_path / "meshes" / "t.stl") in [g.meshPath for g in mech.visual_model.geometryObjects]
    assert analyze_mechanism(mech, solve_actuated(mech, {"crank": 0.4}).q).mechanism_dof == 1
    assert sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*")) == before


# --------------------------------------------------------------------------- loader errors

URDF = FORMATS / "fivebar" / "robot.urdf"
MJCF = (FORMATS / "fourbar" / "fourbar.xml").read_text()
ERRORS = {
    "yaml syntax": ("robot.yaml", "closed_loop: [['L_tip', 'R_tip']\n", "YAML syntax error"),
    "no closed_loop": ("robot.yaml", "name_mot: ['L_mot']\n", "no 'closed_loop' key"),
    "type length": (
        "robot.yaml",
        "closed_loop: [['L_tip', 'R_tip']]\ntype: ['3d', '6d']\n",
        "'type' must list one of '6d', '3d' per closed loop (1)",
    ),
    "joint_type": (
        "robot.yaml",
        "closed_loop: [['L_tip', 'R_tip']]\ntype: ['3d']\njoint_name: ['L_elbow']\njoint_type: ['BALL']\n",
        "joint_type 'BALL' of 'L_elbow' is not supported; valid: 'CARDAN', 'FIXED', 'SPHERICAL'",
    ),
    "unknown frame": ("robot.yaml", "closed_loop: [['L_tip', 'nowhere']]\n", "no frame 'nowhere'"),
    "xml syntax": ("model.xml", "<mujoco><worldbody>\n", "MuJoCo cannot compile it: XML parse error"),
    "equality kind": (
        "model.xml",
        MJCF.replace("</equality>", '  <flex flex="f"/>\n  </equality>').replace(
            "</worldbody>",
            '<body name="fa"><freejoint/><geom size="0.01"/></body><body name="fb" pos="1 0 0"><freejoint/>'
            '<geom size="0.01"/></body></worldbody><deformable><flex name="f" dim="1" body="fa fb" '
            'vertex="0 0 0 0 0 0" element="0 1"/></deformable>',
        ),
        "<equality> kind(s) <flex> are not loop closures pinmob reads; valid: <connect>, <weld>, <joint>, <tendon>",
    ),
    "missing include": (
        "model.xml",
        MJCF.replace("<equality>", '<include file="nope.xml"/>\n  <equality>'),
        "MuJoCo cannot compile it",
    ),
}


@pytest.mark.parametrize("case", sorted(ERRORS))
def test_loader_errors_name_the_file_and_the_problem(case, tmp_path, capsys):
    """Each bad file is a PinmobError naming the file and the problem (listing valid choices where there
    are some); the CLI prints it on one line and exits 2."""
    name, text, message = ERRORS[case]
    shutil.copy(URDF, tmp_path / "robot.urdf")
    path = tmp_path / name
    path.write_text(text)
    with pytest.raises(PinmobError) as err:
        load(path)
    assert str(path) in str(err.value) and message in str(err.value)
    if case == "unknown frame":
        assert "'R_tip'" in str(err.value)  # the valid frames are listed
    assert main(["analyze", str(path)]) == 2
    out = capsys.readouterr().err
    lines = [line for line in out.splitlines() if not line.startswith("pinmob: warning:")]
    assert len(lines) == 1 and lines[0].startswith("pinmob: error:") and message in lines[0], out


def test_analyze_takes_a_name_or_a_path_as_the_cli_does():
    """``pinmob.analyze("3-PUU", "generic")`` is ``pinmob.analyze(pinmob.load("3-PUU"), "generic")`` (issue 31 item 6:
    it raised AttributeError), the name in any case, and a path as a str or a Path."""
    expected = pinmob.analyze(pinmob.load("3-PUU"), "generic").to_dict()
    assert pinmob.analyze("3-PUU", "generic").to_dict() == expected
    assert pinmob.analyze("3-puu", configuration="generic", q="generic").to_dict()["mechanism"] == "3-PUU"
    urdf = Path(__file__).parent / "data" / "mimic" / "scissor_gripper.urdf"
    for given in (urdf, str(urdf)):
        assert pinmob.analyze(given).to_dict()["mechanism_dof"] == 1


def test_analyze_refuses_what_is_no_mechanism():
    """An unknown name lists the built-in models (pinmob.load's message); another type is an ArgumentError."""
    with pytest.raises(pinmob.MechanismFileError, match="neither a built-in model nor an existing file.*'3-PUU'"):
        pinmob.analyze("3-PUX")
    with pytest.raises(pinmob.ArgumentError, match="a built-in model's name or a file's path, got int"):
        pinmob.analyze(3)  # type: ignore[arg-type]


def test_a_folder_name_that_is_not_utf8_is_named_as_the_problem(tmp_path: Path) -> None:
    """A mechanism in a folder whose name holds a byte of another encoding (0xff: what Latin-1 writes for y with
    diaeresis) is refused because of its path, which Pinocchio cannot open, not as a URDF that "does not parse";
    the command line says so in one line and exits 2."""
    import os

    folder = tmp_path / os.fsdecode(b"bad\xffdir")
    models = Path(pinmob.io.builtin_dir())
    shutil.copytree(models, folder, ignore=shutil.ignore_patterns("*.py", "README.md"))
    with pytest.raises(PinmobError, match="not UTF-8") as err:
        pinmob.load(folder / "3puu.toml")
    assert "does not parse" not in str(err.value)
    import subprocess
    import sys

    run = subprocess.run([sys.executable, "-m", "pinmob", "analyze", os.fsencode(folder / "3puu.toml")],
                         capture_output=True, text=True, errors="backslashreplace")  # fmt: skip
    assert run.returncode == 2 and "not UTF-8" in run.stderr and "Traceback" not in run.stderr
    assert len(run.stderr.strip().splitlines()) == 1
