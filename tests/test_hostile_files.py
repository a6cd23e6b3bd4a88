"""Hostile and unlucky mechanism files: one line naming the file and the problem, exit 2, no traceback, no hang.

Issue 14, classes 8 (a small file that exhausts the machine), 9 (tracebacks instead of one line) and
10 (degenerate geometry accepted). Each file is run through the CLI in a subprocess with a time
bound; the 473-byte YAML alias bomb grew memory by 75 MB/s before, now its message is bounded.
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.model.closure import make_closure

MODELS = Path(pinmob.io.builtin_dir())
FIVE_BAR = Path(__file__).parent / "data" / "example-parallel-robots" / "5bar_linkage"
SIDECAR = "closed_loop: [['closedloop1_A', 'closedloop1_B']]\ntype: ['6d']\nname_mot: ['mot1', 'mot2']\n"


def alias_bomb() -> bytes:
    """Ten levels of nine aliases: 9^10 (3.5e9) strings when expanded, 400-odd bytes on disk."""
    text, previous = 'a: &a ["x","x","x","x","x","x","x","x","x"]\n', "a"
    for level in range(1, 10):
        name = chr(ord("a") + level)
        text += f"{name}: &{name} [{', '.join([f'*{previous}'] * 9)}]\n"
        previous = name
    return (text + f"closed_loop: *{previous}\ntype: ['6d']\n").encode()


YAML: dict[str, tuple[bytes, str]] = {
    "not UTF-8": (b"closed_loop: [['\xff\xfe', 'b']]\n", "not a UTF-8 text file"),
    "binary": (bytes(range(256)) * 4, "not a UTF-8 text file"),
    "nested lists": (b"closed_loop: " + b"[" * 5000 + b"]" * 5000 + b"\n", "nested too deeply"),
    "nested mappings": (b"closed_loop: " + b"{a: " * 5000 + b"1" + b"}" * 5000 + b"\n", "nested too deeply"),
    "5000-digit integer": (SIDECAR.encode() + b"extra: " + b"9" * 5000 + b"\n", "value cannot be read"),
    "alias bomb": (alias_bomb(), "'closed_loop' must be a list of [frame_a, frame_b] pairs"),
}


def run(*args: str, env: dict[str, str] | None = None) -> tuple[subprocess.CompletedProcess, float]:
    start = time.monotonic()
    out = subprocess.run([sys.executable, "-m", "pinmob", *args], capture_output=True, text=True, timeout=60, env=env)
    return out, time.monotonic() - start


def one_line_error(out: subprocess.CompletedProcess, *expected: str) -> None:
    assert out.returncode == 2 and "Traceback" not in out.stderr, out.stderr[-2000:]
    assert out.stderr.count("\n") == 1 and out.stderr.startswith("pinmob: error: "), out.stderr[-2000:]
    assert len(out.stderr) < 1000
    for text in expected:
        assert text in out.stderr, out.stderr


@pytest.mark.parametrize("case", YAML)
def test_hostile_yaml_sidecar(case: str, tmp_path: Path) -> None:
    content, said = YAML[case]
    (tmp_path / "robot.urdf").write_text((FIVE_BAR / "robot.urdf").read_text())
    (tmp_path / "robot.yaml").write_bytes(content)
    out, seconds = run("analyze", str(tmp_path / "robot.yaml"))
    one_line_error(out, "robot.yaml", said)
    assert seconds < 30


def test_a_folder_named_like_a_sidecar(tmp_path: Path) -> None:
    (tmp_path / "robot.yaml").mkdir()
    out, _ = run("analyze", str(tmp_path / "robot.yaml"))
    one_line_error(out, "is a folder")


def puu_toml(tmp: Path, text: str | None = None, urdf: str | None = None) -> Path:
    (tmp / "3puu.urdf").write_text(urdf if urdf is not None else (MODELS / "3puu.urdf").read_text())
    (tmp / "3puu.toml").write_text(text if text is not None else (MODELS / "3puu.toml").read_text())
    return tmp / "3puu.toml"


BIG = "1" + "0" * 400  # an integer no float holds
TOML: dict[str, tuple[Callable[[str], str], str]] = {
    "nested arrays": (lambda t: t + "\nx = " + "[" * 5000 + "]" * 5000 + "\n", "nested too deeply"),
    "nested inline tables": (lambda t: t + "\ny = " + "{a=" * 3000 + "1" + "}" * 3000 + "\n", "nested too deeply"),
    "5000-digit integer": (lambda t: t + "\nz = " + "9" * 5000 + "\n", "value cannot be read"),
    "400-digit joint value": (
        lambda t: t.replace("A_slider = 0.0, B_slider", f"A_slider = {BIG}, B_slider", 1),
        "joints.A_slider must be a finite number",
    ),
    "400-digit length scale": (lambda t: f"length_scale = {BIG}\n" + t, "length_scale must be a positive number"),
}


@pytest.mark.parametrize("case", TOML)
def test_hostile_toml(case: str, tmp_path: Path) -> None:
    change, said = TOML[case]
    path = puu_toml(tmp_path, change((MODELS / "3puu.toml").read_text()))
    out, seconds = run("analyze", str(path))
    one_line_error(out, "3puu.toml", said)
    assert seconds < 30


def test_a_file_over_the_size_bound_is_refused_naming_the_bound_and_how_to_raise_it(tmp_path: Path) -> None:
    path = puu_toml(tmp_path)
    size = path.stat().st_size
    out, _ = run("analyze", str(path), env={**os.environ, "PINMOB_MAX_FILE_BYTES": str(size - 1)})
    one_line_error(out, f"{size} bytes, over the {size - 1}-byte bound", "PINMOB_MAX_FILE_BYTES")
    urdf = path.with_suffix(".urdf")  # the URDF the TOML names is bounded too (it was read whatever its size)
    assert urdf.stat().st_size > size
    out, _ = run("analyze", str(path), env={**os.environ, "PINMOB_MAX_FILE_BYTES": str(size)})
    one_line_error(out, f"urdf file {str(urdf)!r} has {urdf.stat().st_size} bytes, over the {size}-byte bound")
    out, _ = run("analyze", str(path), env={**os.environ, "PINMOB_MAX_FILE_BYTES": str(urdf.stat().st_size)})
    assert out.returncode == 0, out.stderr


@pytest.mark.parametrize("name", ["m.toml", "m.urdf", "m.xml"])
def test_a_named_pipe_is_not_read(name: str, tmp_path: Path) -> None:
    """Opening a pipe to read it blocks until a writer comes: it is refused before that (a URDF pipe was said
    not to exist; an MJCF one hung the CLI)."""
    os.mkfifo(tmp_path / name)
    out, seconds = run("analyze", str(tmp_path / name))
    one_line_error(out, name, "not a regular file")


def with_axis(joint: str, axis: str) -> str:
    text = (MODELS / "3puu.urdf").read_text()
    start = text.index(f'<joint name="{joint}"')
    end = text.index("</joint>", start)
    head, block = text[:start], text[start:end]
    old = block[block.index("<axis") : block.index("/>", block.index("<axis")) + 2]
    return head + block.replace(old, f'<axis xyz="{axis}"/>') + text[end:]


@pytest.mark.parametrize("joint", ["A_slider", "B_u1a"])
def test_a_zero_joint_axis_is_refused_naming_the_joint(joint: str, tmp_path: Path) -> None:
    """A zero prismatic axis gave 3-PUU '2 DoF 2T', a zero revolute one 'does not close, residual nan'."""
    path = puu_toml(tmp_path, urdf=with_axis(joint, "0 0 0"))
    with pytest.raises(pinmob.MechanismFileError, match=f"joint '{joint}' has a zero or non-finite axis"):
        pinmob.load(path)
    out, _ = run("analyze", str(path))
    one_line_error(out, f"joint '{joint}'")
    model = pin.buildModelFromXML(with_axis(joint, "0 0 0"))  # parsed by the caller (a sweep's design): checked too
    with pytest.raises(pinmob.MechanismFileError, match=f"joint '{joint}' has a zero or non-finite axis"):
        pinmob.io.load_toml(path, urdf_model=model)


def test_a_closure_axis_near_the_largest_float_is_a_direction() -> None:
    """[1e308, 1e308, 0] overflowed the norm: the axis came out zero and the analysis raised LinAlgError."""
    mech = pinmob.load("3-PUU")
    frames = [f.name for f in mech.model.frames if f.parentJoint != 0][:2]
    closure = make_closure(mech.model, "c", frames[0], frames[1], "revolute", axis=[1e308, 1e308, 0.0])
    assert closure.axis is not None
    assert_allclose(closure.axis, [np.sqrt(0.5), np.sqrt(0.5), 0.0], atol=1e-15)


def test_extended_urdf_parser_output_is_one_line(tmp_path: Path) -> None:
    """urdfdom printed its own diagnostics on the Extended URDF path; now they are part of the one line."""
    (tmp_path / "robot.urdf").write_text('<robot name="r"><link name="a"/><joint name="j" type="bogus"/></robot>')
    (tmp_path / "robot.yaml").write_text(SIDECAR)
    out, _ = run("analyze", str(tmp_path / "robot.yaml"))
    one_line_error(out, "robot.yaml", "does not parse")
    assert pin.__version__  # the parser is Pinocchio's own (urdfdom inside)


def chain(tmp: Path, joints: int) -> Path:
    """A serial chain of ``joints`` revolutes (one limb)."""
    links = "".join(f'<link name="l{i}"/>' for i in range(joints + 1))
    body = "".join(
        f'<joint name="j{i}" type="revolute"><parent link="l{i}"/><child link="l{i + 1}"/><origin xyz="0.01 0 0"/>'
        f'<axis xyz="0 0 1"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>'
        for i in range(joints)
    )
    (tmp / "chain.urdf").write_text(f'<robot name="c">{links}{body}</robot>')
    (tmp / "chain.toml").write_text(
        f'name = "chain"\nurdf = "chain.urdf"\ngeneric_rank = 0\n[[limbs]]\nname = "A"\ntip = "l{joints}"\n'
    )
    return tmp / "chain.toml"


def test_a_model_over_the_joint_bound_is_refused_before_pinocchio_builds_its_data(tmp_path: Path) -> None:
    """400 joints made createData take 4 GB (1000 got the process killed): the bound is 200, raised by a variable."""
    out, seconds = run("analyze", str(chain(tmp_path, 400)))
    one_line_error(out, "chain.urdf", "400 joints, over the bound of 200", "PINMOB_MAX_JOINTS")
    assert seconds < 30
    small = chain(tmp_path, 30)
    out, _ = run("analyze", str(small), env={**os.environ, "PINMOB_MAX_JOINTS": "20"})
    one_line_error(out, "30 joints, over the bound of 20")
    out, _ = run("analyze", str(small), "--json")
    assert out.returncode == 0, out.stderr


def test_an_mjcf_over_the_joint_bound_is_refused_before_pinocchio_builds_its_data(tmp_path: Path) -> None:
    """300 two-hinge chains pinned to the world (600 joints: 87 s and 20 GB before the bound held for MJCF)."""
    chains = "".join(
        f'<body name="a{i}" pos="{i} 0 0"><joint name="ja{i}"/><geom size="0.01"/>'
        f'<body name="b{i}" pos="0 1 0"><joint name="jb{i}"/><geom size="0.01"/></body></body>'
        for i in range(300)
    )
    pins = "".join(f'<connect body1="b{i}" body2="world" anchor="0 0 0"/>' for i in range(300))
    path = tmp_path / "wide.xml"
    path.write_text(f"<mujoco><worldbody>{chains}</worldbody><equality>{pins}</equality></mujoco>")
    out, _ = run("analyze", str(path))
    one_line_error(out, "wide.xml", "600 joints, over the bound of 200", "PINMOB_MAX_JOINTS")


OPTIONS = {
    "path samples": (["scan", "3-PUU", "-n", "100000000"], "100,000,000 samples", "PINMOB_MAX_SAMPLES"),
    "grid samples": (
        ["scan", "3-PUU", "--grid", "x:0:0.1:100000", "y:0:0.1:100000"],
        "10,000,000,000 samples",
        "PINMOB_MAX_SAMPLES",
    ),
    "animation steps": (["show", "3-PUU", "--steps", "100000", "--html", "out.html"], "100,000 steps", "MAX_STEPS"),
    "restarts": (["analyze", "3-PUU", "--restarts", "1000000"], "1,000,000 restarts", "PINMOB_MAX_RESTARTS"),
}


@pytest.mark.parametrize("case", OPTIONS)
def test_an_option_over_its_bound_is_refused_at_once(case: str, tmp_path: Path) -> None:
    """-n 1e8 built 678 MB of chunk descriptors first, a 1e5 x 1e5 grid ran out of memory, --steps 100000 and
    --restarts 1e6 ran for minutes: refused before any work, naming the bound and how to raise it; nothing written."""
    args, said, variable = OPTIONS[case]
    args = [str(tmp_path / a) if a == "out.html" else a for a in args]
    out, seconds = run(*args, "--csv", str(tmp_path / "s.csv")) if args[0] == "scan" else run(*args)
    one_line_error(out, said, variable)
    assert seconds < 20 and list(tmp_path.iterdir()) == []


def test_an_output_pinmob_cannot_create_is_one_line(tmp_path: Path) -> None:
    """--csv in /proc (writable to root by its mode, yet no file can be made there) gave a FileNotFoundError traceback."""
    out, _ = run("scan", "3-PUU", "-n", "3", "--no-progress", "--csv", "/proc/pinmob-test.csv")
    one_line_error(out, "/proc/pinmob-test.csv")


@pytest.mark.parametrize("where", ["mechanism", "limb", "joint"])
def test_a_name_with_a_terminal_escape_is_refused_and_shown_escaped(where: str, tmp_path: Path) -> None:
    """A name could clear the screen (ESC [2J) when printed: refused at load, the message shows it escaped."""
    toml = (MODELS / "3puu.toml").read_text()
    urdf = (MODELS / "3puu.urdf").read_text()
    if where == "mechanism":
        toml = toml.replace('name = "3-PUU"', 'name = "3-PUU\\u001b[2J"', 1)
    elif where == "limb":
        toml = toml.replace('name = "A"', 'name = "A\\u001b[2J"', 1)
    else:
        urdf = urdf.replace('name="A_u1a"', 'name="A_u1a&#27;[2J"')
    path = puu_toml(tmp_path, toml, urdf)
    out, _ = run("analyze", str(path))
    one_line_error(out, "\\x1b[2J")
    assert "\x1b" not in out.stderr + out.stdout


@pytest.mark.parametrize("amplitude", ["1e300", "21"])
def test_an_amplitude_too_large_for_its_steps_is_refused(amplitude: str, tmp_path: Path) -> None:
    """--amplitude 1e300 printed numpy's overflow warnings; 21 m in 2 steps called the 3-PUU's translations "only
    instantaneous" (each step 10.5 m, halved 4 times, never re-closed): a step over 0.5 L is refused, saying how
    many steps would do."""
    out, _ = run("show", "3-PUU", "--amplitude", amplitude, "--steps", "2", "--html", str(tmp_path / "a.html"))
    one_line_error(out, "in 2 steps makes steps of", "0.5 L for translations", "use at least")
    assert "Warning" not in out.stderr and "overflow" not in out.stderr and not (tmp_path / "a.html").exists()


def test_a_keyframe_that_is_not_finite_names_itself_and_its_joint(tmp_path: Path) -> None:
    """An MJCF keyframe with ``nan`` or ``inf`` in its qpos (MuJoCo compiles it as given): asked for, one line naming
    the configuration and the joint (it said ``does not close: residuals B: nan m``); the file's other
    configurations still analyse."""
    text = (Path(__file__).parent / "data" / "fourbar_connect.xml").read_text()
    keys = '<keyframe><key name="bad" qpos="nan 0 0"/><key name="far" qpos="0 inf 0"/></keyframe></mujoco>'
    path = tmp_path / "fourbar.xml"
    path.write_text(text.replace("</mujoco>", keys))
    for key, joint in (("bad", "crank"), ("far", "coupler")):
        out = run("analyze", str(path), "-c", key)[0]
        *warned, error = out.stderr.splitlines()  # MuJoCo's own word on the NaN, as one warning, then the error
        assert all(w.startswith("pinmob: warning: fourbar.xml: MuJoCo says:") for w in warned) and len(warned) <= 1
        out.stderr = error + "\n"
        one_line_error(out, f"configuration {key!r}", f"joint(s) {joint!r}", "not a finite number")
    assert pinmob.analyze(pinmob.load(path), "reference").mechanism_mobility.mechanism_dof == 1


FOUR_BAR_BODY = (
    '<worldbody><body name="a"><joint name="ja"/><geom size="0.01"/>'
    '<body name="b" pos="0 1 0"><joint name="jb"/><geom size="0.01"/>'
    '<body name="c" pos="1 0 0"><joint name="jc"/><geom size="0.01"/></body></body></body></worldbody>'
)
FOUR_BAR_LOOP = '<equality><connect body1="c" body2="world" anchor="0 -1 0"/></equality>'


def mjcf_with_include(tmp_path: Path, include: str) -> Path:
    (tmp_path / "model").mkdir()
    path = tmp_path / "model" / "robot.xml"
    path.write_text(f'<mujoco><include file="{include}"/>{FOUR_BAR_BODY}</mujoco>')
    return path


def test_an_mjcf_including_a_named_pipe_is_refused_not_hung(tmp_path: Path) -> None:
    """MuJoCo's parser opened the pipe and waited for a writer: the CLI hung (killed by the test's time bound)."""
    path = mjcf_with_include(tmp_path, "loop.xml")
    os.mkfifo(tmp_path / "model" / "loop.xml")
    out, _ = run("analyze", str(path))
    one_line_error(out, "robot.xml", "<include file='loop.xml'> is not a regular file")


@pytest.mark.parametrize("include", ["../outside.xml", "OUTSIDE"])
def test_an_mjcf_include_outside_the_models_folder_is_refused(include: str, tmp_path: Path) -> None:
    """What an include holds becomes the model, drawn and exported: a file outside the folder was read as part of it."""
    outside = tmp_path / "outside.xml"
    outside.write_text(f"<mujoco>{FOUR_BAR_LOOP}</mujoco>")
    path = mjcf_with_include(tmp_path, str(outside) if include == "OUTSIDE" else include)
    out, _ = run("analyze", str(path))
    one_line_error(out, "robot.xml", f"<include file={str(outside)!r}> lies outside the model's folder")


def test_nested_mjcf_includes_inside_the_folder_are_read_as_mujoco_reads_them(tmp_path: Path) -> None:
    """A four-bar whose loop comes from a nested include: 1 DoF, as MuJoCo's own constraint rows say (3 hinges, 2 rows)."""
    path = mjcf_with_include(tmp_path, "parts/mid.xml")
    (tmp_path / "model" / "parts").mkdir()
    (tmp_path / "model" / "parts" / "mid.xml").write_text('<mujoco><include file="loop.xml"/></mujoco>')
    comment = "<!-- " + "the loop closure of the four-bar " * 30 + "-->"  # the largest file of the three
    (tmp_path / "model" / "parts" / "loop.xml").write_text(f"<mujoco>{comment}{FOUR_BAR_LOOP}</mujoco>")
    import mujoco

    m = mujoco.MjModel.from_xml_path(str(path))
    m.opt.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    mujoco_dof = m.nv - np.linalg.matrix_rank(d.efc_J[: d.nefc * m.nv].reshape(d.nefc, m.nv)[: d.ne], tol=1e-9)
    report = pinmob.analyze(pinmob.load(path))
    assert report.mechanism_mobility.mechanism_dof == mujoco_dof == 1
    size = (tmp_path / "model" / "parts" / "loop.xml").stat().st_size
    out, _ = run("analyze", str(path), env={**os.environ, "PINMOB_MAX_FILE_BYTES": str(size - 1)})
    one_line_error(out, "<include file='parts/loop.xml'>", f"{size} bytes, over the {size - 1}-byte bound")
