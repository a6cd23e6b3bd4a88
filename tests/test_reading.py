"""A report a designer can read: world axis points, the DoF relation, --brief, --version, names, help, glossary."""

from __future__ import annotations

import argparse
import importlib.metadata
import re
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from scipy.linalg import null_space

import pinmob
from pinmob.assembly.residual import compute_kinematics, stacked_error
from pinmob.cli import main
from pinmob.cli.parser import build_parser
from pinmob.exceptions import ConfigurationError
from pinmob.name_matching import match_name

GLOSSARY = Path(__file__).resolve().parent.parent / "docs" / "glossary.md"
FIVEBAR = Path(__file__).resolve().parent / "data" / "fivebar" / "robot.yaml"
NUMBERS = r"\[([^\]]*)\]"


def run(capsys: pytest.CaptureFixture[str], *args: str) -> str:
    assert main(list(args)) == 0
    return capsys.readouterr().out


def world_points(text: str) -> dict[str, tuple[np.ndarray, np.ndarray]]:
    """Label -> (direction, world point) of every 'axis through [..] m (world)' motion line of a report."""
    out = {}
    pattern = rf"^  (\S+ \S+)\s+\w+\s+direction {NUMBERS}, axis through {NUMBERS} m \(world\)"
    for label, d, p in re.findall(pattern, text, re.M):
        out[label] = (np.array(d.split(","), float), np.array(p.split(","), float))
    return out


def test_spherical_axes_are_printed_through_the_world_centre(capsys):
    # every revolute axis of the built-in 3-RRR-spherical passes through the world origin O (its description),
    # so the three rotation axes the report prints must pass through O, in world coordinates
    text = run(capsys, "analyze", "3-RRR-spherical", "--config", "generic")
    axes = world_points(text.split("constraint rank")[0])
    assert set(axes) == {"R1 x", "R2 y", "R3 z"}
    for d, p in axes.values():
        assert np.linalg.norm(np.cross(p, d)) < 1e-6  # the line p + t d [m] holds O
    assert "the 3 rotation axes meet at [ 0,  0,  0] m (world)" in text
    assert "axis points in world coordinates" in text


def test_world_points_in_json_are_the_platform_origin_plus_the_relative_points(capsys):
    import json

    doc = json.loads(run(capsys, "analyze", "3-PUU", "--config", "offset", "--json"))
    mech = pinmob.load("3-PUU")
    q = pinmob.closed_configuration(mech, "offset")
    data = mech.model.createData()
    compute_kinematics(mech.model, data, q)
    origin = data.oMf[mech.model.getFrameId("platform")].translation
    for c in doc["constraints"] + doc["motions"]:
        if c["point"] is None:
            assert c["world_point"] is None
        else:
            np.testing.assert_allclose(c["world_point"], origin + np.array(c["point"]), atol=1e-12)


def internal_motions(mech: pinmob.Mechanism, q: np.ndarray) -> tuple[int, int]:
    """(mechanism DoF, joint motions with the platform still), from the closure residuals' Jacobian and Pinocchio."""
    model, data = mech.model, mech.model.createData()
    compute_kinematics(model, data, q)
    _, k = stacked_error(mech, model, data, mech.all_closures)
    jp = pin.getFrameJacobian(model, data, mech.platform_id, pin.LOCAL_WORLD_ALIGNED)
    scale = np.r_[np.full(3, 1 / mech.length_scale), np.ones(3)][:, None]
    chain = null_space(k, rcond=1e-9)
    still = null_space(np.vstack([k, scale * jp]), rcond=1e-9)
    return chain.shape[1], still.shape[1]


@pytest.mark.parametrize(("name", "config", "platform_dof"), [("3-PUU-flat", "flat", 2), ("Delta", "generic", 3)])
def test_the_report_relates_mechanism_dof_platform_dof_and_internal_motions(capsys, name, config, platform_dof):
    mech = pinmob.load(name)
    mechanism_dof, internal = internal_motions(mech, pinmob.closed_configuration(mech, config))
    assert mechanism_dof == platform_dof + internal and internal > 0
    text = run(capsys, "analyze", name, "--config", config)
    assert f"mechanism DoF {mechanism_dof} " in text
    assert f"  = {platform_dof} DoF of frame 'platform' + {internal} internal motion(s)" in text
    assert pinmob.analyze(mech, config).mechanism_mobility.internal_dof == internal


def test_no_relation_line_when_there_is_no_internal_motion(capsys):
    text = run(capsys, "analyze", "3-PUU", "--config", "generic")
    assert "internal motion" not in text


def test_brief_is_one_line_with_the_answer(capsys):
    out = run(capsys, "analyze", "3-PUU-flat", "--config", "flat", "--brief")
    assert out.count("\n") == 1
    report = pinmob.analyze(pinmob.load("3-PUU-flat"), "flat")
    assert out.strip() == report.brief()
    assert out.startswith("3-PUU-flat at 'flat': 2 DoF, 1T1R (T1 z translation along [0, 0, 1]; R1 z rotation about")
    assert "through [0, 0, 0] m" in out and out.strip().endswith("singularity: actuation+limb")


def test_brief_with_finite_ends_with_the_finite_verdict(capsys):
    # 3-PUU-flat at beta = 0: the rotation about z is first-order only (blocked at order 2), the z translation
    # is real: 1T at finite amplitude, where the instantaneous answer (and the seed paper) says 1T1R
    out = run(capsys, "analyze", "3-PUU-flat", "--config", "flat", "--brief", "--finite")
    assert out.count("\n") == 1
    assert out.strip().endswith("singularity: actuation+limb; finite: platform 1 DoF finite, 1T")
    full = run(capsys, "analyze", "3-PUU-flat", "--config", "flat", "--finite")
    assert "platform: 1 DoF finite, 1T (instantaneous: 2 DoF, 1T1R)" in full
    chain = run(capsys, "analyze", str(FIVEBAR), "--brief", "--finite")
    assert chain.strip() == "fivebar: mechanism DoF 2; finite: mechanism 2 DoF finite"
    assert "finite" not in run(capsys, "analyze", "3-PUU-flat", "--config", "flat", "--brief")


def test_brief_says_near_singular_where_the_full_text_does():
    """The Gough-Stewart turned 89.99 degrees about the vertical, next to Fichter's actuation singularity at 90:
    no class present, distance ~6e-5 (it falls linearly with the angle to 90 degrees: 6.3e-3 at 89, 6.3e-4 at
    89.9), inside the near-singular band 1e-3. The full text says so; ``--brief`` said ``singularity: none``."""
    from pinmob.assembly.assemble import assemble_pose

    mech = pinmob.load("6-UPS")
    home = pinmob.closed_configuration(mech, "home")
    near = pin.SE3(pin.rpy.rpyToMatrix(0, 0, np.radians(89.99)), np.array([0, 0, 0.4]))
    report = pinmob.analyze(mech, assemble_pose(mech, near, home))
    sing = report.singularity
    assert sing is not None and sing.classes == () and 1e-5 < sing.distance < 1e-4
    assert "; near-singular (below 1e-03))" in str(report)
    assert report.brief().endswith(
        f"; singularity: none, near-singular (below 1e-03; distance {sing.distance:.3g}, closest: actuation)"
    )
    far = pin.SE3(pin.rpy.rpyToMatrix(0, 0, np.radians(60.0)), np.array([0, 0, 0.4]))
    regular = pinmob.analyze(mech, assemble_pose(mech, far, home))
    assert "near-singular" not in str(regular) and regular.brief().endswith("; singularity: none")


def test_brief_and_json_exclude_each_other(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["analyze", "3-PUU", "--brief", "--json"])
    assert exc.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "not allowed with" in err


def test_version(capsys):
    with pytest.raises(SystemExit) as exc:
        main(["--version"])
    assert exc.value.code == 0
    assert (
        capsys.readouterr().out.strip()
        == f"pinmob {importlib.metadata.version('pinmob')}"
        == f"pinmob {pinmob.__version__}"
    )


def test_names_match_ignoring_case_where_unambiguous(capsys):
    assert pinmob.load("delta").name == "Delta"
    assert run(capsys, "analyze", "3-puu-FLAT", "-c", "FLAT", "--brief").startswith("3-PUU-flat at 'flat': 2 DoF")
    text = run(capsys, "analyze", "3-PUU", "--frame", "A_TIP")
    assert "frame 'A_tip': " in text
    assert match_name("ab", ["AB", "cd"], "thing") == "AB"
    with pytest.raises(ConfigurationError, match=r"no thing 'ab' \(did you mean 'AB' or 'Ab'\?\); valid: 'AB', 'Ab'"):
        match_name("ab", ["AB", "Ab"], "thing")


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (
            ["analyze", "delt"],
            "'delt' is neither a built-in model nor an existing file (did you mean 'Delta'?); built-in",
        ),
        (
            ["analyze", "3-PUU-flat", "-c", "flt"],
            "no configuration 'flt' in '3-PUU-flat' (did you mean 'flat'?); valid",
        ),
        (["analyze", "3-PUU", "--frame", "platfrm"], "no frame 'platfrm' in model '3-PUU' (did you mean 'platform'"),
        (
            ["analyze", "3-PUU", "--joints", "A_slidr=0.1"],
            "unknown joint 'A_slidr' in '3-PUU' (did you mean 'A_slider'",
        ),
        (
            ["analyze", "3-PUU", "--actuated", "A_slidr"],
            "joint 'A_slidr' does not exist in '3-PUU' (did you mean 'A_slider'",
        ),
        (
            ["show", "3-PUU", "--joints", "A_slidr=0.1", "--html", "x.html"],
            "joint 'A_slidr' in '3-PUU' (did you mean 'A_slider'",
        ),
    ],
)
def test_unknown_names_get_a_did_you_mean(capsys, args, message):
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err


def subparsers(parser: argparse.ArgumentParser) -> dict[str, argparse.ArgumentParser]:
    action = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return dict(action.choices)


def test_every_default_is_in_help():
    parser = build_parser()
    missing = []
    for name, sub in subparsers(parser).items():
        for action in sub._actions:
            if action.help in (None, argparse.SUPPRESS) or isinstance(action, argparse._HelpAction):
                continue
            given = action.default not in (None, False)
            documented = action.dest in ("amplitude",)  # defaults computed from the mechanism
            if (given or documented) and "default" not in action.help:
                missing.append(f"{name} {action.option_strings}")
    assert not missing, missing


def test_every_help_points_to_the_glossary():
    """To the command that prints it, which a pip user has (a docs/ path is only in pinmob's sources)."""
    parser = build_parser()
    for sub in [parser, *subparsers(parser).values()]:
        assert "'pinmob glossary'" in " ".join(sub.format_help().split())


@pytest.mark.parametrize(
    "term",
    [
        "DoF", "motion type", "pitch", "axis through", "constraint wrench", "couple", "force", "constraint rank",
        "twist rank", "generic", "serial singularity", "Type I", "Type II", "constraint singularity", "distance",
        "closest", "near-singular", "rtol", "tolerance", "**L**", "pin.LOCAL_WORLD_ALIGNED", "nv", "closure rank",
        "mechanism DoF", "internal motions", "idle motions", "Grubler-Kutzbach", "redundant", "actuation valid",
        "uncontrolled", "paper's view", "instantaneous", "edge of its workspace", "path parameter s", "refined",
    ],
)  # fmt: skip
def test_the_glossary_explains_the_report_terms(term):
    assert term in GLOSSARY.read_text(encoding="utf-8")


def test_show_matches_a_motion_label_ignoring_case(tmp_path):
    from pinmob import viewer

    scene = viewer.export_html(pinmob.load("3-PUU"), "generic", tmp_path / "p.html", motion="t2 Y", steps=1)
    assert scene.visible == "T2 y" and scene.panel["visible"] == "T2 y"
    with pytest.raises(ConfigurationError, match=r"no free motion 'T2 x' at this configuration \(did you mean"):
        viewer.export_html(pinmob.load("3-PUU"), "generic", tmp_path / "q.html", motion="T2 x", steps=1)
