"""The 11 Extended URDF robots of LAAS-CNRS's example-parallel-robots, read as they are.

A copy of them, unchanged (``SHA256SUMS`` lists the upstream files' digests, checked
here), lives in ``tests/data/example-parallel-robots`` with its BSD-3-Clause licence, so
the tests need nothing outside the repository (URDF + YAML, meshes not included). Every
robot must load (missing meshes: a warning), close and be analysed, with the numbers of
:data:`EXPECTED`, each counted by hand from the robot's URDF and YAML (the count is in the
comment beside it); docs/closed-chains.md shows the same table.
"""

from __future__ import annotations

import hashlib
import os
import sys
import warnings
from pathlib import Path

import pytest
import yaml

import pinmob
from pinmob import analyze_mechanism
from pinmob.assembly.relaxation import find_closed_relaxed
from pinmob.assembly.seeds import find_closed
from pinmob.cli import main
from pinmob.exceptions import ClosureError

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

#: robot -> (nv, closure rows, redundant rows, mechanism DoF, idle DoF, locked DoF, actuation valid), by hand.
#: nv: URDF revolute/prismatic joints count 1, YAML SPHERICAL 3 and UJOINT 2; rows: 6 per 6d, 3 per 3d.
#: "S" below is a sphere written as three revolutes at one point (the <name>_rev0/1/2 joints).
EXPECTED = {
    # 6 revolutes, all parallel to the base x axis (mot1 and mot2 rpy +-(pi/2, 0, pi/2) turn z into x; the
    # others only turn about z): a planar loop, whose 6d weld ranks 3 -> 3 redundant, DoF 6 - 3 = 3. The weld
    # joins the children of closedloop1_A and closedloop1_B, two revolutes that are coaxial once welded: their
    # common spin moves nothing else (idle); the five-bar's 2 DoF are the motors'. Locked: the spin only.
    "5bar_linkage": (6, 6, 3, 3, 1, 1, True),
    # the planar five-bar (mot1, free1, free2, mot2 parallel to y) plus freeortho (rpy pitch pi/2: axis normal
    # to them) carrying the ball point off its axis: the point's out-of-plane row is not zero, rank 3 -> 5 - 3 = 2.
    "5bar_linkage_iso3d": (5, 3, 0, 2, 0, 0, True),
    # the same with the ball written as three revolutes (part_4_part_6_rev0/1/2) and a weld of part_6 to
    # part_5: a ball between part_4 and part_5 (3 rows) plus 3 orientation rows taken by the sphere -> 8 - 6 = 2.
    "5bar_linkage_iso6d": (8, 6, 0, 2, 0, 0, True),
    # per leg: hips z, x, y, knee, ankle y, x (6); knee: motor R, transmission S (YAML), free_knee U (YAML),
    # 1 + 3 + 2 + knee = 7 in a 6d loop -> 1; ankle: two R-U-S rods (6 each, 6 rows each) on the 2-DoF ankle
    # -> 2. nv 2 x (6 + 6 + 12) = 48, DoF 2 x 6 = 12 = the 12 motors; a U blocks each rod's spin: no idle.
    "battobot_6d": (48, 36, 0, 12, 0, 0, True),
    # serial hip 1, hip 2, tigh, knee, free_knee, free_ankle (6) + motor_ankle + 4 S: 19. Two S-S rods (half
    # rods welded): achilles (tigh-tarsus, free_knee driven by motor_knee) and plantar (servo-foot_2,
    # free_ankle driven by motor_ankle); each rod spins idle about the line of its ball centres: 19 - 12 = 7
    # = 5 motors + 2 idle; locked, the 2 spins remain.
    "cassie_like": (19, 12, 0, 7, 2, 2, True),
    # serial hip x, y, z, knee, free_knee, foot1, foot2 (7) + 2 shin motors + 6 S: 27. Three S-S rods: hip_x-
    # tarsus (free_knee from hip z and knee), crank-foot and crank_2-foot (foot's 2 DoF from the shin motors):
    # 27 - 18 = 9 = 6 motors + 3 rod spins.
    "digit_like": (27, 18, 0, 9, 3, 3, True),
    # 12 revolutes + 5 S = 27, 27 - 18 = 9. Two S-S knee rods (loops 2, 3) spin idle. Locked, loop 1 keeps
    # one motion: free_hip_x + free_universal4 (R) + ankle_universal_2 (S) + the shin-ankle U (2) = 7 freedoms,
    # 6 rows. free_universal4's axis (universal_2's x) passes 0.30 mm from the ball centre (its origin is
    # (0.295, 0, -0.295) mm from it), so this is not a spin of universal_2 but a motion of the second leg and
    # the foot: locked 3 = 2 idle + 1, not valid.
    "disney_like": (27, 18, 0, 9, 2, 3, False),
    # 14 revolutes, all parallel (base x; the others turn only about z or flip it): planar. Each 6d closure
    # welds the children of two closedloop revolutes, coaxial once welded: a revolute between their parents
    # plus one idle spin. Planar count of the 9 links and 8 + 3 revolutes: 3 x 8 - 2 x 11 = 2 (the 2 motors);
    # 2 + 3 spins = 5; rank 14 - 5 = 9 of 18 rows: 3 redundant per planar weld.
    "robot_delta": (14, 18, 9, 5, 3, 3, True),
    # serial hip z, x, y, knee, free_ankle, motor_ankle (6) + motor_shin + 2 S: 13. One S-S rod (moteur-ankle):
    # free_ankle from motor_shin, and the rod's spin: 13 - 6 = 7 = 6 motors + 1 idle.
    "talos_like": (13, 6, 0, 7, 1, 1, True),
    # six S-P-S legs from hip_part to foot_part (one in the tree: motor_6, part_4; five closed by welds of the
    # two half legs, their frames on the legs' z axes): 6 P + 12 S (6 at the hip, 6 at the foot) = 42, 30 rows.
    # A 6-SPS platform: 6 DoF + one spin per leg about its axis (the P joint and both balls on it): 12, 6 idle.
    "wl16_like": (42, 30, 0, 12, 6, 6, True),
}

#: joints moved by the idle motions (coaxial revolute pairs; the rods' own-axis revolutes), by hand
IDLE_JOINTS = {
    "5bar_linkage": {"closedloop1_A", "closedloop1_B"},
    "robot_delta": {f"closedloop{k}_{s}" for k in (1, 2, 3) for s in "AB"},
    "cassie_like": {
        "foot_2_half_planta_rode_2_rev2",
        "servo_gauche_half_planta_rode_rev2",
        "tarsus_half_hachil_rode_rev2",
        "tigh_half_hachil_rode_2_rev2",
    },
}


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
    if robot == "kangaroo_like":
        # 57 revolutes + 6 prismatic in the URDF; 11 x 6d = 66 rows as declared (Grubler -3), but closedloop7
        # welds part_5 to part_1 through only upper_knee, 4barlink_knee and sherical_4bar (a revolute in the
        # URDF): 3 freedoms cannot bring two frames to one pose, so it cannot close as declared. The relaxed
        # model's counts depend on which loops the greedy relaxation picks (a solver outcome, not a property
        # of the files): only its size is checked here.
        relaxed_rows = 66 - 3 * len(relaxed)
        assert "closedloop7_B=closedloop7_A" in relaxed
        assert (mm.nv, mm.rows, mm.grubler) == (63, relaxed_rows, 63 - relaxed_rows)
        return
    nv, rows, redundant, dof, idle, locked, valid = EXPECTED[robot]
    assert (mm.nv, mm.rows, mm.grubler) == (nv, rows, nv - rows)
    assert (mm.redundant_constraints, mm.mechanism_dof, mm.idle_dof) == (redundant, dof, idle)
    assert (mm.actuation.locked_dof, mm.actuation.valid) == (locked, valid)
    if robot in IDLE_JOINTS:
        assert set(mm.idle_joints) == IDLE_JOINTS[robot]


def test_planar_five_bars_have_two_dof(folder):
    """The three five-bars are planar loops: 2 DoF whatever the closure; the 6d one with 6 revolutes keeps a spin idle."""
    for robot, idle in (("5bar_linkage_iso3d", 0), ("5bar_linkage_iso6d", 0), ("5bar_linkage", 1)):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            mech = pinmob.load(folder / robot / "robot.yaml")
        mm = analyze_mechanism(mech, find_closed(mech).q)
        assert mm.mechanism_dof - mm.idle_dof == 2 and mm.idle_dof == idle and mm.actuation.valid, robot


@pytest.mark.parametrize("robot", ROBOTS)
def test_robot_urdf_is_read_with_its_sidecar(folder, robot):
    """``robot.urdf`` given alone is read as the Extended URDF of the ``robot.yaml`` beside it (issue 31, item 2):
    the same loops, actuated joints and name as from the sidecar, and a description naming both files."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # missing meshes
        by_urdf, by_yaml = pinmob.load(folder / robot / "robot.urdf"), pinmob.load(folder / robot / "robot.yaml")
    assert [(c.name, c.type) for c in by_urdf.closures] == [(c.name, c.type) for c in by_yaml.closures]
    assert (by_urdf.name, by_urdf.actuated, by_urdf.model.nv) == (robot, by_yaml.actuated, by_yaml.model.nv)
    assert by_urdf.description == "Extended URDF robot.urdf + robot.yaml"
    assert by_urdf.source == folder / robot / "robot.yaml"


def test_the_cli_says_it_read_the_sidecar(folder, capsys):
    """``pinmob analyze robot.urdf`` names the sidecar it read and prints the Extended URDF's counts (the
    five-bar: nv 6, 3 DoF)."""
    assert main(["analyze", str(folder / "5bar_linkage" / "robot.urdf")]) == 0
    out, err = capsys.readouterr()
    assert "pinmob: read robot.urdf with the Extended URDF sidecar beside it, robot.yaml" in err
    assert "5bar_linkage: mechanism DoF 3 (nv 6 - closure rank 3)" in out


#: paths Python's "open" audit event saw (builtins.open, os.open, Path.read_bytes), while a test listens
_OPENED: list[str] | None = None


def _audit(event, args):
    if event == "open" and _OPENED is not None and isinstance(args[0], (str, bytes, os.PathLike)):
        _OPENED.append(os.fsdecode(args[0]))


sys.addaudithook(_audit)  # an audit hook cannot be removed: it records only while _OPENED is a list


@pytest.mark.parametrize("given", ["robot.urdf", "robot.yaml"])
def test_the_sidecar_is_read_once(tmp_path, given):
    """Loading robot.urdf (the sidecar found beside it) or robot.yaml opens robot.yaml once, as Python's own audit
    events count the opens (before: twice from robot.urdf, once to find the sidecar and once to parse it)."""
    global _OPENED
    for name in ("robot.urdf", "robot.yaml"):
        (tmp_path / name).write_bytes((FOLDER / "5bar_linkage" / name).read_bytes())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # missing meshes
        _OPENED = []
        try:
            mech = pinmob.load(tmp_path / given)
        finally:
            opened, _OPENED = _OPENED, None
    assert mech.source == tmp_path / "robot.yaml" and len(mech.closures) == 1
    assert opened.count(str(tmp_path / "robot.yaml")) == 1, opened


def test_a_yaml_without_closed_loop_is_no_sidecar(tmp_path):
    """A same-named YAML file of another tool (no ``closed_loop``) leaves the URDF a plain URDF."""
    urdf = tmp_path / "robot.urdf"
    urdf.write_bytes((FOLDER / "5bar_linkage" / "robot.urdf").read_bytes())
    (tmp_path / "robot.yaml").write_text("controller_joints: [a, b]\n")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with pytest.raises(pinmob.MechanismFileError, match="a plain URDF without a <mimic> joint"):
            pinmob.load(urdf)


def _strings(value):
    """Every string of a YAML document, keys too."""
    if isinstance(value, str):
        yield value
    elif isinstance(value, dict):
        for k, v in value.items():
            yield from _strings(k)
            yield from _strings(v)
    elif isinstance(value, list):
        for v in value:
            yield from _strings(v)


@pytest.mark.parametrize(
    "text",
    [
        'closed_loop: [["closedloop1_A\\ud800", "closedloop1_B"]]',  # a frame name
        'closed_loop: [["closedloop1_A", "closedloop1_B"]]\nname_mot: ["mot\\udfff1"]',  # an actuated joint
        'closed_loop: [["closedloop1_A", "closedloop1_B\\ud83d\\ude00"]]',  # a pair: PyYAML does not join it
    ],
)
def test_a_lone_surrogate_in_the_sidecar_is_its_error(tmp_path, capsys, text):
    """YAML's \\uD800-\\uDFFF escapes give lone surrogates (PyYAML, as yaml.safe_load shows below), which reached
    Pinocchio's name lookups as a raw UnicodeEncodeError: now one line naming the file, status 2."""
    (tmp_path / "robot.urdf").write_bytes((FOLDER / "5bar_linkage" / "robot.urdf").read_bytes())
    (tmp_path / "robot.yaml").write_text(text + "\n", encoding="ascii")
    assert any(0xD800 <= ord(c) <= 0xDFFF for word in _strings(yaml.safe_load(text)) for c in word)
    with pytest.raises(pinmob.MechanismFileError, match=r"robot.yaml: YAML text .* holds the lone surrogate"):
        pinmob.load(tmp_path / "robot.urdf")
    assert main(["analyze", str(tmp_path / "robot.yaml")]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and len(err.strip().splitlines()) == 1 and "write the character itself" in err


def test_a_lone_surrogate_in_a_key_pinmob_does_not_read_is_left(tmp_path):
    """Another tool's key of the sidecar, with a lone surrogate, is not pinmob's business: the robot loads."""
    (tmp_path / "robot.urdf").write_bytes((FOLDER / "5bar_linkage" / "robot.urdf").read_bytes())
    (tmp_path / "robot.yaml").write_bytes((FOLDER / "5bar_linkage" / "robot.yaml").read_bytes() + b'\n"x\\ud800": 1\n')
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # missing meshes
        assert len(pinmob.load(tmp_path / "robot.urdf").closures) == 1


def test_a_sidecar_that_does_not_parse_is_its_error(tmp_path):
    """A same-named YAML naming closed_loop that does not parse was meant as the sidecar: its error, one line."""
    urdf = tmp_path / "robot.urdf"
    urdf.write_bytes((FOLDER / "5bar_linkage" / "robot.urdf").read_bytes())
    (tmp_path / "robot.yaml").write_text("closed_loop: [['a', 'b']\n")
    with pytest.raises(pinmob.MechanismFileError, match="robot.yaml: YAML syntax error"):
        pinmob.load(urdf)
