"""Bad input: clear errors naming the problem and the valid choices; the CLI prints one line, exits 2."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import pinmob
from pinmob.cli import main

MODELS = Path(pinmob.mechanism_file.builtin_dir())


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


def test_unknown_key_is_named(tmp_path: Path) -> None:
    path = write_mechanism(tmp_path, GOOD + "colour = 'red'\n")
    with pytest.raises(pinmob.MechanismFileError, match="unknown key.*'colour'.*valid keys"):
        pinmob.load(path)


def test_unknown_frame_lists_frames(tmp_path: Path) -> None:
    path = write_mechanism(tmp_path, GOOD.replace('tip = "B_tip"', 'tip = "B_tpi"'))
    with pytest.raises(pinmob.FrameError, match="no frame 'B_tpi'.*valid frames:.*'B_tip'"):
        pinmob.load(path)


def test_unknown_joint_in_configuration(tmp_path: Path) -> None:
    path = write_mechanism(tmp_path, GOOD.replace("A_slider = 0.0", "A_sldier = 0.0"))
    with pytest.raises(pinmob.MechanismFileError, match="unknown joint 'A_sldier'.*'A_slider'"):
        pinmob.load(path)


def test_missing_urdf(tmp_path: Path) -> None:
    path = tmp_path / "mech.toml"
    path.write_text(GOOD.replace("3puu.urdf", "nothing.urdf"))
    with pytest.raises(pinmob.MechanismFileError, match="nothing.urdf.*does not exist"):
        pinmob.load(path)


def test_urdf_that_does_not_parse(tmp_path: Path) -> None:
    path = write_mechanism(tmp_path, GOOD)
    (tmp_path / "3puu.urdf").write_text("<robot name='x'><link name='a'></robot")
    with pytest.raises(pinmob.MechanismFileError, match="does not parse"):
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
        puu.configuration("flat")


def test_cli_error_is_one_line_exit_2(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["analyze", "3-PUU", "--config", "nope"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("pinmob: error: ") and err.count("\n") == 1
    assert "'generic'" in err


def test_cli_points_to_the_model_that_has_the_configuration(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["analyze", "3-PUU", "--config", "flat"]) == 2
    err = capsys.readouterr().err
    assert "no configuration 'flat' in '3-PUU'" in err and "with a configuration 'flat': '3-PUU-flat'" in err


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
