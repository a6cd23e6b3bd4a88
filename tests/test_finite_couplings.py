"""Finite mobility of MJCF mechanisms with joint couplings, tendon couplings and tendon actuators.

Truth is sampled from MuJoCo alone, not from pinmob's finite analysis: starts ``q + r u`` (u a random unit
vector of joint values) are projected onto MuJoCo's closed set by Gauss-Newton (minimum-norm steps on its
equality residuals ``efc_pos`` and Jacobian ``efc_J`` after ``mj_forward``; with the actuators held, also
on ``actuator_length - actuator_length(q)`` and its central differences along each of MuJoCo's joint rates:
``actuator_moment`` is the length's derivative only in part, not on a ball turned away from its zero or on a
site whose reference site turns or sits turned from it), and the local dimension is the number
of directions the projected displacements span (singular values of the displacements over the radius;
the closed set's curvature, O(r), and a shaky direction's leftover, far below it, are no dimension). The
counts by hand are in :data:`CASES`.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from numpy.polynomial import Polynomial
from test_mjcf_tendons import _scaled
from test_third_party import mujoco_joint, mujoco_model, nout

import pinmob
from pinmob.analysis.finite.loop_screws import mechanism_loops
from pinmob.analysis.finite.verdicts import Verdict
from pinmob.cli import main

DATA = Path(__file__).parent / "data"

#: file -> (finite DoF of the closed chain, with the file's actuators held), by hand:
CASES: dict[str, tuple[int, int]] = {
    # two four-bar fingers, each fingertip following its driver (fixed-tendon equalities), the left driver
    # following the right one through l = r + 0.5 r^2 (a tendon equality with a quadratic): 1 DoF; the motor
    # on the right driver holds it
    "tendons/gripper.xml": (1, 0),
    # Robotiq 2F-85: the drivers coupled (q_r = q_l, <equality joint>), each finger a four-bar (driver,
    # coupler, spring link, follower) closed by a connect: 1 + 1 + 1 DoF (the spring links' unactuated
    # motions); its one actuator on the fixed tendon split = (q_r + q_l) / 2 holds the drivers: 2
    "third_party/menagerie_robotiq_2f85/2f85.xml": (3, 2),
    # Franka hand: two slides, finger 1 = finger 2 (<equality joint>): 1 DoF; the actuator on the tendon
    # split = (f1 + f2) / 2 holds it
    "third_party/menagerie_franka_hand/hand.xml": (1, 0),
    # xArm7 hand: one DoF through the drivers' couplings; the actuator on the drivers' tendon holds it
    "third_party/menagerie_xarm7_hand/hand.xml": (1, 0),
    # see the file: 4 DoF to first order, b and c = -d blocked at second order (a = +-b^2, t1 = +-t2^2):
    # 2 DoF (f, g); the actuator on the tendon f + g holds one
    "couplings/shaky_couplings.xml": (2, 1),
    # see the file: per leg 19 joint rates - 3 connects x 3 - 1 coupling = 9 (hip 3, knee, ankle 2, the 3 rods'
    # spins); held (hips and cranks), the spins remain
    "couplings/humanoid_legs.xml": (18, 6),
    # see the file: tendons straight between sites; 4 DoF to first order, c blocked at second order (its cable
    # held at its shortest): 3; the flexor's motor held: 2
    "couplings/site_tendons.xml": (3, 2),
    # see the file: 9 hinges, 4 couplings (two distal joints following the middle ones, finger 3's distal cable
    # held at its length, flex3 following flex2 over their pulleys): 5 DoF; held: knuckle3 and the flexors of
    # fingers 1 and 2 (on tendons over pulleys; flex3 follows flex2): 2 (tip_pull1, on a site, is not held;
    # MuJoCo's length of a site transmission without a reference site is 0: no constraint either)
    "tendons/cable_hand.xml": (5, 2),
    # see the file: the slider-crank loop (1), the ball-jointed wrist (3), the puck pinned at its centre (3): 7;
    # held: the slider-crank actuator holds the loop (its slider's length), the motor on the ball holds the
    # wrist's rotation vector along its gear (2 left), the push on the puck's site (no reference site) has no
    # length to hold (MuJoCo's is 0): 0 + 2 + 3 = 5
    "tendons/transmissions.xml": (7, 5),
    # see the file: a two-link arm (the dial follows the elbow): 2; its tip site held along x relative to the
    # base's reference site (MuJoCo's length of a site transmission with a refsite): 1
    "tendons/refsite.xml": (2, 1),
    # see the file: rocker, shoulder, elbow, twist (the dial follows the elbow): 4; the tip held along a
    # translational and a rotational gear relative to the rocker's turning reference site: 2
    "tendons/refsite_turning.xml": (4, 2),
    # see the file: the rocker and the hinge pair: 2; the site's x in the rocker's frame held locks the rocker: 1
    "tendons/rocker.xml": (2, 1),
    # see the file: two balls, the hinge pair, the cup's ball: 10; held: the orientation servos hold the wrist and
    # the cup (3 each), the motor one axis of the second ball, the PID servo the hinge pair: 2
    "tendons/orientation.xml": (10, 2),
}
#: Fixtures with actuators the finite analysis does not hold (on sites without a reference site): by name.
UNHELD = {"tendons/cable_hand.xml": ("tip_pull1",), "tendons/transmissions.xml": ("push",)}

#: Perturbation radius [rad or m] and directions the displacements must reach to count (over the radius).
RADIUS = 1e-3
SPAN = 0.02


def _load(path: Path) -> pinmob.Mechanism:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return pinmob.load(path)


class MujocoClosure:
    """MuJoCo's equality residuals (and, held, its actuators' lengths) at joint values, with their Jacobian."""

    def __init__(self, path: Path, qpos: np.ndarray, held: bool):
        self.m = mujoco_model(path)
        self.d = mujoco.MjData(self.m)
        self.held = held
        self.lengths = self._forward(qpos)[2] if held else None

    def _forward(self, qpos: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(equality residuals, their rows on qvel, the actuators' lengths) at qpos."""
        m, d = self.m, self.d
        d.qpos[:] = qpos
        mujoco.mj_forward(m, d)
        eq = np.flatnonzero(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
        return d.efc_pos[eq].copy(), d.efc_J[: d.nefc * m.nv].reshape(d.nefc, m.nv)[eq].copy(), d.actuator_length.copy()

    def residual(self, qpos: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(residual, Jacobian on MuJoCo's qvel) at qpos; held, the lengths' rows by central differences."""
        if not self.held:
            return self._forward(qpos)[:2]
        rows = np.zeros((nout(self.m), self.m.nv))
        for k in range(self.m.nv):
            step = np.zeros(self.m.nv)
            step[k] = 1e-7
            ends = [self._forward(self.step(qpos, s * step))[2] for s in (-1, 1)]
            rows[:, k] = (ends[1] - ends[0]) / 2e-7
        r, jac, lengths = self._forward(qpos)
        return np.concatenate([r, lengths - self.lengths]), np.vstack([jac, rows])

    def project(self, qpos: np.ndarray, iterations: int = 200) -> np.ndarray | None:
        """Gauss-Newton with minimum-norm steps onto the zero set; None when it does not close."""
        q = qpos.copy()
        for _ in range(iterations):
            r, jac = self.residual(q)
            if np.abs(r).max(initial=0.0) < 1e-13:
                return q
            mujoco.mj_integratePos(self.m, q, -np.linalg.lstsq(jac, r, rcond=1e-10)[0], 1.0)
        return None

    def step(self, qpos: np.ndarray, dv: np.ndarray) -> np.ndarray:
        """qpos moved by the joint rates dv (MuJoCo's ``mj_integratePos``: quaternions stay unit)."""
        q = qpos.copy()
        mujoco.mj_integratePos(self.m, q, dv, 1.0)
        return q

    def difference(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """The joint rates taking a to b in unit time (``mj_differentiatePos``)."""
        out = np.zeros(self.m.nv)
        mujoco.mj_differentiatePos(self.m, out, 1.0, a, b)
        return out


def sampled_dimension(path: Path, qpos: np.ndarray, held: bool, seed: int = 0) -> tuple[int, np.ndarray]:
    """(local dimension, singular values of the displacements / radius) of MuJoCo's closed set near qpos.

    Starts and displacements in joint rates (``mj_integratePos``, ``mj_differentiatePos``: ball joints too).
    """
    closure = MujocoClosure(path, qpos, held)
    r0, _ = closure.residual(qpos)
    assert np.abs(r0).max(initial=0.0) < 1e-9, "pinmob's configuration does not close MuJoCo's equalities"
    rng = np.random.default_rng(seed)
    moves = []
    nv = closure.m.nv
    for _ in range(3 * nv + 10):
        u = rng.normal(size=nv)
        end = closure.project(closure.step(qpos, RADIUS * u / np.linalg.norm(u)))
        assert end is not None
        moves.append(closure.difference(qpos, end) / RADIUS)
    s = np.linalg.svd(np.array(moves) / np.sqrt(len(moves)), compute_uv=False)
    return int(np.count_nonzero(s > SPAN)), s


def _qpos(path: Path, mech: pinmob.Mechanism, q: np.ndarray) -> np.ndarray:
    """MuJoCo's qpos of pinmob's q, by joint name (the report's joint values)."""
    m = mujoco_model(path)
    qpos = np.zeros(m.nq)
    for name, value in pinmob.analyze(mech, q).to_dict()["joint_values"].items():
        adr = int(m.jnt_qposadr[mujoco_joint(m, name)])
        qpos[adr : adr + np.size(value)] = value
    return qpos


def _moved(mech: pinmob.Mechanism, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    q0 = np.array(mech.configurations["reference"].vector)
    with warnings.catch_warnings():  # outside the joints' ranges: no matter to the closed set's dimension
        warnings.simplefilter("ignore")
        return pinmob.project(mech, pin.integrate(mech.model, q0, rng.uniform(-0.2, 0.2, mech.model.nv))).q


@pytest.mark.parametrize(
    ("name", "moved"), [(n, False) for n in sorted(CASES)] + [(n, True) for n in sorted(CASES) if "shaky" not in n]
)
def test_finite_dof_with_couplings_is_mujocos_sampled_dimension(name, moved):
    """The closed chain's finite DoF, free and with the actuators held, = the local dimension of MuJoCo's closed
    set sampled near q (free: its equalities; held: and its actuators' lengths) = the count by hand; at MuJoCo's
    reference and at a closed configuration moved away from it (not for the shaky file: q is isolated there)."""
    path = DATA / name
    mech = _load(path)
    q = _moved(mech, 3) if moved else np.array(mech.configurations["reference"].vector)
    report = pinmob.analyze(mech, q, finite=True)
    fin = report.finite
    qpos = _qpos(path, mech, q)
    free, s_free = sampled_dimension(path, qpos, held=False)
    locked, s_locked = sampled_dimension(path, qpos, held=True)
    assert (free, locked) == CASES[name], (s_free, s_locked)
    assert fin.finite_mechanism_dof == free, fin.free.notes
    assert fin.finite_dof_locked == locked, fin.locked.notes if fin.locked else None
    assert fin.unheld == UNHELD.get(name, ())


def test_shaky_couplings_are_blocked_at_order_two():
    """a = +-b^2 and t1 = +-t2^2 pass order 1 (rows da = 0, dt1 = 0) and fail order 2: each motion is shaky,
    blocked at order 2 (the polynomials' second derivatives, exact), and f, g are finite."""
    fin = pinmob.analyze(_load(DATA / "couplings" / "shaky_couplings.xml"), finite=True).finite
    verdicts = {frozenset(m.joints): (m.verdict, m.order) for m in fin.free.internal}
    assert verdicts == {
        frozenset("b"): (Verdict.BLOCKED, 2),
        frozenset("cd"): (Verdict.BLOCKED, 2),
        frozenset("f"): (Verdict.FINITE, None),
        frozenset("g"): (Verdict.FINITE, None),
    }


def test_a_coupling_over_a_pulley_is_decided_by_closed_samples_alone(capsys):
    """A tendon wrapping a pulley geom has no written higher derivatives: the cable hand (whose f3_follows_f2 was
    refused, exit 2) is decided by the closed samples, and the report says so and that the order conditions were
    not used, naming the coupling and its tendons (f3_distal, straight between two sites, is not among them);
    the flexors on those tendons are held (MuJoCo's count above), the site actuator is named as not held."""
    assert main(["analyze", str(DATA / "tendons" / "cable_hand.xml"), "--finite"]) == 0
    out = capsys.readouterr().out
    decided = [line for line in out.splitlines() if "decided by closed samples near q" in line]
    assert len(decided) == 2 and all("alone: the order conditions were not used" in line for line in decided)
    assert all("coupling 'f3_follows_f2' on tendons 'flex3', 'flex2'" in line for line in decided)
    assert all("f3_distal" not in line for line in decided)
    assert "coupling 'actuator flexor1' on tendon 'flex1'" in decided[1]
    assert "actuators held (f3_mcp, flexor1, flexor2): mechanism 2 DoF finite" in out
    assert "actuator(s) tip_pull1 not held (on a site without a reference site" in out
    fin = pinmob.analyze(_load(DATA / "tendons" / "cable_hand.xml"), finite=True).finite
    assert fin.to_dict()["conditions_not_written"] == [
        "coupling 'f3_follows_f2' on tendons 'flex3', 'flex2' (wrapping geoms or over a pulley)"
    ]
    assert all(m.verdict is Verdict.FINITE for m in fin.free.internal)


def test_json_gives_no_order_bound_or_tolerance_where_no_condition_was_written(capsys):
    """The cable hand's two sides are decided by closed samples alone (``conditions_not_written``, the text's "no
    higher-order conditions"): the JSON gives their order bound and tolerance as null. The gripper's conditions are
    written: each side's order bound is the one asked for, and the free side's tolerance the one the text prints.

    On the old code the cable hand's JSON said ``"order_bound": 4, "tolerance": 0.0`` and the held side had
    neither."""
    hand = str(DATA / "tendons" / "cable_hand.xml")
    assert main(["analyze", hand, "--finite", "--json"]) == 0
    fin = json.loads(capsys.readouterr().out)["finite"]
    for side in (fin, fin["locked"]):
        assert side["conditions_not_written"] and side["evidence"]
        assert (side["order_bound"], side["tolerance"]) == (None, None)
    gripper = str(DATA / "tendons" / "gripper.xml")
    assert main(["analyze", gripper, "--finite", "--finite-order", "3", "--json"]) == 0
    fin = json.loads(capsys.readouterr().out)["finite"]
    assert main(["analyze", gripper, "--finite", "--finite-order", "3"]) == 0
    text = capsys.readouterr().out
    for side in (fin, fin["locked"]):
        assert side["conditions_not_written"] == [] and side["order_bound"] == 3 and side["tolerance"] > 0
    assert f"higher-order conditions up to order 3 (tolerance {fin['tolerance']:.2e})" in text


def test_coupling_rows_derivatives_are_the_exact_polynomial_ones():
    """Each coupling row's jets = the derivatives at t = 0 of MuJoCo's equality along the joint curve
    ``q(t) = q + sum_i x^(i) t^i / i!``, composed exactly as polynomials in t (numpy) from MuJoCo's compiled
    definitions (``eq_data``'s polycoef, the fixed tendons' ``wrap_prm``, ``tendon_length0``): the gripper's
    quadratic mirror l = r + 0.5 r^2 and its fingertip couplings, away from the reference (r != 0)."""
    path = DATA / "tendons" / "gripper.xml"
    mech = _load(path)
    conf = pinmob.Configuration(mech, _moved(mech, 5))
    loops = mechanism_loops(conf)
    m = mujoco_model(path)
    qpos = _qpos(path, mech, conf.q)
    rng = np.random.default_rng(0)
    k = 4
    x = rng.normal(size=(k, loops.system.size))
    jets = loops.equations.jets(x)[:, -len(loops.couplings) :]
    curves = {}  # joint name -> q_j(t) as a polynomial in t (hinges: the rate is the coordinate's derivative)
    for j in range(m.njnt):
        name = m.joint(j).name
        iv = mech.model.joints[mech.model.getJointId(name)].idx_v
        coefs = [qpos[int(m.jnt_qposadr[j])]] + [x[i, iv] / np.prod(range(1, i + 2)) for i in range(k)]
        curves[name] = Polynomial(coefs)

    def length(t: int) -> Polynomial:
        adr, num = int(m.tendon_adr[t]), int(m.tendon_num[t])
        return sum(
            (m.wrap_prm[w] * curves[m.joint(int(m.wrap_objid[w])).name] for w in range(adr, adr + num)), Polynomial(0)
        )

    for c, row in enumerate(loops.couplings):
        e = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, row.name)
        t1, t2 = int(m.eq_obj1id[e]), int(m.eq_obj2id[e])
        poly = Polynomial(m.eq_data[e, :5])
        f = length(t1) - m.tendon_length0[t1]
        f = f - (poly(length(t2) - m.tendon_length0[t2]) if t2 >= 0 else poly.coef[0])
        exact = [f.deriv(n + 1)(0.0) for n in range(k)]
        np.testing.assert_allclose(jets[:, c], exact, rtol=1e-12, atol=1e-12, err_msg=row.name)


def test_site_tendon_rows_derivatives_are_mujocos():
    """Each tendon equality's row along ``q(t) = q + sum_i x^(i) t^i / i!`` (hinges): its derivatives of orders
    1..4 at t = 0 (times L: the rows of a length are divided by it) = those of MuJoCo's own residual ``efc_pos``
    along the same curve (``ten_length`` of tendons straight between sites, MuJoCo's polynomial), from a
    Chebyshev fit of degree 12 on t in [-0.05, 0.05]."""
    path = DATA / "couplings" / "site_tendons.xml"
    mech = _load(path)
    conf = pinmob.Configuration(mech, np.array(mech.configurations["reference"].vector))
    loops = mechanism_loops(conf)
    rng = np.random.default_rng(1)
    k = 4
    x = rng.normal(size=(k, loops.system.size))
    jets = loops.equations.jets(x)[:, -len(loops.couplings) :]
    closure = MujocoClosure(path, _qpos(path, mech, conf.q), held=False)
    m, d = closure.m, closure.d
    rate = np.zeros((k, m.nv))  # the curve on MuJoCo's qvel (hinges: qpos moves by qvel)
    for j in range(m.njnt):
        rate[:, int(m.jnt_dofadr[j])] = x[:, mech.model.joints[mech.model.getJointId(m.joint(j).name)].idx_v]
    qpos0 = _qpos(path, mech, conf.q)
    ts = 0.05 * np.cos(np.pi * (np.arange(40) + 0.5) / 40)
    values = []
    for t in ts:
        d.qpos[:] = qpos0 + sum(rate[i] * t ** (i + 1) / np.prod(range(1, i + 2)) for i in range(k))
        mujoco.mj_forward(m, d)
        values.append([d.efc_pos[np.flatnonzero(d.efc_id[: d.nefc] == e)[0]] for e in range(m.neq)])
    values = np.array(values)
    for c, row in enumerate(loops.couplings):
        e = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_EQUALITY, row.name)
        fit = np.polynomial.Chebyshev.fit(ts, values[:, e], 12)
        exact = [fit.deriv(n + 1)(0.0) for n in range(k)]
        np.testing.assert_allclose(jets[:, c] * mech.length_scale, exact, rtol=1e-5, atol=1e-9, err_msg=row.name)


def _verdicts(path: Path) -> tuple[int | None, int | None, tuple[tuple[str, int], ...]]:
    """(finite DoF, with the actuators held, the sorted (verdict, blocking order or 0) of every internal motion)."""
    fin = pinmob.analyze(_load(path), "reference", finite=True).finite
    verdicts = sorted((m.verdict.value, m.order or 0) for m in fin.free.internal)
    return fin.finite_mechanism_dof, fin.finite_dof_locked, tuple(verdicts)


@pytest.mark.parametrize(
    "name",
    [
        "couplings/site_tendons.xml",
        "tendons/gripper.xml",
        "tendons/cable_hand.xml",
        "tendons/refsite.xml",
        "tendons/refsite_turning.xml",
        "tendons/orientation.xml",
    ],
)
def test_finite_answers_do_not_depend_on_the_unit_of_length_or_placement(tmp_path, name):
    """The fixture in millimetres, in kilometres (its polynomial between lengths rescaled with them: the same
    mechanism), and moved 10 m away and turned: the same finite DoF and per-motion verdicts (a site path's rows
    are lengths, divided by L like every length)."""
    text = (DATA / name).read_text()
    answers = set()
    for k in (1.0, 1e3, 1e-3):
        path = tmp_path / f"{k}.xml"
        path.write_text(_scaled(text, k).replace('polycoef="0 1 3 0 0"', f'polycoef="0 1 {3 / k!r} 0 0"'))
        answers.add(_verdicts(path))
    moved = text.replace("<worldbody>", '<worldbody><body name="stand" pos="10 -3 2" euler="0.3 -0.2 0.5">', 1)
    path = tmp_path / "moved.xml"
    path.write_text(moved.replace("</worldbody>", "</body></worldbody>", 1))
    answers.add(_verdicts(path))
    assert len(answers) == 1, answers
    assert answers.pop()[:2] == CASES[name]


def test_actuators_held_at_their_lengths_are_named_together(capsys):
    """transmissions.xml: the slider-crank and the ball motor have MuJoCo lengths (held, decided by closed samples
    alone, named once with their reason), the push on a site without a reference site has none (named apart)."""
    assert main(["analyze", str(DATA / "tendons" / "transmissions.xml"), "--finite"]) == 0
    out = capsys.readouterr().out
    decided = [line for line in out.splitlines() if "decided by closed samples near q" in line]
    assert (
        len(decided) == 1 and "actuators 'engine', 'wrist_twist' held at their lengths (MuJoCo's length" in decided[0]
    )
    assert "actuator(s) push not held (on a site without a reference site" in out
    locked = pinmob.analyze(_load(DATA / "tendons" / "transmissions.xml"), finite=True).finite.to_dict()["locked"]
    assert [s.split(" (")[0] for s in locked["conditions_not_written"]] == [
        "actuator 'engine' held at its length",
        "actuator 'wrist_twist' held at its length",
    ]


def test_moment_arms_off_the_length_are_said(capsys):
    """rocker.xml: MuJoCo's moment arms of the site actuator are zero at q (the first-order actuation, as MuJoCo's
    rank, leaves 2 motions) while its length moves with the rocker (held at its length, 1 DoF: MuJoCo's sampled
    dimension above); the report says that the two rows differ. The actuators of gripper.xml (a fixed tendon) and
    transmissions.xml at its reference (a slider-crank, a ball at its zero) hold their lengths' derivatives: no
    such note."""
    assert main(["analyze", str(DATA / "tendons" / "rocker.xml"), "--finite"]) == 0
    out = capsys.readouterr().out
    assert "locked, 2 motion(s) remain" in out and "actuators held (aim): mechanism 1 DoF finite" in out
    assert "note: the moment arms MuJoCo gives actuator(s) aim at q" in out
    for name in ("gripper.xml", "transmissions.xml"):
        assert main(["analyze", str(DATA / "tendons" / name), "--finite"]) == 0
        assert "moment arms MuJoCo gives" not in capsys.readouterr().out
