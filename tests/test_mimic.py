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
from pinmob.io import builtin_dir

MUJOCO_NOTE = """MuJoCo (4) imports a URDF's ``<mimic>`` as an ``<equality joint>`` with ``polycoef = (offset, multiplier)``
(and leaves out, with a warning, a mimic on a fixed joint): the truth of :func:`test_counts_agree_with_mujoco`."""

DATA = Path(__file__).parent / "data" / "mimic"
SCISSOR = DATA / "scissor_gripper.urdf"


def robots() -> Path:
    """example-robot-data's ``robots`` folder (a dependency of pinmob)."""
    import example_robot_data

    return Path(example_robot_data.getModelPath("panda_description/urdf/panda.urdf"))


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
        ('<mimic joint="nowhere"/>', "its driver 'nowhere' is not a joint of the URDF"),
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
    with pytest.raises(
        pinmob.MechanismFileError, match="without a <mimic> joint between moving joints has no loop closure"
    ):
        pinmob.load(urdf)


#: URDF (under tests/data, or ``erd:`` under example-robot-data's robots) -> MuJoCo's (nv, equality rows, DoF) at
#: pinmob's analysed configuration. An Extended URDF is given by its YAML sidecar: its loops are added to MuJoCo's
#: import as site-to-site ``<connect>`` (``3d``) or ``<weld>`` (``6d``) equalities.
MUJOCO: dict[str, tuple[int, int, int]] = {
    "mimic/scissor_gripper.urdf": (3, 2, 1),
    # ROS-Industrial's Robotiq 2F-85 (C2) visualisation URDF: 6 hinges, 5 mimics of the left knuckle
    "mimic/robotiq_c2/robotiq_c2_model.urdf": (6, 5, 1),
    # ROS-Industrial's Robotiq Hand-E: two slides, one mimic
    "mimic/robotiq_hand_e/robotiq_hand_e.urdf": (2, 1, 1),
    # example-parallel-robots' Talos with closed-loop ankle actuation: 2 ankle loops (3d) and 12 gripper mimics
    "mimic/true_talos_2_legs/robot.yaml": (52, 18, 34),
    "erd:panda_description/urdf/panda.urdf": (9, 1, 8),
    "erd:panda_description/urdf/panda_collision.urdf": (9, 1, 8),
    "erd:talos_data/robots/talos_full_v2.urdf": (44, 12, 32),
    "erd:talos_data/robots/talos_full_v2_box.urdf": (44, 12, 32),
    "erd:romeo_description/urdf/romeo.urdf": (55, 22, 33),
    "erd:baxter_description/urdf/baxter.urdf": (19, 2, 17),
    "erd:pr2_description/urdf/pr2.urdf": (30, 10, 20),
    "erd:tiago_pro_description/robots/tiago_pro.urdf": (33, 10, 23),
    # every mimic on a fixed gripper joint: MuJoCo and pinmob leave them out (the URDF is then refused by pinmob:
    # nothing closes); the arm alone
    "erd:talos_data/robots/talos_reduced.urdf": (32, 0, 32),
}


def located(name: str) -> Path:
    """The file of a :data:`MUJOCO` key."""
    return robots() / name[4:] if name.startswith("erd:") else Path(__file__).parent / "data" / name


def test_every_mimic_urdf_in_tests_data_is_compared():
    """Every URDF with a ``<mimic>`` under tests/data is in :data:`MUJOCO` (by itself or its YAML sidecar)."""
    data = Path(__file__).parent / "data"
    found = {p for p in data.rglob("*.urdf") if b"<mimic" in p.read_bytes()}
    listed = set()
    for name in MUJOCO:
        path = located(name)
        listed.add(path if path.suffix == ".urdf" else pinmob_urdf(path))
    assert found <= listed


def pinmob_urdf(sidecar: Path) -> Path:
    """The URDF beside an Extended URDF sidecar (as pinmob finds it)."""
    from pinmob.io.extended_urdf import find_urdf

    return find_urdf(sidecar)


def mujoco_import(path: Path):
    """MuJoCo's compiled import of the URDF (of an Extended URDF's sidecar, with its loops as equalities).

    Meshes are left out with the geoms that show them (they move nothing; the copies here lack them), fixed
    links are kept as bodies (``fusestatic`` off: a loop's frame may be one), inertias balanced (some files
    break the triangle inequality, which moves nothing either).
    """
    import xml.etree.ElementTree as ET

    import mujoco
    import yaml

    urdf, loops = path, []
    if path.suffix == ".yaml":
        doc = yaml.safe_load(path.read_text())
        urdf, loops = (
            pinmob_urdf(path),
            list(zip(doc["closed_loop"], doc.get("type") or ["6d"] * len(doc["closed_loop"]))),
        )
    spec = mujoco.MjSpec.from_file(str(urdf))
    for geom in [g for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_MESH or g.meshname]:
        spec.delete(geom)
    for mesh in list(spec.meshes):
        spec.delete(mesh)
    spec.compiler.fusestatic = False
    spec.compiler.balanceinertia = True
    spec.compiler.boundmass = spec.compiler.boundmass or 1e-9
    spec.compiler.boundinertia = spec.compiler.boundinertia or 1e-12
    child = {j.get("name"): j.find("child").get("link") for j in ET.parse(urdf).getroot().findall("joint")}
    for k, ((a, b), kind) in enumerate(loops):
        sites = []
        for side, frame in (("a", a), ("b", b)):
            body = spec.body(child.get(frame, frame))  # a fixed joint's frame is its child link's origin
            site = body.add_site()
            site.name = f"loop{k}_{side}"
            sites.append(site.name)
        eq = spec.add_equality()
        eq.type = mujoco.mjtEq.mjEQ_CONNECT if kind == "3d" else mujoco.mjtEq.mjEQ_WELD
        eq.objtype = mujoco.mjtObj.mjOBJ_SITE
        eq.name1, eq.name2 = sites
    return spec.compile()


@pytest.mark.parametrize("name", sorted(MUJOCO))
def test_counts_agree_with_mujoco(name):
    """pinmob's nv, closure rows and mechanism DoF are MuJoCo's (``nv - rank`` of its equality rows of
    ``efc_J``) at pinmob's closed configuration, which closes MuJoCo's own equalities."""
    import mujoco
    from test_mujoco_counts import clear_rank

    path = located(name)
    m = mujoco_import(path)
    d = mujoco.MjData(m)
    if name == "erd:talos_data/robots/talos_reduced.urdf":
        with (
            pytest.warns(UserWarning, match="<mimic> of 12 joint.s. left out, the joint or its driver being fixed"),
            pytest.raises(pinmob.MechanismFileError, match="without a <mimic> joint between moving joints"),
        ):
            pinmob.load(path)
        doc = {"nv": m.nv, "closure_rows": 0, "mechanism_dof": m.nv, "joint_values": {}}
    else:
        doc = pinmob.analyze(pinmob.load(path)).to_dict()
    for joint, value in doc["joint_values"].items():
        d.joint(joint).qpos[:] = value
    mujoco.mj_forward(m, d)
    eq = np.flatnonzero(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    jac = d.efc_J[: d.nefc * m.nv].reshape(d.nefc, m.nv)[eq]
    assert np.abs(d.efc_pos[eq]).max(initial=0.0) < 1e-9  # pinmob's configuration closes MuJoCo's equalities
    figures = (m.nv, eq.size, m.nv - clear_rank(jac))
    assert figures == MUJOCO[name]
    assert (doc["nv"], doc["closure_rows"], doc["mechanism_dof"]) == figures
    if "actuation" in doc:  # the actuated joints held (an Extended URDF's name_mot; a URDF has none)
        act = doc["actuation"]
        held = np.zeros((len(act["actuated"]), m.nv))
        for k, joint in enumerate(act["actuated"]):
            held[k, m.jnt_dofadr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, joint)]] = 1.0
        both = clear_rank(np.vstack([jac, held]))
        assert (act["locked_dof"], act["redundant_actuators"]) == (m.nv - both, clear_rank(jac) + len(held) - both)


def test_the_viewer_moves_mimics_with_their_driver():
    """The viewer's followed motions (pinmob.viewer.prepare) keep every mimic on its driver: the jaw and the
    plunger follow jaw_a along the whole path, which moves."""
    from pinmob.viewer import ViewOptions, prepare

    mech = pinmob.load(SCISSOR)
    prep = prepare(mech, pinmob.analyze(mech).state.q, None, ViewOptions(steps=4))
    assert prep.paths
    ids = {
        name: mech.model.joints[mech.model.getJointId(name)].idx_q
        for name in ("jaw_a_joint", "jaw_b_joint", "plunger_joint")
    }
    for path in prep.paths.values():
        qs = np.array(path.forward + path.backward)
        a = qs[:, ids["jaw_a_joint"]]
        assert np.ptp(a) > 1e-3  # the gripper moves
        np.testing.assert_allclose(qs[:, ids["jaw_b_joint"]], -2 * a + 0.1, atol=1e-9)
        np.testing.assert_allclose(qs[:, ids["plunger_joint"]], 0.05 * a, atol=1e-9)


def test_mimics_that_couple_limbs_of_a_toml_mechanism(tmp_path):
    """The 3-PUU (3T, three sliders) with B's and C's sliders mimicking A's: the couplings join the limbs (the
    limb-wise method does not apply, the report says so) and the platform keeps one motion: the sliders moving
    together, along the 3-fold symmetry axis z by symmetry (a 3T platform whose three sliders stay equal)."""
    text = (builtin_dir() / "3puu.urdf").read_text()  # the built-in model's folder, installed or not
    for joint in ("B_slider", "C_slider"):
        start = text.index(f'<joint name="{joint}"')
        end = text.index("</joint>", start)
        text = text[:end] + '<mimic joint="A_slider"/>' + text[end:]
    (tmp_path / "3puu.urdf").write_text(text)
    (tmp_path / "3puu.toml").write_text((builtin_dir() / "3puu.toml").read_text())
    report = pinmob.analyze(tmp_path / "3puu.toml", "generic")
    assert (report.dof, report.motion_type) == (1, "1T")
    np.testing.assert_allclose(np.abs(report.motions[0].direction), [0, 0, 1], atol=1e-9)
    assert "closure 'mimic_B_slider' couples limbs A, B" in str(report)


def test_a_scan_along_an_actuated_mimic_moves_its_driver(tmp_path, capsys):
    """pinmob scan along jaw_b (a mimic, actuated): every sample closes the couplings (jaw_a = (0.1 - jaw_b) / 2,
    plunger = 0.05 jaw_a), 1 DoF, the actuation valid."""
    import json

    out = tmp_path / "scan.json"
    argv = ["scan", str(SCISSOR), "--from", "jaw_b_joint=-0.2", "--to", "jaw_b_joint=0.3", "--samples", "3"]
    assert main([*argv, "--actuated", "jaw_b_joint", "--no-progress", "--json", str(out)]) == 0
    samples = json.loads(out.read_text())["samples"]
    assert [s["q_jaw_b_joint"] for s in samples] == pytest.approx([-0.2, 0.05, 0.3], abs=1e-12)
    for s in samples:
        assert s["q_jaw_a_joint"] == pytest.approx((0.1 - s["q_jaw_b_joint"]) / 2, abs=1e-9)
        assert s["q_plunger_joint"] == pytest.approx(0.05 * s["q_jaw_a_joint"], abs=1e-9)
        assert (s["dof"], s["actuation_valid"]) == (1, True)
