"""URDF ``<mimic>`` joints are couplings ``q_j = multiplier * q_m + offset``: one closure row each.

Every expected figure is computed without pinmob: Pinocchio's model of the URDF (every joint its own coordinate)
and the coupling rows written here by hand from the file's numbers (``e_j - multiplier e_m``), whose null space's
dimension is the DoF of a mechanism whose only closures are mimics.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pinmob
from pinmob.cli import main

DATA = Path(__file__).parent / "data" / "mimic"
SCISSOR = DATA / "scissor_gripper.urdf"


def panda_urdf() -> Path:
    """example-robot-data's Franka Panda (a dependency): the right finger mimics the left."""
    import example_robot_data

    return (
        Path(example_robot_data.getModelPath("panda_description/urdf/panda.urdf")) / "panda_description/urdf/panda.urdf"
    )


def hand_rows(urdf: Path, mimics: list[tuple[str, str, float]]) -> tuple[pin.Model, np.ndarray]:
    """Pinocchio's model of ``urdf`` and one row ``e_joint - multiplier e_driver`` per ``(joint, driver, multiplier)``."""
    model = pin.buildModelFromUrdf(str(urdf))
    rows = np.zeros((len(mimics), model.nv))
    for k, (joint, driver, multiplier) in enumerate(mimics):
        rows[k, model.joints[model.getJointId(joint)].idx_v] = 1.0
        rows[k, model.joints[model.getJointId(driver)].idx_v] = -multiplier
    return model, rows


def nullity(rows: np.ndarray, nv: int) -> int:
    """``nv - rank(rows)``: the dimension of the rows' null space."""
    return nv - int(np.linalg.matrix_rank(rows))


def test_panda_fingers_are_one_coupling_row():
    """panda.urdf: nv 9 (7 arm joints, 2 finger slides), one mimic row, DoF 8 (as the hand-built row gives);
    analysed, not refused as "a plain URDF has no loop closure"."""
    model, rows = hand_rows(panda_urdf(), [("panda_finger_joint2", "panda_finger_joint1", 1.0)])
    doc = pinmob.analyze(pinmob.load(panda_urdf())).to_dict()
    assert (doc["nv"], doc["closure_rows"], doc["closure_rank"]) == (model.nv, 1, 1)
    assert doc["mechanism_dof"] == nullity(rows, model.nv) == 8
    [closure] = doc["closures"]
    assert (closure["name"], closure["type"], closure["rank"]) == ("mimic_panda_finger_joint2", "joint", 1)
    q = doc["joint_values"]
    assert q["panda_finger_joint2"] == pytest.approx(q["panda_finger_joint1"], abs=1e-12)


def test_multiplier_and_offset_hold_at_the_closed_configuration():
    """The fixture's jaw_b = -2 jaw_a + 0.1 and plunger = 0.05 jaw_a hold at the analysed configuration; nv 3,
    rank 2, DoF 1 (the hand-built rows' null space), and the one motion is the rows' null vector."""
    model, rows = hand_rows(SCISSOR, [("jaw_b_joint", "jaw_a_joint", -2.0), ("plunger_joint", "jaw_a_joint", 0.05)])
    doc = pinmob.analyze(pinmob.load(SCISSOR)).to_dict()
    q = doc["joint_values"]
    assert q["jaw_b_joint"] == pytest.approx(-2 * q["jaw_a_joint"] + 0.1, abs=1e-12)
    assert q["plunger_joint"] == pytest.approx(0.05 * q["jaw_a_joint"], abs=1e-12)
    assert (doc["nv"], doc["closure_rank"], doc["mechanism_dof"]) == (3, 2, nullity(rows, model.nv))
    [motion] = doc["actuation"]["remaining"]  # nothing actuated: the one motion remains
    v = np.array([motion[model.names[j]] for j in range(1, model.njoints)])
    np.testing.assert_allclose(rows @ v, 0, atol=1e-12)


@pytest.mark.parametrize("actuated", ["jaw_a_joint", "jaw_b_joint", "plunger_joint"])
def test_an_actuated_driver_or_mimic_holds_the_gripper(actuated):
    """An actuated driver moves its mimics; an actuated mimic holds its driver (multiplier != 0): either one
    locks the gripper's one motion, the hand-built rows with the actuated joint's row having rank nv."""
    model, rows = hand_rows(SCISSOR, [("jaw_b_joint", "jaw_a_joint", -2.0), ("plunger_joint", "jaw_a_joint", 0.05)])
    held = np.zeros((1, model.nv))
    held[0, model.joints[model.getJointId(actuated)].idx_v] = 1.0
    doc = pinmob.analyze(pinmob.load(SCISSOR), actuated=[actuated]).to_dict()
    assert doc["actuation"]["locked_dof"] == nullity(np.vstack([rows, held]), model.nv) == 0
    assert doc["actuation"]["valid"]


def test_a_mimic_is_exact_at_every_order():
    """A linear coupling: the finite analysis finds the instantaneous motion finite (one branch, 1 DoF)."""
    report = pinmob.analyze(pinmob.load(SCISSOR), finite=True)
    finite = report.to_dict()["finite"]
    assert (finite["mechanism_dof"], finite["finite_mechanism_dof"]) == (1, 1)
    assert finite["conditions_not_written"] == [] and len(finite["branches"]) == 1


def test_mimic_couplings_in_a_toml_file_and_an_extended_urdf(tmp_path):
    """The URDF a pinmob TOML file names and an Extended URDF's URDF bring their mimics: the same counts."""
    urdf = tmp_path / "gripper.urdf"
    urdf.write_text(SCISSOR.read_text())
    (tmp_path / "gripper.toml").write_text('name = "gripper"\nurdf = "gripper.urdf"\nactuated = ["jaw_b_joint"]\n')
    (tmp_path / "gripper.yaml").write_text("closed_loop: []\nname_mot: [jaw_b_joint]\n")
    for path in (tmp_path / "gripper.toml", tmp_path / "gripper.yaml"):
        doc = pinmob.analyze(pinmob.load(path)).to_dict()
        assert (doc["nv"], doc["closure_rank"], doc["mechanism_dof"]) == (3, 2, 1), path.name
        assert doc["actuation"]["locked_dof"] == 0, path.name


@pytest.mark.parametrize(
    ("mimic", "said"),
    [
        ('<mimic joint="nowhere"/>', "its driver 'nowhere' is not a moving joint"),
        ('<mimic joint="jaw_a_joint" multiplier="lots"/>', "multiplier value (lots) is not a valid float"),  # urdfdom's
        ('<mimic joint="jaw_a_joint" offset="nan"/>', "offset value (nan) is not a valid float"),
        ('<mimic joint="jaw_b_joint"/>', "joint 'jaw_b_joint' mimics itself"),
        ("<mimic/>", "no mimic joint specified"),  # urdfdom's
    ],
)
def test_a_bad_mimic_is_one_line(tmp_path, capsys, mimic, said):
    """A mimic that names no joint, a number that is none, a joint mimicking itself: one line, exit 2."""
    urdf = tmp_path / "bad.urdf"
    urdf.write_text(SCISSOR.read_text().replace('<mimic joint="jaw_a_joint" multiplier="-2" offset="0.1"/>', mimic))
    assert main(["analyze", str(urdf)]) == 2
    err = capsys.readouterr().err
    assert said in err and "Traceback" not in err and len(err.strip().splitlines()) == 1, err


def test_a_continuous_mimic_is_refused_in_one_line(tmp_path):
    """A continuous joint's coordinate is a point on a circle (Pinocchio's nq 2): not a one-coordinate coupling."""
    urdf = tmp_path / "continuous.urdf"
    urdf.write_text(
        SCISSOR.read_text().replace(
            'type="revolute">\n    <parent link="palm"/><child link="jaw_b"/>',
            'type="continuous">\n    <parent link="palm"/><child link="jaw_b"/>',
        )
    )
    with pytest.raises(pinmob.MechanismFileError, match="is not a revolute or prismatic joint"):
        pinmob.load(urdf)


def test_a_urdf_without_loop_or_mimic_is_still_refused(tmp_path):
    """No closing frame and no mimic: nothing couples the joints, the message names both."""
    urdf = tmp_path / "free.urdf"
    urdf.write_text(
        SCISSOR.read_text()
        .replace('<mimic joint="jaw_a_joint" multiplier="-2" offset="0.1"/>', "")
        .replace('<mimic joint="jaw_a_joint" multiplier="0.05"/>', "")
    )
    with pytest.raises(pinmob.MechanismFileError, match="without <mimic> joints has no loop closure"):
        pinmob.load(urdf)
