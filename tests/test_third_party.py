"""Closed-chain models written by other people, read as they are, each count checked twice.

Every expected count is established independently of pinmob: by hand (the docstrings) and by the rank of
MuJoCo's own equality-constraint Jacobian (``efc_J``) at the same configuration, set in MuJoCo from the
``joint_values`` pinmob reports (which must close MuJoCo's equalities). The files are in
``tests/data/third_party`` (see its README); the placo and onshape-to-robot conventions are tested on
fixtures written here.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.assembly.residual import closure_error, compute_kinematics
from pinmob.cli import main
from pinmob.io.mjcf import qpos_to_q

DATA = Path(__file__).parent / "data" / "third_party"

#: file -> (mechanism DoF, redundant closure equations, idle motions), counted by hand:
HAND: dict[str, tuple[int, int, int]] = {
    # Cassie: 6 (free base) + 2 x 13 joints. Per leg, the plantar loop (foot-crank, plantar-rod, foot:
    # three parallel hinges, closed by a ball) is a planar four-bar: 3 rows, the out-of-plane one implied
    # (1 redundant); the Achilles loop (a ball rod from the hip to the heel spring, closed by a ball) has
    # 3 independent rows and the rod spins idle about its axis. Rows 12, rank 10: DoF 22, 2 redundant, 2 idle.
    "pinocchio_closed_chain/closed_chain.xml": (22, 2, 2),
    # xArm7 gripper: each side a planar four-bar (driver, finger, inner knuckle: 3 parallel hinges, a ball
    # closure: 1 redundant row) and the two drivers coupled (<equality joint>, 1 row): rows 7, rank 5 of nv 6.
    "menagerie_xarm7_hand/hand.xml": (1, 2, 0),
    # three free beams pinned by a point each (to the world, to a box, site to site): 18 - 9. Idle (moving
    # no joint centre and no closure point): beam1 is pinned at its own origin (3), the others turn only
    # about the line through their origin and pin (1 each): 5.
    "mujoco_testdata/connect.xml": (9, 0, 5),
    # three free bodies: a connect and two welds (site to site): 18 - 15, the connected body's rotations,
    # about its own origin where its site is: idle.
    "mujoco_testdata/equality_site.xml": (3, 0, 3),
    # a hinge and a planar body (slide x, slide z, hinge y) pinned together: the y row is implied. 4 - 2;
    # the body turns idle about its origin, the pin.
    "mujoco_testdata/jdotv_connect_2d.xml": (2, 1, 1),
    # a ball-jointed pendulum and a free body, pinned tip to tip (the body's origin): 9 - 3; idle: the body's
    # 3 rotations about its origin, the pendulum's spin about the line from its ball to its tip: 4.
    "mujoco_testdata/jdotv_connect_3d.xml": (6, 0, 4),
    # the same, welded: 9 - 6; idle: the spin about the line from the ball to the weld: 1.
    "mujoco_testdata/jdotv_weld_3d.xml": (3, 0, 1),
    # a slide fixed by a joint equality (1), a free body welded to a fixed one (6), another pinned (3):
    # 14 - 10, the other slide and the pinned body's rotations (idle: only the one about the line from its
    # origin to the pin).
    "mujoco_testdata/multiple_constraints.xml": (4, 0, 1),
    # five free beams welded (6 each) but one weld with torquescale 0 (a point: 3): 30 - 27; idle: that
    # beam's turn about the line from its origin to the anchor: 1.
    "mujoco_testdata/weld.xml": (3, 0, 1),
}


def mujoco_model(path: Path) -> Any:
    """MuJoCo's compiled model of the file's kinematics: its meshes are left out with the geoms that show them
    (they move no joint, site or body frame; the copies in ``tests/data`` may lack them, see the README), and a
    moving body left without mass is given a tiny one (the compiler's ``boundmass`` and ``boundinertia``)."""
    spec = mujoco.MjSpec.from_file(str(path))
    for geom in [g for g in spec.geoms if g.type == mujoco.mjtGeom.mjGEOM_MESH or g.meshname]:
        spec.delete(geom)
    for mesh in list(spec.meshes):
        spec.delete(mesh)
    spec.compiler.boundmass = spec.compiler.boundmass or 1e-9
    spec.compiler.boundinertia = spec.compiler.boundinertia or 1e-12
    return spec.compile()


def mujoco_joint(m: Any, name: str) -> int:
    """MuJoCo's id of the joint pinmob names ``name``: its name, or ``#<id>`` for an unnamed one (nothing else)."""
    if name.startswith("#") and name[1:].isdigit():
        return int(name[1:])
    j = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, name)
    assert j >= 0, f"pinmob's joint name {name!r} is not MuJoCo's"
    return j


def mujoco_at(path: Path, joint_values: dict[str, float | list[float]]) -> tuple[Any, Any, np.ndarray]:
    """MuJoCo's model and data at the given joint values (``mj_forward``), and the indices of its equality rows."""
    m = mujoco_model(path)
    d = mujoco.MjData(m)
    for name, value in joint_values.items():
        d.joint(mujoco_joint(m, name)).qpos[:] = value
    mujoco.mj_forward(m, d)
    return m, d, np.flatnonzero(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)


def mujoco_counts(path: Path, joint_values: dict[str, float | list[float]]) -> tuple[int, int, int, float]:
    """(nv, equality rows, rank of efc_J, largest |efc_pos|) with MuJoCo at the given joint values.

    Rows that MuJoCo multiplies by zero (a weld's rotation rows with torquescale 0) are not counted.
    """
    m, d, eq = mujoco_at(path, joint_values)
    ids = d.efc_id[eq]
    keep = np.ones(eq.size, bool)
    for e in range(m.neq):  # a weld with torquescale 0: its rotation rows (the 4th to 6th) are multiplied by 0
        if m.eq_type[e] == mujoco.mjtEq.mjEQ_WELD and m.eq_data[e, 10] == 0:
            keep[np.flatnonzero(ids == e)[3:6]] = False
    jac = d.efc_J.reshape(d.nefc, m.nv)[eq[keep]]
    s = np.linalg.svd(jac, compute_uv=False)
    rank = int(np.count_nonzero(s > 1e-9 * s[0]))
    return m.nv, jac.shape[0], rank, float(np.abs(d.efc_pos[eq]).max())


@pytest.mark.parametrize("name", sorted(HAND))
def test_counts_agree_with_mujoco_and_by_hand(name):
    """pinmob's DoF and redundant equations = MuJoCo's efc_J rank = the hand count, at a closed configuration
    (MuJoCo's reference pose when it closes, else one found), whose joint values close MuJoCo's equalities."""
    path = DATA / name
    mech = pinmob.load(path)
    report = pinmob.analyze(mech)
    doc = report.to_dict()
    nv, rows, rank, gap = mujoco_counts(path, doc["joint_values"])
    assert gap < 1e-9  # the reported joint values close MuJoCo's own constraints
    dof, redundant, idle = HAND[name]
    assert (doc["mechanism_dof"], doc["redundant_constraints"]) == (dof, redundant)
    assert (nv - rank, rows - rank) == (dof, redundant)
    assert doc["idle_dof"] == idle
    assert doc["ambiguous_ranks"] == [] and doc["rank_tolerance_note"] is None


def nout(m: Any) -> int:
    """MuJoCo's number of actuator outputs (``nout``, rows of ``actuator_moment``; ``nu`` counts controls)."""
    return int(m.nout)


def mujoco_locked(path: Path, joint_values: dict[str, float | list[float]]) -> tuple[int, int]:
    """(nu, motions left with every actuator held) by MuJoCo: ``nv - rank [efc_J's equality rows; moments]``.

    The actuators' rows are MuJoCo's transmission moments (``actuator_moment``, a tendon's Jacobian for an
    actuator on a tendon), at the given joint values.
    """
    m, d, eq = mujoco_at(path, joint_values)
    moments = np.zeros((nout(m), m.nv))
    mujoco.mju_sparse2dense(moments, d.actuator_moment, d.moment_rownnz, d.moment_rowadr, d.moment_colind)
    rows = np.vstack([d.efc_J.reshape(d.nefc, m.nv)[eq], moments])
    s = np.linalg.svd(rows, compute_uv=False)
    return m.nu, m.nv - int(np.count_nonzero(s > 1e-9 * s[0]))


FIVEBAR = Path(__file__).parent / "data" / "formats" / "fivebar" / "fivebar.xml"


@pytest.mark.parametrize(
    ("name", "actuators", "left"),
    [
        # the xArm7 hand's one actuator on the tendon split = (right driver + left driver) / 2: the gripper's one DoF
        ("menagerie_xarm7_hand/hand.xml", None, 0),
        # a five-bar (2 DoF) driven through the tendon L_mot + R_mot alone: the motion L_mot = -R_mot is left
        ("fivebar", '<general tendon="sum"/>', 1),
        # ... and with a motor on L_mot too: both rates held, nothing left
        ("fivebar", '<general tendon="sum"/><motor joint="L_mot"/>', 0),
        # a tendon over a motor and an elbow (coefficients 0.3 m/rad and 2 m/rad), and the other motor
        ("fivebar", '<general tendon="mix"/><motor joint="R_mot"/>', 0),
    ],
)
def test_tendon_actuators_are_held_as_mujoco_holds_them(tmp_path, name, actuators, left):
    """An actuator on a fixed tendon holds its combination of joint rates: pinmob counts MuJoCo's ``nu``
    actuators and leaves the motions MuJoCo's constraint and moment rows leave (and the count by hand)."""
    path = _fivebar_with(tmp_path, actuators) if name == "fivebar" else DATA / name
    mech = pinmob.load(path)
    doc = pinmob.analyze(mech).to_dict()
    act = doc["actuation"]
    nu, mujoco_left = mujoco_locked(path, doc["joint_values"])
    assert len(act["actuated"]) + len(act["actuated_tendons"]) == nu
    assert act["actuated_tendons"] and act["locked_dof"] == mujoco_left == left
    assert act["valid"] is (left == 0)


def _fivebar_with(tmp_path: Path, actuators: str) -> Path:
    """The MJCF five-bar with the tendons 'sum' (L_mot + R_mot) and 'mix' (0.3 L_mot + 2 L_elbow) and these actuators."""
    tendons = (
        '<tendon><fixed name="sum"><joint joint="L_mot" coef="1"/><joint joint="R_mot" coef="1"/></fixed>'
        '<fixed name="mix"><joint joint="L_mot" coef="0.3"/><joint joint="L_elbow" coef="2"/></fixed></tendon>'
    )
    text = FIVEBAR.read_text()
    start, end = text.index("<actuator>"), text.index("</actuator>")
    path = tmp_path / "fivebar.xml"
    path.write_text(text[:start] + tendons + "<actuator>" + actuators + text[end:])
    return path


def test_a_scan_says_the_tendon_actuators_are_not_held_along_its_path(tmp_path, capsys):
    """The path moves the actuated joints only: one warning line names the tendon actuators it does not hold."""
    path = _fivebar_with(tmp_path, '<general name="pull" tendon="sum"/><motor joint="L_mot"/>')
    assert main(["scan", str(path), "--from", "reference", "--to", "L_mot=0.2", "-n", "3"]) == 0
    warned = [line for line in capsys.readouterr().err.splitlines() if "not held along it" in line]
    assert len(warned) == 1 and "tendon actuator(s) pull" in warned[0]


def test_a_joint_in_parent_transmission_actuates_its_joint(tmp_path):
    """<general jointinparent=...> on a hinge is the joint's own coordinate: counted as MuJoCo counts it (nu)."""
    path = _fivebar_with(tmp_path, '<general jointinparent="L_mot"/><motor joint="R_mot"/>')
    mech = pinmob.load(path)
    doc = pinmob.analyze(mech).to_dict()
    assert mech.actuated == ("L_mot", "R_mot") and not mech.actuated_tendons
    assert mujoco_locked(path, doc["joint_values"]) == (2, 0) and doc["actuation"]["locked_dof"] == 0


@pytest.mark.parametrize("name", sorted(HAND))
def test_closure_residuals_are_mujocos_at_random_configurations(name):
    """At MuJoCo's reference pose and random qpos, each closure's residual is MuJoCo's (efc_pos): the same
    points, frames and couplings (defaults, ref, sites, relpose, anchors, polynomials), to round-off."""
    path = DATA / name
    mech = pinmob.load(path)
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    data = mech.model.createData()
    rng = np.random.default_rng(7)
    for k in range(4):
        d.qpos[:] = m.qpos0 + (0 if k == 0 else rng.normal(scale=0.3, size=m.nq))
        mujoco.mj_forward(m, d)
        compute_kinematics(mech.model, data, qpos_to_q(mech.model, d.qpos))
        eq = np.flatnonzero(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
        for i, c in enumerate(mech.closures):
            theirs = d.efc_pos[eq[d.efc_id[eq] == i]]
            if c.type == "joint":
                ours, _, _ = closure_error(mech.model, data, c)
                assert_allclose(abs(ours[0]), abs(theirs[0]), atol=1e-12)
                continue
            a, b = data.oMf[c.frame_a_id], data.oMf[c.frame_b_id]
            assert_allclose(np.linalg.norm(a.translation - b.translation), np.linalg.norm(theirs[:3]), atol=1e-12)
            if c.type == "6d":  # MuJoCo's rotation rows: torquescale * sin(angle / 2) * axis
                scale = m.eq_data[i, 10]
                angle = np.linalg.norm(pin.log3(a.rotation.T @ b.rotation))
                assert_allclose(np.linalg.norm(theirs[3:6]), scale * np.sin(angle / 2), atol=1e-12)


# --------------------------------------------------------------------------- fixtures of our own


def spherical_urdf(eps: float = 0.0, cancel: bool = False) -> str:
    """A spherical four-bar in onshape-to-robot's URDF convention (closing_tip_1/_2), rocker axis off by ``eps``.

    Crank j1 (z) and coupler j2 (x) from the base, rocker j4 (y): every axis through the origin when eps = 0.
    The tip P = (0, 0.1, 0.1) on the coupler and on the rocker is cut by a point closure. The relative angular
    velocity must be parallel to OP: with w1 = a z + b x, w2 = c y, (b, -c, a) // (0, 1, 1) gives b = 0,
    c = -a: DoF 1; the radial row is implied: 1 redundant of 3. With ``cancel`` the rocker's tip is moved
    back by eps (exactly closed, but no longer spherical: rank 3, DoF 0 by 4e-6, within a factor 10 of
    the tolerance).
    """
    joint = '<joint name="{n}" type="revolute"><parent link="{p}"/><child link="{c}"/><origin xyz="{o}"/>'
    joint += '<axis xyz="{a}"/><limit lower="-3" upper="3" effort="1" velocity="1"/></joint>'
    links = "".join(
        f'<link name="{n}"/>' for n in ("base", "crank", "coupler", "rocker", "closing_tip_1", "closing_tip_2")
    )
    return (
        f'<robot name="spherical">{links}'
        + joint.format(n="j1", p="base", c="crank", o="0 0 0", a="0 0 1")
        + joint.format(n="j2", p="crank", c="coupler", o="0 0 0", a="1 0 0")
        + joint.format(n="j4", p="base", c="rocker", o=f"{eps} 0 0", a="0 1 0")
        + '<joint name="t1" type="fixed"><parent link="coupler"/><child link="closing_tip_1"/>'
        '<origin xyz="0 0.1 0.1"/></joint><joint name="t2" type="fixed"><parent link="rocker"/>'
        f'<child link="closing_tip_2"/><origin xyz="{-eps if cancel else 0} 0.1 0.1"/></joint></robot>'
    )


def spherical_mjcf(eps: float = 0.0, cancel: bool = False) -> str:
    """The same four-bar in onshape-to-robot's MJCF convention: ``<connect site1 site2>`` between closing sites."""
    geom = '<geom type="sphere" size="0.01"/>'
    return (
        '<mujoco model="spherical"><worldbody>'
        f'<body name="crank"><joint name="j1" axis="0 0 1"/>{geom}'
        f'<body name="coupler"><joint name="j2" axis="1 0 0"/>{geom}<site name="closing_tip_1" pos="0 0.1 0.1"/>'
        "</body></body>"
        f'<body name="rocker" pos="{eps} 0 0"><joint name="j4" axis="0 1 0"/>{geom}'
        f'<site name="closing_tip_2" pos="{-eps if cancel else 0} 0.1 0.1"/></body>'
        '</worldbody><equality><connect site1="closing_tip_1" site2="closing_tip_2"/></equality></mujoco>'
    )


def test_onshape_to_robot_conventions_agree(tmp_path):
    """The URDF (placo) and MJCF (onshape-to-robot) fixtures load as they are: one point closure 'tip', DoF 1,
    1 redundant (by hand, :func:`spherical_urdf`), as MuJoCo's efc_J rank on the MJCF says."""
    (tmp_path / "robot.urdf").write_text(spherical_urdf())
    (tmp_path / "robot.xml").write_text(spherical_mjcf())
    for path in (tmp_path / "robot.urdf", tmp_path / "robot.xml"):
        mech = pinmob.load(path)
        assert [str(c.type) for c in mech.closures] == ["3d"]
        doc = pinmob.analyze(mech).to_dict()
        assert (doc["mechanism_dof"], doc["redundant_constraints"]) == (1, 1), path.name
        nv, rows, rank, gap = mujoco_counts(tmp_path / "robot.xml", doc["joint_values"])
        assert gap < 1e-12 and (nv - rank, rows - rank) == (1, 1)
    assert pinmob.load(tmp_path / "robot.urdf").closures[0].name == "tip"


def test_urdf_without_closing_frames_says_what_to_add(tmp_path, capsys):
    path = tmp_path / "robot.urdf"
    path.write_text(spherical_urdf().replace("closing_tip_", "tip_"))
    assert main(["analyze", str(path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "closing_<name>_1 and closing_<name>_2" in err
    path.write_text(spherical_urdf().replace("closing_tip_2", "tip_2"))
    assert main(["analyze", str(path)]) == 2
    assert "missing closing_tip_2" in capsys.readouterr().err


def test_cad_gap_raises_the_rank_tolerance(tmp_path):
    """Rocker axis 1 um off the centre, tip gap 1 um: the loops close to 8.7e-6 L only. With --closure-tol 1e-4
    the singular value the gap explains (4.3e-6, half the residual) is not counted: DoF 1, 1 redundant (the
    spherical design, by hand), and the report says the tolerance was raised."""
    path = tmp_path / "robot.urdf"
    path.write_text(spherical_urdf(1e-6))
    mech = pinmob.load(path)
    with pytest.raises(pinmob.ClosureError):
        pinmob.analyze(mech, mech.neutral())
    report = pinmob.analyze(mech, mech.neutral(), closure_tol=1e-4)
    doc = report.to_dict()
    assert (doc["mechanism_dof"], doc["redundant_constraints"]) == (1, 1)
    assert doc["rank_tolerance_note"].startswith("rank tolerance raised from 1e-06")
    assert_allclose(report.rtol, 10 * report.state.residual, rtol=1e-12)
    assert "note: rank tolerance raised" in str(report)


def test_ambiguous_rank_gives_both_values(tmp_path, capsys):
    """Exactly closed but 1 um off spherical: the third singular value 4.3e-6 is 3.5 x the tolerance 1.2e-6
    (no clear gap): the report counts it (DoF 0) and says the decision is ambiguous, with both values."""
    path = tmp_path / "robot.urdf"
    path.write_text(spherical_urdf(1e-6, cancel=True))
    assert main(["analyze", str(path), "--joints", "j1=0", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["mechanism_dof"] == 0
    (amb,) = doc["ambiguous_ranks"]
    assert amb["decision"] == "closure rank" and amb["rank"] == 3
    assert amb["tolerance"] < amb["kept"] < 10 * amb["tolerance"] and amb["dropped"] == 0.0  # no clear gap
    assert main(["analyze", str(path), "--joints", "j1=0"]) == 0
    assert f"ambiguous closure rank: singular values {amb['kept']:.2e} (counted)" in capsys.readouterr().out
    assert main(["analyze", str(path), "--joints", "j1=0", "--brief"]) == 0  # the one line says it too
    assert (
        capsys.readouterr().out.rstrip().endswith("mechanism DoF 0; ambiguous closure rank: 3 as counted, 2 possible")
    )


# --------------------------------------------------------------------------- MJCF details


MJCF = """<mujoco model="details">
  <default><default class="pin"><joint pos="0 0.02 0"/></default></default>
  <worldbody>
    <site name="anchor" pos="0.3 0.02 0"/>
    <body name="crank"><joint name="crank" axis="0 0 1" ref="30"/><geom type="sphere" size="0.01"/>
      <body name="coupler" pos="0.1 0 0"><joint name="coupler" class="pin" axis="0 0 1"/>
        <geom type="sphere" size="0.01"/><site name="coupler" pos="0.2 0.02 0"/></body></body>
    <body name="coupler_twin" pos="0 0.5 0"><joint name="twin" axis="0 0 1"/><geom type="sphere" size="0.01"/>
      <site name="coupler_twin" pos="0.1 0 0"/></body>
  </worldbody>
  <equality><connect site1="coupler" site2="anchor"/><joint joint1="twin" joint2="crank" polycoef="0 2 0 0 0"/></equality>
  <actuator><motor joint="crank"/></actuator>
  <keyframe><key name="bent" qpos="0.9 -0.6 0.2"/></keyframe>
</mujoco>
"""


def test_mjcf_details_as_mujoco_reads_them(tmp_path):
    """A joint pos from a default class, a hinge ref, a site on the worldbody in a connect, a body and a site
    sharing a name, a joint coupling and a keyframe: loaded without crash, the closure point is MuJoCo's
    (residual = efc_pos at random qpos), the keyframe is a named configuration. By hand: nv 3, rows 3 + 1
    (the crank and coupler pin a point in the plane: 2 independent rows, the z row implied; the coupling
    1), rank 3: DoF 0, 1 redundant; the crank's qpos at the reference pose is its ref, 30 deg."""
    path = tmp_path / "details.xml"
    path.write_text(MJCF)
    mech = pinmob.load(path)
    assert list(mech.configurations) == ["reference", "bent"] and mech.actuated == ("crank",)
    doc = pinmob.analyze(mech).to_dict()
    assert doc["joint_values"]["crank"] == pytest.approx(np.radians(30), abs=1e-12)  # MuJoCo's qpos
    nv, rows, rank, gap = mujoco_counts(path, doc["joint_values"])
    assert gap < 1e-12 and (doc["mechanism_dof"], doc["redundant_constraints"]) == (nv - rank, rows - rank) == (0, 1)
    with pytest.raises(pinmob.ClosureError, match="'bent'"):
        pinmob.analyze(mech, "bent")


def test_mjcf_refusals_are_one_line(tmp_path, capsys):
    """A file MuJoCo cannot compile gives one line, exit 2 (no crash)."""
    bad = tmp_path / "bad.xml"
    bad.write_text(MJCF.replace('ref="30"', 'ref="x"'))
    assert main(["analyze", str(bad)]) == 2
    assert capsys.readouterr().err.startswith(f"pinmob: error: {bad}: MuJoCo cannot compile it")


def test_floating_base_is_held_when_judging_the_actuation(capsys):
    """Cassie's pelvis is a free joint: with its 6 DoF held (said in the verdict) and every hinge locked, only
    the two Achilles rods' spins remain, idle (by hand, above); without holding the base 6 more would."""
    path = DATA / "pinocchio_closed_chain" / "closed_chain.xml"
    mech = pinmob.load(path)
    joints = [n for n in list(mech.model.names)[1:] if mech.model.joints[mech.model.getJointId(n)].nv == 1]
    assert main(["analyze", str(path), "--actuated", ",".join(joints), "--json"]) == 0
    act = json.loads(capsys.readouterr().out)["actuation"]
    assert act["base_held"] == ["#0"] and act["locked_dof"] == 2 and act["idle_dof"] == 2  # the rods' spins
    assert main(["analyze", str(path), "--actuated", ",".join(joints)]) == 0
    assert "(floating base '#0' held: 6 DoF of the base's own)" in capsys.readouterr().out


def test_show_html_for_mjcf_extended_urdf_and_bare_urdf(tmp_path, capsys):
    """show --html works on an MJCF, an Extended URDF and a bare onshape-to-robot URDF (none names a platform:
    the most mobile output frame is shown, and a note says so)."""
    (tmp_path / "robot.urdf").write_text(spherical_urdf())
    sources = [
        DATA / "menagerie_xarm7_hand" / "hand.xml",
        Path(__file__).parent / "data" / "fivebar" / "robot.yaml",
        tmp_path / "robot.urdf",
    ]
    for k, source in enumerate(sources):
        out = tmp_path / f"scene{k}.html"
        assert main(["show", str(source), "--html", str(out), "--steps", "2"]) == 0, source
        text = capsys.readouterr().out
        assert "names no platform: showing the motions of its output frame" in text and out.stat().st_size > 10_000


def test_one_joint_welded_to_the_world(tmp_path):
    """nv = 1 (Pinocchio gives its Jacobians as (6,) vectors): a hinge welded to the world. By hand 6 rows on
    one column, rank 1: DoF 0, 5 redundant; MuJoCo's efc_J says the same."""
    path = tmp_path / "one.xml"
    path.write_text('<mujoco><worldbody><body name="a"><joint name="j"/><geom size=".1"/></body></worldbody>'
                    '<equality><weld body1="a"/></equality></mujoco>')  # fmt: skip
    doc = pinmob.analyze(pinmob.load(path)).to_dict()
    nv, rows, rank, gap = mujoco_counts(path, doc["joint_values"])
    assert gap < 1e-12 and (doc["mechanism_dof"], doc["redundant_constraints"]) == (nv - rank, rows - rank) == (0, 5)


def test_one_joint_pinned_on_its_own_axis(tmp_path):
    """nv = 1 with a motion left: a hinge (axis z) pinned to the world at a point of its axis. By hand the pin's 3
    rows are zero on the one column: DoF 1, 3 redundant, and the turn moves no joint centre and no closure point
    (idle 1). (Pinocchio's (6,) Jacobian for nv = 1 once broke the idle split.)"""
    path = tmp_path / "pinned.xml"
    path.write_text('<mujoco><worldbody><body name="a"><joint name="j"/><geom size=".1"/></body></worldbody>'
                    '<equality><connect body1="a" anchor="0 0 0.1"/></equality></mujoco>')  # fmt: skip
    doc = pinmob.analyze(pinmob.load(path)).to_dict()
    assert (doc["mechanism_dof"], doc["redundant_constraints"], doc["idle_dof"]) == (1, 3, 1)


def test_cassie_limits_and_reference_are_mujocos():
    """Cassie's knee (ref -45 deg, range -164..-37 deg) and tarsus (ref 58, range 50..170): q is MuJoCo's qpos,
    so the limits are the file's range (not shifted by -ref) and the joints outside their limits at the
    reference pose are those MuJoCo's qpos0 puts outside its range (the feet, at 0 of -140..-30 deg)."""
    from pinmob.model.joints import outside_limits

    mech = pinmob.load(DATA / "pinocchio_closed_chain" / "closed_chain.xml")
    model = mech.model
    for name, ref, lo, hi in (("left-knee", -45, -164, -37), ("left-tarsus", 58, 50, 170)):
        i = model.joints[model.getJointId(name)].idx_q
        assert_allclose([model.lowerPositionLimit[i], model.upperPositionLimit[i]], np.radians([lo, hi]), atol=1e-12)
        assert_allclose(pinmob.analyze(mech).to_dict()["joint_values"][name], np.radians(ref), atol=1e-12)
    m = mujoco.MjModel.from_xml_path(str(DATA / "pinocchio_closed_chain" / "closed_chain.xml"))
    theirs = {
        m.joint(j).name
        for j in range(m.njnt)
        if m.jnt_limited[j] and not m.jnt_range[j, 0] <= m.qpos0[m.jnt_qposadr[j]] <= m.jnt_range[j, 1]
    }
    ours = outside_limits(model, pinmob.Configuration(mech, "reference").q)
    assert {entry.split(" ")[0] for entry in ours} == theirs and len(theirs) == 4


def test_actuated_and_joints_on_the_command_line(tmp_path, capsys):
    """A URDF says nothing of its motors: --actuated names them (j1 drives the spherical four-bar's one DoF:
    valid; j1 and j4 over-determine it, one of them implied). --joints sets joint values, solving the others
    when they do not close as given; a malformed item is one line, exit 2."""
    path = tmp_path / "robot.urdf"
    path.write_text(spherical_urdf())
    assert main(["analyze", str(path), "--actuated", "j1", "--joints", "j1=0.2", "--json"]) == 0
    doc = json.loads(capsys.readouterr().out)
    assert doc["actuation"]["valid"] and doc["joint_values"]["j1"] == 0.2
    assert doc["closed_configuration"]["residual"] < 1e-12
    assert main(["analyze", str(path), "--actuated", "j1,j4", "--json"]) == 0
    act = json.loads(capsys.readouterr().out)["actuation"]
    assert not act["valid"] and act["redundant_actuators"] == 1
    for bad in ("j1", "j1=x", "j1=1,,j4=2", "=1"):
        assert main(["analyze", str(path), "--joints", bad]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and "is not name=value" in err


@pytest.mark.parametrize(
    ("values", "rank", "other"),
    [
        ([1.0, 3e-6], 2, (1,)),  # the counted 3e-6 is within 10x above the tolerance 1e-6: rank 1 is possible
        ([1.0, 3e-7], 1, (2,)),  # the dropped 3e-7 is within 10x below it: rank 2 is possible
        ([1.0, 2e-6, 5e-7], 2, (1, 3)),  # both close
    ],
)
def test_an_ambiguous_rank_names_the_count_the_geometry_may_mean(values, rank, other):
    """Hand-chosen singular values around a tolerance of 1e-6 (the margin is a factor 10 either side)."""
    from pinmob.analysis.ambiguity import ambiguous_rank

    amb = ambiguous_rank("closure rank", np.array(values), 1e-6, rank)
    assert amb is not None and amb.alternatives == other
    assert f"the rank is {rank} as counted, {' or '.join(map(str, other))} if the geometry" in str(amb)
    assert ambiguous_rank("closure rank", np.array([1.0, 1e-3, 1e-12]), 1e-6, 2) is None  # a clear gap
