"""MJCF tendon equalities and actuators on tendons, sites, slider-cranks and ball joints, as MuJoCo reads them.

Truth is MuJoCo's own: the rank of its equality rows (``efc_J``) and of those rows stacked with its
actuators' moment arms (``actuator_moment``) at the configuration pinmob reports (whose ``joint_values``
must close MuJoCo's equalities: ``efc_pos``), and MuJoCo's tendon and actuator lengths (their derivatives
along Pinocchio's joint rates are the rows pinmob holds). The fixtures in ``tests/data/tendons`` are
written for these tests; the counts by hand are in :data:`HAND`.
"""

from __future__ import annotations

import pickle
import re
import warnings
from pathlib import Path
from typing import Any

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose
from test_third_party import mujoco_counts, mujoco_locked, nout

import pinmob
from pinmob.io.mjcf import MomentActuator, SpatialTendon, q_to_qpos

DATA = Path(__file__).parent / "data" / "tendons"

#: file -> (mechanism DoF, redundant closure equations, actuators pinmob holds, motions left with them locked):
HAND: dict[str, tuple[int, int, int, int]] = {
    # two four-bar fingers (driver, coupler, follower; a connect: 2 of its 3 rows independent) carrying a
    # fingertip: 8 joints; rows: 2 x 2 + each fingertip follows its driver (a fixed tendon held at its length,
    # 2) + the left driver follows the right one (a polynomial between fixed tendons, 1) = 7: DoF 1, the
    # connects' out-of-plane rows redundant (2). The motor on the right driver holds it: nothing left.
    "gripper.xml": (1, 2, 1, 0),
    # three fingers of three hinges (9): distal follows middle (3 couplings, finger 3's through a spatial
    # tendon over its back) and finger 3's flexor follows finger 2's (1): DoF 5. Held: finger 1's flexor and
    # tip pull (its 2 DoF), finger 2's flexor and finger 3's knuckle motor (2 of fingers 2 and 3's 3): 1 left.
    "cable_hand.xml": (5, 0, 4, 1),
    # a slider-crank (3 joints, a connect: 2 rows, the out-of-plane one redundant), a ball wrist (3) and a free
    # puck pinned at its centre (6 - 3): DoF 1 + 3 + 3 = 7. Held: the slider-crank transmission (the
    # crank's DoF), the wrist's motor about z (1 of 3), the push at the puck's edge (1 of its 3 turns): 4 left.
    # The adhesion actuator acts through contacts: left out (MuJoCo's row is zero without contact).
    "transmissions.xml": (7, 1, 3, 4),
}


def _load(path: Path) -> pinmob.Mechanism:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return pinmob.load(path)


def _moved(mech: pinmob.Mechanism, seed: int) -> np.ndarray:
    """A closed configuration away from MuJoCo's reference: the reference moved at random, then projected."""
    rng = np.random.default_rng(seed)
    q0 = np.array(mech.configurations["reference"].vector)
    q = pin.integrate(mech.model, q0, rng.uniform(-0.3, 0.3, mech.model.nv))
    return pinmob.project(mech, q).q


@pytest.mark.parametrize("seed", [None, 1, 2])
@pytest.mark.parametrize("name", sorted(HAND))
def test_counts_agree_with_mujoco(name, seed):
    """pinmob's DoF, redundant equations and motions left with the actuators locked are MuJoCo's
    (``nv - rank [efc_J equality rows]``, ``nv - rank [those rows; actuator_moment]``) and the count by hand,
    at MuJoCo's reference and at two other closed configurations (where the tendon couplings' polynomials
    and the moment arms have changed), whose joint values close MuJoCo's equalities."""
    path = DATA / name
    mech = _load(path)
    q = "reference" if seed is None else _moved(mech, seed)
    doc = pinmob.analyze(mech, q).to_dict()
    nv, rows, rank, gap = mujoco_counts(path, doc["joint_values"])
    _, left = mujoco_locked(path, doc["joint_values"])
    assert gap < 1e-9  # the tendon equalities hold in MuJoCo at pinmob's configuration
    dof, redundant, held, locked = HAND[name]
    act = doc["actuation"]
    assert (doc["mechanism_dof"], doc["redundant_constraints"]) == (nv - rank, rows - rank) == (dof, redundant)
    assert act["locked_dof"] == left == locked
    assert len(act["actuated"]) + len(act["actuated_tendons"]) == held


def _mujoco_rows(path: Path, model: pin.Model, q: np.ndarray) -> tuple[np.ndarray, np.ndarray, Any, Any]:
    """MuJoCo's tendon Jacobians and actuator moments (dense, on ``qvel``) at Pinocchio's q; its model and data."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    d.qpos[:] = q_to_qpos(model, q)
    mujoco.mj_forward(m, d)
    ten = np.zeros((m.ntendon, m.nv))
    mujoco.mju_sparse2dense(ten, d.ten_J, m.ten_J_rownnz, m.ten_J_rowadr, m.ten_J_colind)
    moments = np.zeros((nout(m), m.nv))
    mujoco.mju_sparse2dense(moments, d.actuator_moment, d.moment_rownnz, d.moment_rowadr, d.moment_colind)
    return ten, moments, m, d


@pytest.mark.parametrize("name", ["cable_hand.xml", "transmissions.xml"])
def test_held_rows_are_mujocos_on_pinocchios_rates(name):
    """Each row pinmob closes on or holds (a spatial tendon's, an actuator's) is MuJoCo's (``ten_J``,
    ``actuator_moment``) on the same motion: ``row . v`` equals MuJoCo's ``row . qvel`` for the ``qvel`` that
    MuJoCo's own ``mj_differentiatePos`` finds between the configurations ``pin.integrate`` reaches along
    ``-v`` and ``+v``, at a random configuration (a free joint's linear rate is in the body frame in Pinocchio
    and in the world in MuJoCo). Spatial tendons' rows are also the derivatives of MuJoCo's ``ten_length``."""
    path = DATA / name
    mech = _load(path)
    model, data = mech.model, mech.model.createData()
    rng = np.random.default_rng(0)
    q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
    pin.computeJointJacobians(model, data, q)
    ten, moments, m, d = _mujoco_rows(path, model, q)
    mine, theirs, lengths = [], [], []
    for c in mech.closures:
        for t in c.tendons:
            if isinstance(t, SpatialTendon):
                mine.append(t.length(model, data)[1])
                theirs.append(ten[t.index])
                lengths.append(t.index)
    for a in mech.actuated_tendons:
        if isinstance(a, MomentActuator):
            mine.append(a.rate_row(model, q))
            theirs.append(moments[a.index])
    assert len(mine) >= 3
    eps = 1e-6
    for _ in range(3):
        v = rng.normal(size=model.nv)
        ends = [q_to_qpos(model, pin.integrate(model, q, s * eps * v)) for s in (-1, 1)]
        qvel = np.zeros(m.nv)
        mujoco.mj_differentiatePos(m, qvel, 2 * eps, ends[0], ends[1])
        assert_allclose(np.array(mine) @ v, np.array(theirs) @ qvel, rtol=1e-6, atol=1e-9)
        rates = []
        for qpos in ends if lengths else ():
            d.qpos[:] = qpos
            mujoco.mj_forward(m, d)
            rates.append(np.array(d.ten_length[lengths]))
        if lengths:
            assert_allclose(np.array(mine[: len(lengths)]) @ v, (rates[1] - rates[0]) / (2 * eps), rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("name", ["transmissions.xml", "refsite.xml", "refsite_turning.xml", "orientation.xml"])
def test_held_actuator_lengths_are_mujocos_and_their_rows_its_derivatives(name):
    """An actuator on a slider-crank, a ball joint or a site with a reference site holds MuJoCo's
    ``actuator_length``; the row of the held closure is its derivative along Pinocchio's joint rates (central
    differences of MuJoCo's own length between the configurations ``pin.integrate`` reaches along ``-v`` and
    ``+v``), at random configurations (the ball turned away from its zero, where MuJoCo's moment arms, ``gear``,
    are not the length's derivative; the reference site turning and the sites' relative rotation away from the
    identity, where MuJoCo's moment is not it either). An orientation servo (one of MuJoCo's multi-output actuators)
    holds its three expmap components, each at its own output (``actuator_outadr``), and the actuators after it
    their own outputs' lengths and gears. Sites without a reference site and free joints have no length to hold.
    On the old code the orientation file was not loaded (IndexError: pinmob read ``nu`` controls as actuators)."""
    path = DATA / name
    mech = _load(path)
    model, data = mech.model, mech.model.createData()
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)

    def mujoco_lengths(q: np.ndarray) -> np.ndarray:
        d.qpos[:] = q_to_qpos(model, q)
        mujoco.mj_forward(m, d)
        return d.actuator_length.copy()

    held = {a.name: a.driven_tendon(model) for a in mech.actuated_tendons}
    expected = {
        "transmissions.xml": {"engine", "wrist_twist"},
        "refsite.xml": {"reach"},
        "refsite_turning.xml": {"slide", "turn"},
        "orientation.xml": {f"{s}[{k}]" for s in ("wrist_servo", "cup_servo") for k in range(3)} | {"elbow_spin"},
    }[name]
    assert {k for k, t in held.items() if t is not None} == expected
    rng = np.random.default_rng(3)
    eps = 1e-6
    for _ in range(3):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        pin.forwardKinematics(model, data, q)
        for a in mech.actuated_tendons:
            tendon = held[a.name]
            if tendon is None:
                continue
            base, _, part = a.name.partition("[")  # an orientation servo's k-th output: 'name[k]'
            out = int(m.actuator_outadr[m.actuator(base).id]) + (int(part[:-1]) if part else 0)  # MuJoCo's row
            length, row = tendon.length(model, data)
            assert length == pytest.approx(mujoco_lengths(q)[out], abs=1e-12)
            v = rng.normal(size=model.nv)
            ends = [mujoco_lengths(pin.integrate(model, q, s * eps * v))[out] for s in (-1, 1)]
            assert row @ v == pytest.approx((ends[1] - ends[0]) / (2 * eps), rel=1e-6, abs=1e-9)


def test_what_is_left_out_is_said_in_one_warning(capsys):
    """A tendon limit (even a narrow one: MuJoCo's one-sided constraint) and an adhesion actuator are named in
    one warning line each file; the others load without a word."""
    for name, said in [("gripper.xml", "stop [-0.0001, 0.0001]"), ("transmissions.xml", "stick on bodies")]:
        with pytest.warns(UserWarning) as record:
            pinmob.load(DATA / name)
        lines = [str(r.message) for r in record if "left out" in str(r.message)]
        assert len(lines) == 1 and said in lines[0]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pinmob.load(DATA / "cable_hand.xml")


def test_a_mechanism_with_spatial_tendons_pickles():
    """A Dask worker's copy (pickled) holds the same rows: MuJoCo's model goes with it, its data is remade."""
    mech = _load(DATA / "cable_hand.xml")
    copy = pickle.loads(pickle.dumps(mech))
    a, b = (pinmob.analyze(x, "reference").to_dict()["actuation"] for x in (mech, copy))
    assert a == b and a["locked_dof"] == HAND["cable_hand.xml"][3]


def test_a_narrow_tendon_limit_is_no_coupling(tmp_path):
    """A fixed tendon with a narrow ``limited`` range (how some hands couple a finger's last two joints) is a
    one-sided constraint in MuJoCo, absent from its equality rows: no closure, and the warning says so before
    the file is refused for having no loop."""
    path = tmp_path / "finger.xml"
    path.write_text(
        '<mujoco><worldbody><body name="a"><joint name="j1" axis="0 1 0"/><geom size="0.01"/>'
        '<body name="b" pos="0.05 0 0"><joint name="j0" axis="0 1 0"/><geom size="0.01"/></body></body></worldbody>'
        '<tendon><fixed name="c" limited="true" range="-0.001 0.001"><joint joint="j1" coef="1"/>'
        '<joint joint="j0" coef="-1"/></fixed></tendon></mujoco>'
    )
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    assert d.nefc == 0  # MuJoCo: no constraint row at qpos0 (the length is inside the range)
    with pytest.warns(UserWarning, match=r"left out: tendon limits \(c \[-0.001, 0.001\]"):
        with pytest.raises(pinmob.MechanismFileError, match="no loop to analyse"):
            pinmob.load(path)


def _scaled(text: str, k: float) -> str:
    """The MJCF text with every length (``pos``, ``fromto``, ``size``, ``anchor``, ``cranklength``) times k."""

    def lengths(match: re.Match[str]) -> str:
        return f'{match.group(1)}="{" ".join(repr(float(v) * k) for v in match.group(2).split())}"'

    return re.sub(r'\b(pos|fromto|size|anchor|cranklength)="([^"]*)"', lengths, text)


@pytest.mark.parametrize("name", sorted(HAND))
def test_answers_do_not_depend_on_the_unit_of_length(tmp_path, name):
    """The same fixtures in millimetres and in kilometres give the same counts (a spatial tendon's row is a
    length per rate, divided by L like every length; a fixed tendon over hinges couples angles)."""
    counts = set()
    for k in (1.0, 1e3, 1e-3):
        path = tmp_path / f"{k}_{name}"
        path.write_text(_scaled((DATA / name).read_text(), k))
        doc = pinmob.analyze(_load(path), "reference").to_dict()
        counts.add((doc["mechanism_dof"], doc["redundant_constraints"], doc["actuation"]["locked_dof"]))
    dof, redundant, _, locked = HAND[name]
    assert counts == {(dof, redundant, locked)}


@pytest.mark.parametrize("name", ["cable_hand.xml", "gripper.xml"])
def test_answers_do_not_depend_on_where_the_mechanism_stands(tmp_path, name):
    """The fixture moved 10 m away and turned (its bodies inside one moved body) gives the same counts."""
    text = (DATA / name).read_text()
    moved = text.replace("<worldbody>", '<worldbody><body name="stand" pos="10 -3 2" euler="0.3 -0.2 0.5">', 1)
    path = tmp_path / name
    path.write_text(moved.replace("</worldbody>", "</body></worldbody>", 1))
    doc = pinmob.analyze(_load(path), "reference").to_dict()
    dof, redundant, _, locked = HAND[name]
    assert (doc["mechanism_dof"], doc["redundant_constraints"], doc["actuation"]["locked_dof"]) == (
        dof,
        redundant,
        locked,
    )
