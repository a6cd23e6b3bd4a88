"""The higher-order conditions against independent truth: Pinocchio's kinematics along curves.

- The Lie-bracket recursion (:mod:`pinmob.screw.lie`) gives the time derivatives of every body's
  spatial twist along a joint-space curve; here they are measured on Pinocchio's own Jacobians at
  configurations along a polynomial curve (a polynomial fit of ``J(q(t)) q'(t)``).
- The cut joints (:mod:`pinmob.analysis.finite.loop_screws`) must make the loop twists vanish to second order
  along a closed curve of each closure type: the curve is measured on the closed set (projections of a
  straight line, fitted), its first and second derivatives put into the loop equations.
- The order-2 conditions must agree with a second method: the second difference of Pinocchio's closure
  residual along a first-order motion, with its part in the range of the closure Jacobian removed
  (the part no joint acceleration can cancel), is zero exactly where the Lie-bracket forms vanish.
"""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from finite_cases import arm_closed_by, four_bar_flat
from numpy.testing import assert_allclose

import pinmob
from pinmob.analysis.chain.closed_chain import closed_chain
from pinmob.analysis.finite.higher_order import HigherOrder
from pinmob.analysis.finite.loop_screws import mechanism_loops
from pinmob.analysis.finite.tangent_cone import cone
from pinmob.assembly.residual import closure_residual
from pinmob.assembly.solver import solve
from pinmob.model.closure import make_closure
from pinmob.model.joints import short_difference
from pinmob.screw.algebra import shift_twists, twist_scaling
from pinmob.screw.lie import bracket


def test_bracket_is_pinocchios_motion_cross_product() -> None:
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=6), rng.normal(size=6)
    assert_allclose(bracket(a, b), (pin.Motion(a).cross(pin.Motion(b))).vector, atol=1e-14)


def _fit_derivatives(ts: np.ndarray, values: np.ndarray, count: int) -> np.ndarray:
    """Derivatives 0..count-1 at t = 0 of each column of ``values`` (len(ts), k), by a degree-6 fit."""
    coef = np.polynomial.polynomial.polyfit(ts, values, 6)
    return np.array([coef[i] * math.factorial(i) for i in range(count)])


def _body_twists(mech: pinmob.Mechanism, loops, data: pin.Data, q: np.ndarray, rate: np.ndarray) -> np.ndarray:
    """Every body's twist ``J_b(q) rate`` from Pinocchio's joint Jacobians, as the recursion expresses it (at the
    loops' reference point, scaled by L), stacked body after body."""
    model = mech.model
    pin.computeJointJacobians(model, data, q)
    rows = []
    for j in range(1, model.njoints):
        mask = np.zeros(model.nv)
        for k in model.supports[j][1:]:
            mask[model.joints[k].idx_v : model.joints[k].idx_v + model.joints[k].nv] = 1.0
        rows.append(shift_twists(np.array(data.J) @ (mask * rate), loops.reference) * twist_scaling(mech.length_scale))
    return np.concatenate(rows)


def _random_rates(loops, seed: int) -> np.ndarray:
    """Random joint-rate derivatives ``x^(1..4)`` (4, size): the joints' random, the cut joints' zero."""
    x = np.zeros((4, loops.system.size))
    x[:, : loops.nv] = np.random.default_rng(seed).normal(size=(4, loops.nv))
    return x


def _recursion(loops, x: np.ndarray, njoints: int) -> np.ndarray:
    """The body twists' derivatives ``V^(n)``, n = 0..3, from the bracket recursion (``V^(n) = support U^(n)``) along
    the joint-rate derivatives ``x`` (4, size), stacked as :func:`_body_twists` stacks them."""
    system = loops.system
    s, v = [system.screws], []
    for n in range(4):
        if n:
            s.append(sum(math.comb(n - 1, a) * bracket(v[a][system.body], s[n - 1 - a]) for a in range(n)))
        u = sum(math.comb(n, b) * s[b] * x[n - b][:, None] for b in range(n + 1))
        v.append(system.support @ u)
    return np.array([vn[1:njoints].ravel() for vn in v])


@pytest.mark.parametrize(("name", "config"), [("3-PUU", "generic"), ("Bennett", "generic"), ("3-UR5", "generic")])
def test_body_twist_derivatives_match_pinocchio(name: str, config: str) -> None:
    """``V_b^(n)``, n = 0..3, from the brackets equal the derivatives of ``J_b(q(t)) q'(t)`` (Pinocchio, fitted)."""
    mech = pinmob.load(name)
    conf = pinmob.Configuration(mech, config)
    loops = mechanism_loops(conf)
    nv, col = loops.nv, loops.columns
    x = _random_rates(loops, 1)
    model, data = mech.model, mech.model.createData()
    ts = np.linspace(-4e-3, 4e-3, 9)
    twists = []
    for t in ts:  # revolute and prismatic joints: q(t) = q + sum t^i / i! x^(i), exactly
        dq = sum(t ** (i + 1) / math.factorial(i + 1) * x[i, :nv] for i in range(4)) * col
        rate = sum(t**i / math.factorial(i) * x[i, :nv] for i in range(4)) * col
        twists.append(_body_twists(mech, loops, data, pin.integrate(model, conf.q, dq), rate))
    measured = _fit_derivatives(ts, np.array(twists), 4)
    # the recursion's body twists: V^(n) = support U^(n), the loop rows being differences of them
    computed = _recursion(loops, x, model.njoints)
    scale = np.abs(measured).max(axis=1, keepdims=True)
    assert_allclose(computed / scale, measured / scale, atol=2e-5)


def _chain_through(kind: str) -> tuple[pinmob.Mechanism, np.ndarray]:
    """An RX - ``kind`` - RY chain at a random configuration, its end frame welded (6d) to a ground frame there."""
    rng = np.random.default_rng(7)
    axis = rng.normal(size=3)
    joint = {
        "spherical": pin.JointModelSpherical(),
        "planar": pin.JointModelPlanar(),
        "helical": pin.JointModelHelicalUnaligned(axis / np.linalg.norm(axis), 0.04),
        "helical-x": pin.JointModelHX(-0.03),
        "translation": pin.JointModelTranslation(),
        "free-flyer": pin.JointModelFreeFlyer(),
    }[kind]
    model = pin.Model()
    parent = 0
    for name, j in (("r0", pin.JointModelRX()), ("j", joint), ("r2", pin.JointModelRY())):
        parent = model.addJoint(
            parent, j, pin.SE3(pin.rpy.rpyToMatrix(*rng.normal(size=3)), rng.normal(scale=0.1, size=3)), name
        )
    model.addFrame(pin.Frame("b", parent, pin.SE3(np.eye(3), rng.normal(scale=0.1, size=3)), pin.FrameType.OP_FRAME))
    q = pin.integrate(model, pin.neutral(model), rng.normal(size=model.nv))
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    model.addFrame(pin.Frame("a", 0, data.oMf[model.getFrameId("b")].copy(), pin.FrameType.OP_FRAME))
    closure = make_closure(model, "weld", "a", "b", "6d")
    return pinmob.Mechanism.from_model(model, [], name=kind, closures=[closure], length_scale=0.2), q


def _curve(model: pin.Model, q: np.ndarray, rate, ts: np.ndarray, steps: int = 400) -> list[np.ndarray]:
    """q(t) at the times ``ts`` (symmetric about 0) of the curve with velocity ``rate(t)`` (nv,) in Pinocchio's own
    joint velocity coordinates from q(0) = q: exponential midpoint steps (second order; 1e-5 apart)."""
    out = {}
    for sign in (1.0, -1.0):
        current, t = q.copy(), 0.0
        h = sign * float(np.max(np.abs(ts))) / steps
        marks = sorted((abs(u), u) for u in ts if np.sign(u) in (sign, 0.0))
        for _ in range(steps + 1):
            for a, u in marks:
                if abs(abs(t) - a) < abs(h) / 2:
                    out[u] = current.copy()
            current = pin.integrate(model, current, h * rate(t + h / 2))
            t += h
    return [out[u] for u in ts]


@pytest.mark.parametrize("kind", ["spherical", "planar", "helical", "helical-x", "translation", "free-flyer"])
def test_body_twist_derivatives_match_pinocchio_for_every_supported_joint(kind: str) -> None:
    """The bracket recursion on joints of several coordinates and of coupled screws (loop_screws.SUPPORTED_JOINTS
    beyond revolute and prismatic): ``V_b^(n)``, n = 0..3, against the derivatives of Pinocchio's ``J_b(q(t)) q'(t)``
    along a curve integrated in Pinocchio's velocity coordinates (a Lie group's q(t) is not q + a polynomial)."""
    mech, q = _chain_through(kind)
    conf = pinmob.Configuration(mech, q)
    loops = mechanism_loops(conf)
    nv, col = loops.nv, loops.columns
    x = _random_rates(loops, 3)
    model, data = mech.model, mech.model.createData()

    def rate(t: float) -> np.ndarray:
        return sum(t**i / math.factorial(i) * x[i, :nv] for i in range(4)) * col

    ts = np.linspace(-4e-3, 4e-3, 9)
    twists = []
    for t, qt in zip(ts, _curve(model, q, rate, ts)):
        twists.append(_body_twists(mech, loops, data, qt, rate(t)))
    measured = _fit_derivatives(ts, np.array(twists), 4)
    computed = _recursion(loops, x, model.njoints)
    scale = np.abs(measured).max(axis=1, keepdims=True)
    assert_allclose(computed / scale, measured / scale, atol=2e-5)


@pytest.mark.parametrize("kind", ["3d", "revolute", "universal", "cylindrical", "planar"])
def test_cut_joints_close_the_loop_to_second_order(kind: str) -> None:
    """Along a closed curve (a straight line projected on the closed set, fitted), some cut-joint rates
    make ``Phi^(0)`` and ``Phi^(1)`` vanish: the cut joint of each closure type is its relative motion."""
    mech = arm_closed_by(kind)
    conf = pinmob.Configuration(mech, mech.neutral())
    loops = mechanism_loops(conf)
    system, nv, col = loops.system, loops.nv, loops.columns
    model, residual = mech.model, closure_residual(mech)
    direction = closed_chain(conf, 1e-6).null @ np.random.default_rng(2).normal(
        size=nv - closed_chain(conf, 1e-6).decision.rank
    )
    ts = np.linspace(-6e-3, 6e-3, 9)
    points = []
    for t in ts:
        res = solve(
            model, residual, pin.integrate(model, conf.q, t * col * direction), tol=1e-14, length=mech.length_scale
        )
        assert res.residual < 1e-12
        points.append(short_difference(model, conf.q, res.q) / col)
    x1, x2 = _fit_derivatives(ts, np.array(points), 3)[1:]
    a = system.first_order()
    cut = slice(nv, system.size)
    first = np.zeros(system.size)
    first[:nv] = x1
    first[cut] = np.linalg.lstsq(a[:, cut], -a[:, :nv] @ x1, rcond=None)[0]
    assert np.abs(a @ first).max() < 1e-6 * np.abs(a[:, :nv] @ x1).max()
    jet = np.zeros((2, system.size))
    jet[0] = first
    jet[1, :nv] = x2
    phi = system.jets(jet)[1]  # Phi^(1) with no cut acceleration yet
    c2 = np.linalg.lstsq(a[:, cut], -phi, rcond=None)[0]
    assert np.abs(phi + a[:, cut] @ c2).max() < 1e-5 * np.abs(phi).max()


def _obstruction(mech: pinmob.Mechanism, conf: pinmob.Configuration, rates: np.ndarray) -> float:
    """The second-order obstruction along joint rates (dimensionless), from Pinocchio's closure residual.

    ``f(q (+) t x) + f(q (+) -t x) = t^2 f''(x, x) + O(t^4)`` (f(q) = 0); the part of ``f''(x, x)`` in the
    range of the closure Jacobian K can be cancelled by a joint acceleration, the rest cannot.
    """
    model, residual = mech.model, closure_residual(mech)
    col = mechanism_loops(conf).columns
    t = 1e-4
    second = sum(residual(pin.integrate(model, conf.q, s * t * col * rates))[0] for s in (1.0, -1.0)) / t**2
    k = residual(conf.q)[1] * col
    u, sv, _ = np.linalg.svd(k)
    rank = int(np.sum(sv > 1e-6 * sv[0]))
    return float(np.linalg.norm(u[:, rank:].T @ second))


@pytest.mark.parametrize(("name", "config"), [("3-PUU-flat", "flat"), ("Sarrus", "stretched")])
def test_second_order_cone_agrees_with_the_closure_residual(name: str, config: str) -> None:
    """Branch tangents pass order 2 by both methods; the instantaneous motions off them fail by both."""
    mech = pinmob.load(name)
    conf = pinmob.Configuration(mech, config)
    ho = HigherOrder(mechanism_loops(conf), 1e-6)
    nv = mech.model.nv
    found = cone(ho)
    assert found.components and found.linear
    for component in found.components:
        rates = ho.kernel[:nv] @ component.basis[:, 0]
        assert _obstruction(mech, conf, rates / np.linalg.norm(rates)) < 1e-5
    for i in range(ho.m):  # the kernel's own basis: none lies on a branch here
        rates = ho.kernel[:nv, i] / np.linalg.norm(ho.kernel[:nv, i])
        lie = float(np.linalg.norm(ho.forms()[:, i, i]))  # g_2 of the i-th basis motion: y^T H_l y
        assert (lie > 1e3 * ho.tol) == (_obstruction(mech, conf, rates) > 1e-3)


def test_four_bar_obstruction_by_both_methods() -> None:
    """At the flat four-bar both hand-derived branch tangents pass, their sum does not, by both methods."""
    mech = four_bar_flat()
    conf = pinmob.Configuration(mech, mech.neutral())
    k = (0.3 + 0.1) / (0.1 - 0.3)
    for rates, blocked in (([1, -1, 1], False), ([1, k, k], False), ([2, k - 1, k + 1], True)):
        r = np.array(rates, float) / np.linalg.norm(rates)
        assert (_obstruction(mech, conf, r) > 1e-3) == blocked
        ho = HigherOrder(mechanism_loops(conf), 1e-6)
        y = np.linalg.lstsq(ho.kernel[:3], r, rcond=None)[0]
        assert (ho.test(y, None, 4).blocked_at == 2) == blocked
