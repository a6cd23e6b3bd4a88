"""pinmob's counts agree with MuJoCo's on every MJCF file in ``tests/data``, at the configuration pinmob analyses.

MuJoCo is the truth: at pinmob's closed configuration (its ``joint_values`` set as MuJoCo's ``qpos``, closing
MuJoCo's own equalities), the mechanism DoF is ``nv - rank(efc_J's equality rows)`` and the motions left with the
actuators held are ``nv - rank([equality rows; actuator_moment rows])``, with the floating bases pinmob holds
(``base_held``) held in MuJoCo too (their 6 velocity columns as rows). :data:`MUJOCO` lists MuJoCo's figures per
file (computed with MuJoCo, checked here again); every MJCF file under ``tests/data`` must be in it, so a copied
model cannot go untested. The third-party files and their sources are listed in ``tests/data/third_party/README.md``.
The files of ``../shared/external`` with a licence that allows it are copied there (the others are not read by
the tests: they are not part of the repository).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pytest
from test_third_party import mujoco_at, mujoco_joint, nout

import pinmob

DATA = Path(__file__).parent / "data"

#: file (under tests/data) -> MuJoCo's (nv, nu, mechanism DoF, motions left with the actuators and the floating
#: bases pinmob holds held), at pinmob's analysed configuration (``mujoco_truth`` below).
MUJOCO: dict[str, tuple[int, int, int, int]] = {
    # a quadruped of four planar five-bar legs (test_cad_gaps' fixture), at MuJoCo's qpos0, which closes: 4 foot
    # connects of 3 rows, 1 redundant each (planar legs); 8 hip motors and the held torso lock every motion
    "cad_gaps/legged/robot.xml": (22, 8, 14, 0),
    "formats/delta/delta.xml": (24, 3, 9, 6),
    "formats/fivebar/fivebar.xml": (4, 2, 2, 0),
    "formats/fourbar/fourbar.xml": (3, 1, 1, 0),
    "fourbar_connect.xml": (3, 1, 1, 0),
    # a position and a velocity servo on the crank (MuJoCo's PD pair): two actuators, one coordinate held
    "fourbar_servo_pair.xml": (3, 2, 1, 0),
    "fourbar_weld.xml": (4, 1, 1, 0),
    # test_keyframe_starts' four-bar: no keyframe (nor qpos0) closes; pinmob closes it from the keyframe 'wide'
    "keyframes/fourbar_open_keys.xml": (3, 1, 1, 0),
    # test_mjcf_tendons' fixtures: a cable hand (spatial tendons over sites and pulleys, a site actuator, a spatial
    # tendon equality), a gripper whose four-bar fingers are coupled by tendon equalities, and a slider-crank, a
    # ball-joint motor, a free puck pushed at its edge and an adhesion actuator (on a body: not held by either)
    # humanoid legs (test_finite_couplings): per leg 19 rates - 3 connects x 3 - 1 toe coupling = 9; the hips and
    # cranks held leave the 6 rods' spins
    "couplings/humanoid_legs.xml": (38, 12, 18, 6),
    # a = +-b^2 and t1 = +-t2^2 give each row twice at zero (rank 2 of 4); the actuator on f + g holds one more
    "couplings/shaky_couplings.xml": (6, 1, 4, 3),
    # tendons straight between sites: a_distal and b_follows_a (2 rows); c_held's row is zero at qpos0 (the cable at
    # its shortest: MuJoCo adds no row there); the flexor's motor holds one more
    "couplings/site_tendons.xml": (6, 1, 4, 3),
    "tendons/cable_hand.xml": (9, 4, 5, 1),
    "tendons/gripper.xml": (8, 1, 1, 0),
    "tendons/transmissions.xml": (12, 4, 7, 4),
    # a two-link arm's tip driven along x relative to a reference site, a dial following the elbow
    "tendons/refsite.xml": (3, 1, 2, 1),
    # two site transmissions with a turning reference site (one along a translational gear, one a rotational)
    "tendons/refsite_turning.xml": (5, 2, 4, 2),
    # a site transmission whose moment arms MuJoCo gives as zero at q (its reference site on a rocker's pivot)
    "tendons/rocker.xml": (3, 1, 2, 2),
    # actuators with several controls or outputs: two orientation servos (3 outputs each), a PID (2 controls)
    "tendons/orientation.xml": (11, 9, 10, 2),
    # a Bennett linkage closed by a weld (written for tests/test_minimal_closures.py): 1 DoF (Bennett, 1914), the
    # weld's rotation rows implied; the crank's motor holds it
    "bennett_weld.xml": (4, 1, 1, 0),
    # pinmob's own names fixture: a pinned free base (held), a parallelogram, a coupled follower, a free hinge
    "unnamed_parts.xml": (11, 0, 5, 2),
    # Cassie (menagerie, with its 10 motors; meshes not copied): 22 DoF as Pinocchio's copy; with the pelvis and
    # the motors held, MuJoCo leaves 8 motions (of the shin and heel springs, tarsi, foot cranks and rods)
    "third_party/menagerie_agility_cassie/cassie.xml": (32, 10, 22, 8),
    "third_party/menagerie_agility_cassie/scene.xml": (32, 10, 22, 8),
    # Franka hand (meshes not copied): two slides coupled by a joint equality, an actuator on the tendon 'split'
    "third_party/menagerie_franka_hand/hand.xml": (2, 1, 1, 0),
    # the xArm7 arm with its hand (the arm's meshes not copied): 7 motors and the hand's actuator
    "third_party/menagerie_xarm7_hand/scene.xml": (13, 8, 8, 0),
    "third_party/menagerie_xarm7_hand/xarm7.xml": (13, 8, 8, 0),
    # two of its actuators are on spatial tendons; its head (a free joint carrying legs) is held
    "third_party/mujoco_testdata/solver/model.xml": (43, 10, 37, 21),
    # Robotiq 2F-85: two four-bars (a connect each: 1 redundant row each) and the drivers coupled; the fingers are
    # adaptive: 3 DoF, the actuator on the tendon 'split' holds one, 2 left. scene.xml adds a free box (6)
    "third_party/menagerie_robotiq_2f85/2f85.xml": (8, 1, 3, 2),
    "third_party/menagerie_robotiq_2f85/scene.xml": (14, 1, 9, 8),
    "third_party/menagerie_xarm7_hand/hand.xml": (6, 1, 1, 0),
    "third_party/mujoco_testdata/actuation/tendon_dampratio.xml": (8, 2, 2, 0),
    "third_party/mujoco_testdata/armature_equivalence.xml": (3, 2, 2, 0),
    # a weld between two bodies of the world: MuJoCo makes no row of it, pinmob 6 zero rows (redundant)
    "third_party/mujoco_testdata/core_constraint/dofless_weld.xml": (12, 0, 6, 6),
    "third_party/mujoco_testdata/core_constraint/soft_weld.xml": (6, 0, 0, 0),
    "third_party/mujoco_testdata/core_smooth/rne_post/connect/force_free.xml": (6, 0, 3, 3),
    "third_party/mujoco_testdata/core_smooth/rne_post/connect/force_slide.xml": (1, 0, 0, 0),
    "third_party/mujoco_testdata/core_smooth/rne_post/connect/force_slide_rotated.xml": (1, 0, 0, 0),
    "third_party/mujoco_testdata/core_smooth/rne_post/connect/torque_free.xml": (6, 0, 3, 3),
    "third_party/mujoco_testdata/core_smooth/rne_post/weld/force_free.xml": (6, 0, 0, 0),
    "third_party/mujoco_testdata/core_smooth/rne_post/weld/force_free_rotated.xml": (6, 0, 0, 0),
    "third_party/mujoco_testdata/core_smooth/rne_post/weld/force_torque_free.xml": (6, 0, 0, 0),
    "third_party/mujoco_testdata/core_smooth/rne_post/weld/force_torque_free_rotated.xml": (6, 0, 0, 0),
    "third_party/mujoco_testdata/core_smooth/rne_post/weld/force_torque_free_rotated_tendon.xml": (6, 0, 0, 0),
    # welds with torquescale 0: their rotation rows are multiplied by 0 (3 rows of 6 count)
    "third_party/mujoco_testdata/core_smooth/rne_post/weld/tfratio0_force_free.xml": (6, 0, 3, 3),
    "third_party/mujoco_testdata/core_smooth/rne_post/weld/tfratio0_force_slide.xml": (1, 0, 0, 0),
    "third_party/mujoco_testdata/core_smooth/rne_post/weld/tfratio0_force_slide_rotated.xml": (1, 0, 0, 0),
    "third_party/mujoco_testdata/core_smooth/rne_post/weld/tfratio0_multiple_constraints.xml": (14, 0, 4, 4),
    "third_party/mujoco_testdata/core_smooth/rne_post/weld/tfratio0_torque_free.xml": (6, 0, 3, 3),
    "third_party/mujoco_testdata/core_smooth/ten_armature_1_equiv.xml": (3, 0, 1, 1),
    # inactive equalities (active="false") are left out by both
    "third_party/mujoco_testdata/equality_site_body_compare.xml": (12, 0, 3, 3),
    "third_party/mujoco_testdata/island/island_efc.xml": (20, 0, 14, 14),
    "third_party/mujoco_testdata/sleep/equality.xml": (17, 0, 16, 16),
    "third_party/mujoco_testdata/connect.xml": (18, 0, 9, 9),
    "third_party/mujoco_testdata/equality_site.xml": (18, 0, 3, 3),
    "third_party/mujoco_testdata/jdotv_connect_2d.xml": (4, 0, 2, 2),
    "third_party/mujoco_testdata/jdotv_connect_3d.xml": (9, 0, 6, 6),
    "third_party/mujoco_testdata/jdotv_weld_3d.xml": (9, 0, 3, 3),
    "third_party/mujoco_testdata/multiple_constraints.xml": (14, 0, 4, 4),
    "third_party/mujoco_testdata/weld.xml": (30, 0, 3, 3),
    # Cassie's pelvis (a free joint carrying the legs) is held: 22 - 6
    "third_party/pinocchio_closed_chain/closed_chain.xml": (32, 0, 22, 16),
}

#: a relative gap in MuJoCo's singular values that its rank must clear (no rank decided by round-off)
GAP = 1e-6


def mjcf_files() -> list[str]:
    """Every MJCF file under tests/data (a ``<mujoco`` root), relative to it."""
    return sorted(
        p.relative_to(DATA).as_posix() for p in DATA.rglob("*.xml") if "<mujoco" in p.read_text(errors="replace")[:2000]
    )


def clear_rank(rows: np.ndarray) -> int:
    """The rank of ``rows``, asserting a clear gap in their singular values (relative to the largest)."""
    if rows.size == 0:
        return 0
    s = np.linalg.svd(rows, compute_uv=False)
    s = s / max(s[0], 1e-300)
    rank = int(np.count_nonzero(s > 1e-9))
    assert rank == s.size or s[rank] < GAP * 1e-3, f"MuJoCo's rank is not clear: singular values {s}"
    assert rank == 0 or s[rank - 1] > GAP, f"MuJoCo's rank is not clear: singular values {s}"
    return rank


def mujoco_truth(path: Path, joint_values: dict[str, Any], held_bases: list[str]) -> tuple[int, int, int, int, float]:
    """MuJoCo's (nv, nu, DoF, motions left, largest equality residual) at the given joint values.

    DoF: ``nv - rank`` of the equality rows of ``efc_J`` (a weld's rotation rows with torquescale 0 are
    multiplied by 0 there, so they do not count); motions left: ``nv - rank`` of those rows, the actuators'
    moment arms (``actuator_moment``) and the velocity columns of the floating bases held.
    """
    m, d, eq = mujoco_at(path, joint_values)
    jac = d.efc_J[: d.nefc * m.nv].reshape(d.nefc, m.nv)[eq]
    moments = np.zeros((nout(m), m.nv))
    mujoco.mju_sparse2dense(moments, d.actuator_moment, d.moment_rownnz, d.moment_rowadr, d.moment_colind)
    held = np.zeros((6 * len(held_bases), m.nv))
    for k, name in enumerate(held_bases):
        j = mujoco_joint(m, name)
        assert m.jnt_type[j] == mujoco.mjtJoint.mjJNT_FREE, name
        held[6 * k : 6 * k + 6, m.jnt_dofadr[j] : m.jnt_dofadr[j] + 6] = np.eye(6)
    dof = m.nv - clear_rank(jac)
    left = m.nv - clear_rank(np.vstack([jac, moments, held]))
    gap = float(np.abs(d.efc_pos[eq]).max()) if eq.size else 0.0
    return m.nv, m.nu, dof, left, gap


def test_every_mjcf_file_is_counted():
    """No MJCF file under tests/data is left out of the comparison."""
    assert mjcf_files() == sorted(MUJOCO)


@pytest.mark.parametrize("name", sorted(MUJOCO))
def test_counts_agree_with_mujoco(name):
    """pinmob's mechanism DoF and motions left with the actuators held are MuJoCo's, at pinmob's closed
    configuration (whose joint values close MuJoCo's equalities), and MuJoCo's figures are those listed."""
    path = DATA / name
    doc = pinmob.analyze(pinmob.load(path)).to_dict()
    act = doc["actuation"]
    nv, nu, dof, left, gap = mujoco_truth(path, doc["joint_values"], act["base_held"])
    assert gap < 1e-9  # pinmob's configuration closes MuJoCo's own constraints
    assert (nv, nu, dof, left) == MUJOCO[name]
    m = mujoco_at(path, doc["joint_values"])[0]
    rows = actuator_rows(m)
    on_bodies = sum(len(r) for a, r in rows if m.actuator_trntype[a] == mujoco.mjtTrn.mjTRN_BODY)  # adhesion
    assert len(act["joint_actuators"]) + len(act["actuated_tendons"]) == nout(m) - on_bodies  # each output once
    on_joints = [int(m.actuator_trnid[a, 0]) for a in joint_actuators(m)]  # MuJoCo's joint of each, in order
    assert [mujoco_joint(m, j) for j in act["joint_actuators"].values()] == on_joints
    assert sorted(mujoco_joint(m, j) for j in act["actuated"]) == sorted(set(on_joints))  # each joint once
    assert (doc["mechanism_dof"], act["locked_dof"]) == (dof, left)


def actuator_rows(m: Any) -> list[tuple[int, range]]:
    """Each of MuJoCo's actuators and its rows of ``actuator_moment`` (an actuator may have several outputs,
    ``actuator_outadr``, ``actuator_outnum``: an orientation servo three)."""
    return [(a, range(m.actuator_outadr[a], m.actuator_outadr[a] + m.actuator_outnum[a])) for a in range(m.nactuator)]


def joint_actuators(m: Any) -> list[int]:
    """MuJoCo's actuators on a hinge or slide (``joint`` and ``jointinparent`` transmissions), in order."""
    on_joint = {int(mujoco.mjtTrn.mjTRN_JOINT), int(mujoco.mjtTrn.mjTRN_JOINTINPARENT)}
    kinds = {int(mujoco.mjtJoint.mjJNT_HINGE), int(mujoco.mjtJoint.mjJNT_SLIDE)}
    return [
        a
        for a, _ in actuator_rows(m)
        if int(m.actuator_trntype[a]) in on_joint and int(m.jnt_type[m.actuator_trnid[a, 0]]) in kinds
    ]


def drives(m: Any) -> list[int]:
    """The moment rows of one actuator per transmission (``actuator_trntype``, ``actuator_trnid``), those on bodies
    left out.

    Actuators with one transmission move one thing (a position and a velocity servo on one joint): their
    forces add, and their moment rows are one row times their gears. They are one drive, not an actuator
    that over-determines the chain with the other.
    """
    first: dict[tuple[int, int, int], range] = {}
    for a, rows in actuator_rows(m):
        if int(m.actuator_trntype[a]) != int(mujoco.mjtTrn.mjTRN_BODY):  # adhesion: held by neither
            first.setdefault((int(m.actuator_trntype[a]), *map(int, m.actuator_trnid[a])), rows)
    return sorted(r for rows in first.values() for r in rows)


@pytest.mark.parametrize("name", sorted(MUJOCO))
def test_redundant_actuators_agree_with_mujoco(name):
    """The actuators pinmob calls redundant are MuJoCo's: ``rank([eq; held bases]) + (drives) -
    rank([eq; their moments; held bases])`` at pinmob's configuration, one drive per transmission (:func:`drives`).
    A floating base that the closures already hold in part (pinned to the world) makes no actuator redundant
    (tests/data/unnamed_parts.xml said 3)."""
    path = DATA / name
    doc = pinmob.analyze(pinmob.load(path)).to_dict()
    act = doc["actuation"]
    m, d, eq = mujoco_at(path, doc["joint_values"])
    jac = d.efc_J[: d.nefc * m.nv].reshape(d.nefc, m.nv)[eq]
    moments = np.zeros((nout(m), m.nv))
    mujoco.mju_sparse2dense(moments, d.actuator_moment, d.moment_rownnz, d.moment_rowadr, d.moment_colind)
    moments = moments[drives(m)]
    held = np.zeros((6 * len(act["base_held"]), m.nv))
    for k, base in enumerate(act["base_held"]):
        j = mujoco_joint(m, base)
        held[6 * k : 6 * k + 6, m.jnt_dofadr[j] : m.jnt_dofadr[j] + 6] = np.eye(6)
    redundant = clear_rank(np.vstack([jac, held])) + len(moments) - clear_rank(np.vstack([jac, moments, held]))
    assert (act["redundant_actuators"], act["overdetermined"]) == (redundant, redundant > 0)


def test_a_joint_driven_by_two_actuators_is_actuated_once(tmp_path):
    """The four-bar's crank driven by a position and a velocity servo (MuJoCo's PD pair): MuJoCo has two actuators
    (``nu`` 2) whose transmissions are both the crank (``actuator_trnid``). pinmob names both, actuates the crank
    once and calls neither redundant: one coordinate driven, the chain not over-determined. A motor on the rocker
    as well does over-determine the 1-DoF chain: one redundant actuator, not two. On the old code the report named
    no actuator ('joint_actuators' did not exist) and the text only '1 actuated joint(s)'."""
    path = DATA / "fourbar_servo_pair.xml"
    m = mujoco.MjModel.from_xml_path(str(path))
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_ACTUATOR, a) for a in range(m.nu)]
    crank = mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, int(m.actuator_trnid[0, 0]))
    assert m.nu == 2 and m.actuator_trnid[:, 0].tolist() == [m.actuator_trnid[0, 0]] * 2 and crank == "crank"
    report = pinmob.analyze(pinmob.load(path))
    act = report.to_dict()["actuation"]
    assert act["actuated"] == [crank] and act["joint_actuators"] == dict.fromkeys(names, crank)
    assert (act["valid"], act["redundant_actuators"], act["locked_dof"]) == (True, 0, 0)
    assert f"1 actuated joint(s) ('crank' by 2 actuators: {', '.join(names)})" in str(report)
    # the named actuators are the file's: naming joints instead (--actuated) drops them
    chosen = pinmob.analyze(pinmob.load(path), actuated=["crank"]).to_dict()["actuation"]
    assert chosen["joint_actuators"] == {} and chosen["actuated"] == ["crank"]
    rocker = tmp_path / "rocker_too.xml"
    rocker.write_text(
        path.read_text().replace("</actuator>", '  <motor name="rocker_motor" joint="rocker"/>\n  </actuator>')
    )
    act = pinmob.analyze(pinmob.load(rocker)).to_dict()["actuation"]
    assert act["actuated"] == ["crank", "rocker"] and act["joint_actuators"]["rocker_motor"] == "rocker"
    assert (act["valid"], act["redundant_actuators"]) == (False, 1)  # 2 drives on 1 DoF (MuJoCo's rank: 2 + 2 - 3)
