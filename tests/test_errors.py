"""Bad input: clear errors naming the problem and the valid choices; the CLI prints one line, exits 2."""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

import pinmob
from pinmob.cli import main

DATA = Path(__file__).parent / "data"

MODELS = Path(pinmob.io.builtin_dir())
FIVE_BAR = Path(__file__).parent / "data" / "example-parallel-robots" / "5bar_linkage" / "robot.yaml"


def write_mechanism(tmp_path: Path, text: str) -> Path:
    (tmp_path / "3puu.urdf").write_text((MODELS / "3puu.urdf").read_text())
    path = tmp_path / "mech.toml"
    path.write_text(text)
    return path


GOOD = """
name = "copy"
urdf = "3puu.urdf"
[[limbs]]
name = "A"
tip = "A_tip"
[[limbs]]
name = "B"
tip = "B_tip"
[configurations.home]
joints = { A_slider = 0.0 }
"""


def test_missing_file() -> None:
    with pytest.raises(pinmob.MechanismFileError, match="neither a built-in model nor an existing file.*3-PUU"):
        pinmob.load("no/such/robot.toml")


def test_toml_syntax_error(tmp_path: Path) -> None:
    path = write_mechanism(tmp_path, 'name = "x"\nurdf = \n')
    with pytest.raises(pinmob.MechanismFileError, match="mech.toml: TOML syntax error"):
        pinmob.load(path)


def test_unknown_top_level_key_is_named(tmp_path: Path) -> None:
    """The key goes first: after a [table] header a TOML key belongs to that table, not the top level."""
    path = write_mechanism(tmp_path, "colour = 'red'\n" + GOOD)
    with pytest.raises(
        pinmob.MechanismFileError, match=r"mech.toml: unknown key\(s\) 'colour' in the top level; valid"
    ):
        pinmob.load(path)


def test_unknown_key_in_a_table_is_named(tmp_path: Path) -> None:
    path = write_mechanism(tmp_path, GOOD + "colour = 'red'\n")  # lands in [configurations.home]
    with pytest.raises(pinmob.MechanismFileError, match=r"'colour' in configurations.home; valid keys: 'approach'"):
        pinmob.load(path)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda t: "description = 5\n" + t, "description must be a string, got integer 5"),
        (lambda t: "length_scale = '0.3'\n" + t, 'length_scale must be a number, got string "0.3"'),
        (lambda t: "generic_rank = 3.0\n" + t, "generic_rank must be an integer, got float 3.0"),
        (lambda t: "limbs = [1]\n" + t.split("[[limbs]]")[0], r"limbs\[0\] must be a table, got integer 1"),
        (lambda t: t.replace('tip = "A_tip"', "tip = 7"), r"limbs\[0\].tip must be a string, got integer 7"),
        (
            lambda t: t.replace('tip = "A_tip"', 'tip = "A_tip"\nactuated = "A_slider"'),
            r"limbs\[0\].actuated must be an array of strings",
        ),
        (
            lambda t: t + 'expected = { dof = true, motion_type = "3T" }\n',
            "configurations.home.expected.dof must be an integer, got boolean true",
        ),
        (
            lambda t: t + "expected = { dof = 3, motion_type = 3 }\n",
            "configurations.home.expected.motion_type must be a string",
        ),
        (
            lambda t: t.replace("joints = { A_slider = 0.0 }", "joints = [0.0]"),
            "configurations.home.joints must be a table, got array",
        ),
        (
            lambda t: t.replace("A_slider = 0.0", "A_slider = '0.1'"),
            "configurations.home.joints.A_slider must be a finite number .* got string",
        ),
        (
            lambda t: t.replace("A_slider = 0.0", "A_slider = true"),
            "configurations.home.joints.A_slider must be a finite number .* got boolean",
        ),
        (
            lambda t: t.replace("joints = { A_slider = 0.0 }", "pose = { xyz = ['a', 0, 0] }"),
            r"configurations.home.pose.xyz must be an array of numbers",
        ),
        (
            lambda t: t.replace("[configurations.home]", "[configurations]\nhome = 1\n[configurations.other]"),
            "configurations.home must be a table, got integer 1",
        ),
    ],
)
def test_wrong_types_name_the_key_and_the_file(tmp_path: Path, edit: Callable[[str], str], message: str) -> None:
    path = write_mechanism(tmp_path, edit(GOOD))
    with pytest.raises(pinmob.MechanismFileError, match="mech.toml: " + message):
        pinmob.load(path)


@pytest.mark.parametrize(
    "value",
    [
        r'"caf\u00E9 \"q\" back\\slash tab\t del\u007F nul\u0000"',  # DEL: JSON left it raw, not TOML
        r'{ "\u00E9" = 1, "two words" = "x", "a.b" = [true, 1.5], ok = { "\u00E9" = "\u007F" } }',  # keys
        "1979-05-27T07:32:00.5Z",
        "1979-05-27T07:32:00",
        "1979-05-27",
        "07:32:00",
        "[nan, inf, -inf, -0.0, 1e300]",
    ],
)
def test_a_wrong_value_is_shown_as_toml_that_reads_back(tmp_path: Path, value: str) -> None:
    """The value a message quotes is TOML: tomllib reads it back as it read the file's (the file is ASCII, its
    text escaped, so the truth does not depend on pinmob's writer). Before: JSON strings (a raw DEL, which TOML
    refuses in a string) and bare keys (é, two words, a.b: not TOML); dates and times were TOML already."""
    name = {True: "generic_rank", False: "description"}[value.startswith('"')]  # a string is wrong for an integer
    path = write_mechanism(tmp_path, f"{name} = {value}\n" + GOOD)
    given = tomllib.loads(f"v = {value}")["v"]
    with pytest.raises(pinmob.MechanismFileError, match=f"{name} must be") as info:
        pinmob.load(path)
    shown = str(info.value).split(", got ", 1)[1].split(" ", 1)[1]  # "<TOML type> <value>"
    read = tomllib.loads(f"v = {shown}")["v"]
    assert read == given or (repr(read) == repr(given))  # nan: equal as written


@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_non_finite_numbers_in_the_file(tmp_path: Path, value: str) -> None:
    """TOML has nan and inf literals; a joint value, a pose and length_scale must be finite."""
    for text, key in [
        (GOOD.replace("A_slider = 0.0", f"A_slider = {value}"), "configurations.home.joints.A_slider"),
        (
            GOOD.replace("joints = { A_slider = 0.0 }", f"pose = {{ xyz = [0.0, {value}, 0.0] }}"),
            "configurations.home.pose.xyz",
        ),
        (f"length_scale = {value}\n" + GOOD, "length_scale"),
    ]:
        path = write_mechanism(tmp_path, text)
        with pytest.raises(pinmob.MechanismFileError, match=f"mech.toml: {key} must be .*{value.lstrip('-')}"):
            pinmob.load(path)


@pytest.mark.parametrize("value", ["1e300", "1e-300", "1e-4", "100.0"])
def test_length_scale_where_round_off_decides_is_refused(tmp_path: Path, value: str) -> None:
    """length_scale = 1e300 gave 'rigid' (issue 14): a declared L must lie within 1/100..100 times the geometry's own.

    The range is stated in metres: 1/100 and 100 times the L computed without the declaration.
    """
    path = write_mechanism(tmp_path, f"length_scale = {value}\n" + GOOD)
    out = subprocess.run(
        [sys.executable, "-m", "pinmob", "analyze", str(path)], capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 2 and out.stderr.count("\n") == 1 and "Traceback" not in out.stderr, out.stderr
    own = pinmob.load(write_mechanism(tmp_path, GOOD)).length_scale
    assert f"length_scale {float(value):g} m is outside [{own / 100:.3g}, {own * 100:.3g}] m" in out.stderr, out.stderr


def test_length_scale_inside_the_range_is_used(tmp_path: Path) -> None:
    mech = pinmob.load(write_mechanism(tmp_path, "length_scale = 0.003\n" + GOOD))
    assert mech.length_scale == 0.003


def test_duplicate_limb_names(tmp_path: Path) -> None:
    path = write_mechanism(tmp_path, GOOD.replace('name = "B"', 'name = "A"'))
    with pytest.raises(pinmob.MechanismFileError, match=r"mech.toml: limbs\[1\].name: duplicate limb name 'A'"):
        pinmob.load(path)


def test_folder_and_binary_files(tmp_path: Path) -> None:
    (tmp_path / "dir.toml").mkdir()
    with pytest.raises(pinmob.MechanismFileError, match="dir.toml' is a folder"):
        pinmob.load(tmp_path / "dir.toml")
    path = write_mechanism(tmp_path, "")
    path.write_bytes(b'name = "caf\xe9"\n')  # Latin-1, not UTF-8
    with pytest.raises(pinmob.MechanismFileError, match="mech.toml: not a UTF-8 text file"):
        pinmob.load(path)


def test_unknown_frame_lists_frames(tmp_path: Path) -> None:
    path = write_mechanism(tmp_path, GOOD.replace('tip = "B_tip"', 'tip = "B_tpi"'))
    with pytest.raises(pinmob.FrameError, match=r"mech.toml: limbs\[1\].tip: no frame 'B_tpi'.*valid frames:.*'B_tip'"):
        pinmob.load(path)
    path = write_mechanism(tmp_path, 'platform = "plate"\n' + GOOD)
    with pytest.raises(pinmob.FrameError, match=r"mech.toml: platform: no frame 'plate'.*valid frames:.*'platform'"):
        pinmob.load(path)
    path = write_mechanism(tmp_path, GOOD.replace('tip = "A_tip"', 'tip = "A_tip"\nactuated = ["A_sldr"]'))
    with pytest.raises(pinmob.FrameError, match=r"limbs\[0\].actuated names unknown joint 'A_sldr'.*'A_slider'"):
        pinmob.load(path)


def test_unknown_joint_in_configuration(tmp_path: Path) -> None:
    path = write_mechanism(tmp_path, GOOD.replace("A_slider = 0.0", "A_sldier = 0.0"))
    with pytest.raises(pinmob.MechanismFileError, match="unknown joint 'A_sldier'.*'A_slider'"):
        pinmob.load(path)


def test_each_file_of_a_load_is_looked_at_once(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    """One ``stat`` of the URDF per load (its check) and two of the TOML (``load`` finds the file, then its check),
    an Extended URDF's YAML likewise. The old code stat'ed the TOML 4 times and the URDF 3 (exists, is_dir and the
    check, each with its own wording of a missing file)."""
    import os
    from collections import Counter

    toml = write_mechanism(tmp_path, GOOD)
    calls: Counter[str] = Counter()
    real = os.stat

    def counted(path: object, *args: object, **kwargs: object) -> os.stat_result:
        calls[os.path.basename(os.fspath(path))] += 1  # type: ignore[arg-type]
        return real(path, *args, **kwargs)  # type: ignore[arg-type]

    monkeypatch.setattr(os, "stat", counted)
    pinmob.load(toml)
    assert (calls["mech.toml"], calls["3puu.urdf"]) == (2, 1)
    calls.clear()
    pinmob.load(FIVE_BAR)
    assert (calls["robot.yaml"], calls["robot.urdf"]) == (2, 2)  # the URDF: found beside the YAML, then checked


def test_missing_urdf(tmp_path: Path) -> None:
    path = tmp_path / "mech.toml"
    path.write_text(GOOD.replace("3puu.urdf", "nothing.urdf"))
    with pytest.raises(pinmob.MechanismFileError, match="nothing.urdf.*does not exist"):
        pinmob.load(path)


def test_urdf_that_does_not_parse(tmp_path: Path) -> None:
    path = write_mechanism(tmp_path, GOOD)
    (tmp_path / "3puu.urdf").write_text("<robot name='x'><link name='a'></robot")
    with pytest.raises(pinmob.MechanismFileError, match="does not parse.*parser: .*XML_ERROR"):
        pinmob.load(path)


def test_limbs_sharing_a_joint(tmp_path: Path) -> None:
    path = write_mechanism(tmp_path, GOOD.replace('tip = "B_tip"', 'tip = "A_u2b_link"'))
    with pytest.raises(pinmob.ConfigurationError, match="share joint"):
        pinmob.load(path)


def test_configuration_that_does_not_close(puu: pinmob.Mechanism) -> None:
    q = puu.q_from_joints({"B_slider": 0.05})
    with pytest.raises(pinmob.ClosureError, match="does not close.*B: .* m") as err:
        pinmob.analyze(puu, q)
    assert err.value.residuals["B"][0] > 0.01


def test_nan_and_wrong_shape(puu: pinmob.Mechanism) -> None:
    q = puu.neutral()
    q[3] = np.nan
    with pytest.raises(pinmob.ConfigurationError, match="non-finite.*\\[3\\]"):
        pinmob.analyze(puu, q)
    with pytest.raises(pinmob.ConfigurationError, match="shape \\(14,\\).*needs shape \\(15,\\)"):
        pinmob.analyze(puu, np.zeros(14))
    with pytest.raises(pinmob.ConfigurationError, match="not finite"):
        puu.q_from_joints({"A_slider": float("nan")})


def test_unknown_configuration_lists_valid(puu: pinmob.Mechanism) -> None:
    with pytest.raises(pinmob.ConfigurationError, match="no configuration 'flat'.*'generic', 'offset'"):
        pinmob.closed_configuration(puu, "flat")


def test_cli_error_is_one_line_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["analyze", "3-PUU", "--config", "nope"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pinmob: error: ") and err.count("\n") == 1
    assert "'generic'" in err


def test_cli_points_to_the_model_that_has_the_configuration(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["analyze", "3-PUU", "--config", "flat"]) == 2
    err = capsys.readouterr().err
    assert "no configuration 'flat' in '3-PUU'" in err and "with a configuration 'flat': '3-PUU-flat'" in err
    # and why, in a few words: the sentence of 3-PUU's description that points to 3-PUU-flat
    assert "Why not in '3-PUU': Links longer than R - r, so beta = 0 cannot be assembled here" in err


def test_cli_subprocess_has_no_traceback(tmp_path: Path) -> None:
    path = write_mechanism(tmp_path, "name = [\n")
    proc = subprocess.run([sys.executable, "-m", "pinmob", "analyze", str(path)], capture_output=True, text=True)
    assert proc.returncode == 2
    assert "Traceback" not in proc.stderr
    assert proc.stderr.startswith("pinmob: error:") and "TOML syntax error" in proc.stderr
    assert (tmp_path / "mech.toml").read_text() == "name = [\n"  # nothing the user gave is changed


def test_missing_meshes_warn_but_load(tmp_path: Path) -> None:
    urdf = (
        (MODELS / "3puu.urdf")
        .read_text()
        .replace(
            '<link name="base"/>',
            '<link name="base"><visual><geometry><mesh filename="package://nowhere/base.stl"/></geometry></visual></link>',
        )
    )
    path = write_mechanism(tmp_path, GOOD)
    (tmp_path / "3puu.urdf").write_text(urdf)
    with pytest.warns(UserWarning, match="geometry not loaded"):
        mech = pinmob.load(path)
    assert len(mech.limbs) == 2


def test_pose_out_of_reach_is_a_closure_error_with_residuals(tmp_path: Path) -> None:
    """A platform pose no limb A can reach, so the solver must fail and say by how much.

    The platform frame is limb A's tip (the file names no platform). Limb A's vertex is at most
    0.25 m (the link) horizontally from its guide, the vertical line through (0.3, 0), and the tip at
    most r = 0.15 m from the vertex whatever the rotation: within 0.40 m of the guide. The target
    (1.0, 0, -0.2) is 0.70 m from it, so the platform ends >= 0.30 m from the target; the linear part
    of log6 is at least that long (p = V(w) v with ||V|| <= 1).
    """
    text = GOOD.replace("joints = { A_slider = 0.0 }", "pose = { xyz = [1.0, 0.0, -0.2], rpy = [0.0, 0.0, 0.0] }")
    mech = pinmob.load(write_mechanism(tmp_path, text))
    with pytest.raises(pinmob.ClosureError, match="could not assemble 'copy' at platform pose") as err:
        pinmob.closed_configuration(mech, "home")
    res = err.value.residuals
    assert set(res) == {"A", "B", "pose"}
    assert all(len(r) == 2 and np.isfinite(r).all() for r in res.values())
    assert res["pose"][0] >= 0.30 - 1e-9


@pytest.mark.parametrize("rtol", [0, -1e-6, 1.0, 2.0, float("nan"), float("inf"), True, "1e-6", 1e-16, 1e-300, 9e-11])
def test_rtol_is_checked_everywhere(puu: pinmob.Mechanism, rtol: object) -> None:
    """rtol = 0 used to raise numpy's ValueError, nan gave 'rigid' and -1 gave '3H': now one clear error.

    Below 1e-10 round-off decides (issue 14: 1e-16 turned 3-PUU-flat into 1H, 1e-300 gave pitches of 1e16 m/rad).
    """
    q = pinmob.closed_configuration(puu, "generic")
    for call in (pinmob.analyze, pinmob.paper_view, pinmob.closure_jacobian_twists):
        with pytest.raises(pinmob.ConfigurationError, match=r"rtol must be .*number in \[1e-10, 1\)"):
            call(puu, q, rtol=rtol)  # type: ignore[operator]


def test_cli_rejects_bad_rtol(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["analyze", "3-PUU", "--rtol", "nan"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pinmob: error: --rtol must be a finite number in [1e-10, 1)") and err.count("\n") == 1


def test_paper_view_and_second_method_check_closure(puu_flat: pinmob.Mechanism) -> None:
    """Both used to answer for any q; a configuration that does not close is a ClosureError, as in analyze."""
    q = puu_flat.q_from_joints({"B_slider": 0.05})
    for call in (pinmob.paper_view, pinmob.closure_jacobian_twists):
        with pytest.raises(pinmob.ClosureError, match="does not close.*B: 5.00e-02 m") as err:
            call(puu_flat, q)  # type: ignore[operator]
        assert err.value.residuals["B"][0] == pytest.approx(0.05)


def test_paper_view_takes_an_array_approach(puu_flat: pinmob.Mechanism) -> None:
    """The declared approach of 'flat' as an (nv,) array gives the paper's 3T1R, like the declared one."""
    model = puu_flat.model
    dv = np.zeros(model.nv)
    for name, rate in puu_flat.configurations["flat"].approach.items():
        dv[model.joints[model.getJointId(name)].idx_v] = rate
    q = pinmob.closed_configuration(puu_flat, "flat")
    assert pinmob.paper_view(puu_flat, q, approach=dv).motion_type == "3T1R"
    with pytest.raises(pinmob.ConfigurationError, match="approach direction is zero"):
        pinmob.paper_view(puu_flat, q, approach=np.zeros(model.nv))
    with pytest.raises(pinmob.ConfigurationError, match=r"shape \(15,\), got \(3,\)"):
        pinmob.paper_view(puu_flat, q, approach=np.ones(3))
    with pytest.raises(pinmob.ConfigurationError, match="must be finite"):
        pinmob.paper_view(puu_flat, q, approach=np.full(model.nv, np.nan))


def test_closure_tol_applies_to_named_configurations(tmp_path: Path) -> None:
    """A named configuration 1e-5 m from closed: rejected at the default tolerance (1e-6 x L, L ~ 0.24 m),
    accepted when the caller loosens closure_tol, whether q is given by name or as a vector."""
    mech = pinmob.load(write_mechanism(tmp_path, GOOD.replace("A_slider = 0.0", "B_slider = 1e-5")))
    with pytest.raises(pinmob.ClosureError, match="B: 1.00e-05 m"):
        pinmob.analyze(mech, "home")
    for call in (pinmob.analyze, pinmob.paper_view):
        assert call(mech, "home", closure_tol=1e-3).configuration == "home"  # type: ignore[operator]
    assert pinmob.closure_jacobian_twists(mech, "home", closure_tol=1e-3).shape[0] == 6


def far_four_bar(tmp_path: Path, limbs: bool) -> Path:
    """tests/data/fourbar's URDF with the rocker's pivot 3 m away (its links are 0.1-0.3 m): no loop can close.
    With ``limbs``: the coupler end is limb L's tip and the rocker end the platform (the tip's weld is the only
    closure); otherwise a 6d closure B joins them and nothing names a platform."""
    urdf = (DATA / "fourbar.urdf").read_text().replace('<origin xyz="0.3 0 0"', '<origin xyz="3.0 0 0"')
    (tmp_path / "fourbar.urdf").write_text(urdf)
    joined = (
        'platform = "rocker_end"\n[[limbs]]\nname = "L"\ntip = "coupler_end"\nactuated = ["crank"]\n'
        if limbs
        else 'actuated = ["crank"]\n[[closures]]\nname = "B"\nframes = ["coupler_end", "rocker_end"]\ntype = "6d"\n'
    )
    path = tmp_path / "far.toml"
    path.write_text(f'name = "far"\nurdf = "fourbar.urdf"\n{joined}')
    return path


@pytest.mark.parametrize("relax", [False, True])
def test_an_unclosable_limb_is_named_and_relaxing_is_not_offered(tmp_path: Path, capsys, relax: bool) -> None:
    """The limbs' tip welds define the platform: relaxing cannot help, and the message says why and names the
    limb (it said "every closure is a point or joint coupling already", and --relax "0 random restarts")."""
    assert main(["analyze", str(far_four_bar(tmp_path, limbs=True))] + ["--relax"] * relax) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "nor 20 random restarts" in err
    assert "Relaxing cannot help: the limbs' tips (L) are welded to the platform by definition" in err
    assert err.rstrip().endswith(", at L") and "0 random restarts" not in err.replace("20 random", "")


def test_relaxing_that_cannot_close_says_what_it_relaxed(tmp_path: Path, capsys) -> None:
    path = str(far_four_bar(tmp_path, limbs=False))
    assert main(["analyze", path]) == 2
    assert "Rerun with --relax (Python: relax=True)" in capsys.readouterr().err
    assert main(["analyze", path, "--relax"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "could not be closed even with closures B relaxed to 3d" in err
    assert "nor 20 random restarts; best attempt's residuals B: 2." in err and "0 random restarts" not in err.replace(
        "20 random", ""
    )


def test_a_frame_name_no_model_can_hold_is_no_frame(capsys: pytest.CaptureFixture[str]) -> None:
    """A frame name with a lone surrogate (how Python reads the command-line byte 0xff, os.fsdecode below) names no
    frame: the FrameError of any unknown frame, with the close names (before: Pinocchio's raw UnicodeEncodeError)."""
    name = os.fsdecode(b"plat\xffform")
    with pytest.raises(UnicodeEncodeError):
        name.encode("utf-8")  # the truth: no UTF-8 name (Pinocchio's) is this one
    mech = pinmob.load("Delta")
    with pytest.raises(pinmob.FrameError, match=r"no frame 'plat\\udcffform' in model .*did you mean 'platform'"):
        pinmob.model.frame_id(mech.model, name)
    assert main(["analyze", "Delta", "--frame", name]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pinmob: error: no frame 'plat\\udcffform'") and len(err.strip().splitlines()) == 1


def test_a_joint_name_no_model_can_hold_is_no_joint(capsys: pytest.CaptureFixture[str]) -> None:
    """A joint name with a lone surrogate (how Python reads the command-line byte 0xff, os.fsdecode below) names no
    joint: every joint lookup gives the FrameError of any unknown joint, with the close names and the valid ones
    (before: Pinocchio's raw UnicodeEncodeError from existJointName or getJointId, which take UTF-8 only)."""
    name = os.fsdecode(b"A_slid\xffer")
    with pytest.raises(UnicodeEncodeError):
        name.encode("utf-8")  # the truth: no UTF-8 name (Pinocchio's) is this one
    mech = pinmob.load("3-PRRR")
    model = mech.model
    close = r"'A_slid\\udcffer'.*did you mean 'A_slider'.*; valid: 'A_r1'"
    assert not pinmob.model.has_joint(model, name) and not pinmob.model.has_joint(model, "\ud800")
    assert pinmob.model.has_joint(model, "A_slider") and not pinmob.model.has_joint(model, "universe")
    with pytest.raises(pinmob.FrameError, match="unknown joint " + close):
        pinmob.model.joint_id(model, name)
    with pytest.raises(pinmob.FrameError, match="unknown joint " + close):
        pinmob.model.q_from_values(model, {name: 0.1}, np.zeros(model.nq), "3-PRRR")
    with pytest.raises(pinmob.FrameError, match="unknown joint " + close):
        pinmob.model.joint_value(model, np.zeros(model.nq), name)
    with pytest.raises(pinmob.FrameError, match="unknown joint " + close):
        pinmob.model.one_degree_indices(model, [name], "3-PRRR")
    with pytest.raises(pinmob.FrameError, match=r"unknown joint 'A_slid\\udcffer' in 't'.*did you mean 'A_slider'"):
        pinmob.model.FixedTendon("t", (name,), (1.0,)).row(model)
    with pytest.raises(pinmob.FrameError, match=r"closure 'c': no joint 'A_slid\\udcffer'"):
        pinmob.model.make_coupling(model, "c", (name, "B_slider"), (0.0, 1.0), (0.0, 0.0))
    with pytest.raises(pinmob.FrameError, match=r"unknown joint 'A_slid\\udcffer' in '3-PRRR'"):
        pinmob.analyze(mech, joints={name: 0.1})
    for argv in (
        ["analyze", "3-PRRR", "--joints", f"{name}=0.1"],
        ["analyze", "3-PRRR", "--actuated", f"{name},B_slider,C_slider"],
        ["scan", "3-PRRR", "--from", f"{name}=0.1", "--to", f"{name}=0.2", "-n", "3"],
        ["scan", "3-PRRR", "--grid", f"{name}:0:0.1:3"],
    ):
        assert main(argv) == 2, argv
        err = capsys.readouterr().err
        assert err.startswith("pinmob: error: ") and "A_slid\\udcffer" in err, (argv, err)
        assert len(err.strip().splitlines()) == 1 and "Traceback" not in err, (argv, err)
