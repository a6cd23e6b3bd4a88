"""Each closure type allows exactly the relative motions it is defined by, checked on a free body.

A free-flyer body carries frame b; frame a is fixed in the world at a generic pose; the closure joins
them. The body has all six motions, so the closure alone decides what is left: the null space of the
closure Jacobian, mapped to the twist of b relative to a (in frame a, which coincides with b at the
closed configuration), must be the subspace written by hand below, and a finite motion inside that
subgroup must keep the residual at 0 while a motion outside it must not.

Allowed relative twists ``[v; w]`` (u = axis in a, u_b = second axis in b, p1, p2 a basis of the plane
normal to u), and rows = 6 - allowed:

- 6d: none; 3d: any rotation about the common origin (3R);
- revolute: rotation about u (1R); universal: rotations about u and u_b through the origin (2R);
- cylindrical: rotation about and translation along u (1T1R, coaxial);
- prismatic: translation along u (1T);
- planar: translations along p1, p2 and rotation about u (2T1R).

The fewer-row kinds (minimal closures of planar and spherical loops) allow, to first order:

- planar_weld: translation along u, rotations about p1, p2; inline: translation along u, any rotation;
- inplane: translations along p1, p2, any rotation; orientation: any translation;
- parallel_axes: any translation, rotation about u; perpendicular: any translation, rotations about u and u_b.

Their residual Jacobians are also checked against finite differences away from the closed pose.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import pinmob
from pinmob.assembly.residual import closure_error, closure_value, compute_kinematics
from pinmob.model.closure import make_closure
from pinmob.screw.bases import subspace_gap

RNG = np.random.default_rng(7)
U = np.array([0.2, -0.5, 0.84])
U /= np.linalg.norm(U)
P1 = np.cross(U, [1.0, 0, 0])
P1 /= np.linalg.norm(P1)
P2 = np.cross(U, P1)
A_POSE = pin.SE3(pin.rpy.rpyToMatrix(0.3, -0.7, 1.1), np.array([0.2, -0.1, 0.4]))
B_OFFSET = pin.SE3(pin.rpy.rpyToMatrix(-0.4, 0.2, 0.9), np.array([0.05, 0.15, -0.1]))


def twist(v=(0, 0, 0), w=(0, 0, 0)) -> np.ndarray:
    return np.concatenate([np.asarray(v, float), np.asarray(w, float)])


ALLOWED = {
    "6d": [],
    "3d": [twist(w=e) for e in np.eye(3)],
    "revolute": [twist(w=U)],
    "universal": [twist(w=U), twist(w=P1)],  # u_b = P1 (in b, = in a at the closed pose): perpendicular to u
    "cylindrical": [twist(v=U), twist(w=U)],
    "prismatic": [twist(v=U)],
    "planar": [twist(v=P1), twist(v=P2), twist(w=U)],
}


FEWER_ROWS = {
    "planar_weld": [twist(v=U), twist(w=P1), twist(w=P2)],
    "inline": [twist(v=U)] + [twist(w=e) for e in np.eye(3)],
    "inplane": [twist(v=P1), twist(v=P2)] + [twist(w=e) for e in np.eye(3)],
    "orientation": [twist(v=e) for e in np.eye(3)],
    "parallel_axes": [twist(v=e) for e in np.eye(3)] + [twist(w=U)],
    "perpendicular": [twist(v=e) for e in np.eye(3)] + [twist(w=U), twist(w=P1)],
}


def finite(kind: str, s: float) -> pin.SE3:
    """A finite relative pose of b in a inside the closure's subgroup (parameter s)."""
    exp = pin.exp6
    return {
        "6d": pin.SE3.Identity(),
        "3d": exp(twist(w=s * np.array([0.3, -0.2, 0.5]))),
        "revolute": exp(twist(w=s * U)),
        "universal": exp(twist(w=s * U)) * exp(twist(w=-0.7 * s * P1)),  # about u (in a), then u_b (in b)
        "cylindrical": exp(twist(v=0.2 * s * U, w=s * U)),
        "prismatic": exp(twist(v=0.2 * s * U)),
        "planar": exp(twist(v=0.1 * s * P1 - 0.3 * s * P2, w=s * U)),
    }[kind]


def free_body(kind: str) -> tuple[pinmob.Mechanism, pinmob.Closure]:
    model = pin.Model()
    body = model.addJoint(0, pin.JointModelFreeFlyer(), pin.SE3.Identity(), "free")
    model.addFrame(pin.Frame("a", 0, A_POSE, pin.FrameType.OP_FRAME))
    model.addFrame(pin.Frame("b", body, B_OFFSET, pin.FrameType.OP_FRAME))
    two, none = ("universal", "perpendicular"), ("6d", "3d", "orientation")
    axes = {"axis": U, "axis_b": P1} if kind in two else {"axis": U} if kind not in none else {}
    closure = make_closure(model, kind, "a", "b", kind, **axes)
    return pinmob.Mechanism.from_model(model, [], name=kind, closures=[closure], length_scale=0.3), closure


def at(relative: pin.SE3) -> np.ndarray:
    """Free-flyer q giving frame b the pose ``A_POSE * relative`` (pose of b in a)."""
    return pin.SE3ToXYZQUAT(A_POSE * relative * B_OFFSET.inverse())


@pytest.mark.parametrize("kind", sorted(ALLOWED | FEWER_ROWS))
def test_closure_allows_exactly_its_motions(kind):
    mech, closure = free_body(kind)
    model, data = mech.model, mech.model.createData()
    q = at(pin.SE3.Identity())
    compute_kinematics(model, data, q)
    e, jac, lin = closure_error(model, data, closure)
    assert np.max(np.abs(e)) < 1e-12
    allowed = (ALLOWED | FEWER_ROWS)[kind]
    assert jac.shape == (closure.rows, 6) == (6 - len(allowed), 6)
    _, s, vt = np.linalg.svd(jac)
    assert np.sum(s > 1e-9 * max(s, default=1.0)) == closure.rows  # independent rows
    null = vt[closure.rows :].T
    relative = pin.getFrameJacobian(model, data, model.getFrameId("b"), pin.LOCAL) @ null  # b in a = b in b here
    expected = np.column_stack(allowed) if allowed else np.zeros((6, 0))
    scale = np.array([1 / 0.3] * 3 + [1.0] * 3)[:, None]
    assert subspace_gap(scale * relative, scale * expected) < 1e-7  # its floor is sqrt(eps) ~ 1.5e-8


@pytest.mark.parametrize("kind", sorted(ALLOWED))
def test_residual_zero_inside_the_subgroup_and_not_outside(kind):
    mech, closure = free_body(kind)
    model, data = mech.model, mech.model.createData()
    for s in (0.3, -1.1):
        compute_kinematics(model, data, at(finite(kind, s)))
        assert np.max(np.abs(closure_error(model, data, closure)[0])) < 1e-12, s
    allowed = np.column_stack(ALLOWED[kind]) if ALLOWED[kind] else np.zeros((6, 0))
    complement = np.linalg.svd(np.hstack([allowed, np.zeros((6, 6 - allowed.shape[1]))]))[0][:, allowed.shape[1] :]
    for k in range(complement.shape[1]):
        off = pin.exp6(0.05 * complement[:, k]) * finite(kind, 0.3)
        compute_kinematics(model, data, at(off))
        e = closure_error(model, data, closure)[0]
        assert np.linalg.norm(e) > 1e-3, (kind, complement[:, k])


@pytest.mark.parametrize("kind", sorted(FEWER_ROWS))
def test_fewer_row_jacobians_match_finite_differences(kind):
    """Away from the closed pose (residual not 0), J = de/dq by central differences (Pinocchio's integrate)."""
    mech, closure = free_body(kind)
    model, data = mech.model, mech.model.createData()
    q = at(pin.exp6(0.2 * RNG.standard_normal(6)))
    compute_kinematics(model, data, q)
    e, jac, _ = closure_error(model, data, closure)
    assert np.linalg.norm(e) > 1e-3
    np.testing.assert_allclose(closure_value(model, data, closure)[0], e, atol=1e-14)  # the same residual
    h, numeric = 1e-6, np.zeros_like(jac)
    for k in range(model.nv):
        dq = np.zeros(model.nv)
        dq[k] = h
        compute_kinematics(model, data, pin.integrate(model, q, dq))
        plus = closure_error(model, data, closure)[0]
        compute_kinematics(model, data, pin.integrate(model, q, -dq))
        numeric[:, k] = (plus - closure_error(model, data, closure)[0]) / (2 * h)
    np.testing.assert_allclose(jac, numeric, atol=1e-7)
