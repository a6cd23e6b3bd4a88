"""The local dimension of a closed set by sampling, written for the tests without pinmob's analyses.

A second method for the finite DoF (the finite analysis is not called): only Pinocchio's kinematics and
the mechanism's data (its closures' frame pairs and types, its platform frame, its joints).

1. The closure residual and its Jacobian from Pinocchio's frame placements and world-aligned frame
   Jacobians: a weld (``6d``) gives ``[(p_b - p_a) / L; log3(R_b R_a^T)]``, a ball (``3d``) ``(p_b - p_a) / L``.
2. A Newton projection (least-squares, minimum-norm steps; held joints kept) from ``q (+) RADIUS u``, u random
   first-order motions (the Jacobian's null space at q): closed samples near q.
3. At each sample p, each of its first-order motions v_i is probed: ``p (+/-) PROBE v_i`` projected back, the
   central difference of the two over ``2 PROBE``. A motion that exists at finite amplitude moves the
   projection along with it (singular value about 1), one that exists to first order only does not (about 0):
   the number of singular values above 0.5 is the dimension of the closed set at p; the platform
   displacements (``[dx / L; log3(R R0^T)]``) along the combinations that extend give the platform's
   (singular values above ``PLATFORM_TOL``: the probes' curvature leaves about 1e-5 at the Delta's rods
   horizontal, round-off 1e-9; a real motion moves the platform by more than 1e-3 per unit of joint motion
   at one sample at least, even beside the Delta's stretched arms, where it moves only to second order).
4. The finite DoF at q are the largest over the samples (0 when every projection falls back onto q).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

import pinmob
from pinmob.model.joints import linear_velocity_mask

RADIUS = 0.03
PROBE = 2e-4
PLATFORM_TOL = 3e-4


class ClosedSet:
    """The closure equations of ``mech`` (only welds and balls, as the built-in models have) by Pinocchio."""

    def __init__(self, mech: pinmob.Mechanism, held: tuple[str, ...] = ()) -> None:
        self.mech, self.model = mech, mech.model
        self.data = self.model.createData()
        self.length = mech.length_scale
        self.col = np.where(linear_velocity_mask(self.model), self.length, 1.0)  # joint steps: rad, or m / L
        self.free = np.ones(self.model.nv, bool)
        for name in held:
            joint = self.model.joints[self.model.getJointId(name)]
            self.free[joint.idx_v : joint.idx_v + joint.nv] = False
        self.pairs = []
        for c in mech.all_closures:
            kind = str(getattr(c.type, "value", c.type))
            assert kind in ("6d", "3d"), kind
            self.pairs.append((self.model.getFrameId(c.frame_a), self.model.getFrameId(c.frame_b), kind == "6d"))
        self.platform = self.model.getFrameId(mech.platform)

    def residual(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(e, J): the stacked dimensionless residual and its Jacobian in dimensionless joint steps."""
        model, data = self.model, self.data
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        es, js = [], []
        for a, b, weld in self.pairs:
            ja = pin.getFrameJacobian(model, data, a, pin.LOCAL_WORLD_ALIGNED)
            jb = pin.getFrameJacobian(model, data, b, pin.LOCAL_WORLD_ALIGNED)
            ma, mb = data.oMf[a], data.oMf[b]
            es.append((mb.translation - ma.translation) / self.length)
            js.append((jb[:3] - ja[:3]) / self.length)
            if weld:
                es.append(pin.log3(mb.rotation @ ma.rotation.T))
                js.append(jb[3:] - ja[3:])
        return np.concatenate(es), np.vstack(js) * self.col

    def null(self, q: np.ndarray) -> np.ndarray:
        """(nv, d) orthonormal first-order motions at the closed q (held joints still), rank tolerance 1e-6."""
        _, jac = self.residual(q)
        jac = jac[:, self.free]
        _, s, vt = np.linalg.svd(jac)
        rank = int(np.sum(s > 1e-6 * max(1.0, s[0]))) if s.size else 0
        out = np.zeros((self.model.nv, jac.shape[1] - rank))
        out[self.free] = vt[rank:].T
        return out

    def project(self, q: np.ndarray, step: np.ndarray) -> np.ndarray | None:
        """q moved by the dimensionless ``step`` and brought back by Newton (None: not closed to 1e-11)."""
        x = pin.integrate(self.model, q, self.col * step)
        for _ in range(200):
            e, jac = self.residual(x)
            if np.max(np.abs(e)) < 1e-12:
                return x
            dz = np.zeros(self.model.nv)
            dz[self.free] = -np.linalg.lstsq(jac[:, self.free], e, rcond=1e-12)[0]
            x = pin.integrate(self.model, x, self.col * dz)
        return x if np.max(np.abs(self.residual(x)[0])) < 1e-11 else None

    def moved(self, a: np.ndarray, b: np.ndarray) -> np.ndarray:
        """Dimensionless joint displacement from a to b."""
        return pin.difference(self.model, a, b) / self.col

    def pose(self, q: np.ndarray) -> pin.SE3:
        pin.framesForwardKinematics(self.model, self.data, q)
        return self.data.oMf[self.platform].copy()

    def dimensions_at(self, p: np.ndarray) -> tuple[int, int] | None:
        """(closed set, platform poses) dimensions at the closed sample p (None: a probe fell in between)."""
        found = self.tangent_at(p)
        if found is None:
            return None
        extend, poses = found
        sp = np.linalg.svd(poses, compute_uv=False) if poses.size else np.zeros(0)
        return extend.shape[1], int(np.sum(sp > PLATFORM_TOL))

    def tangent_at(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
        """(joint rates (nv, d), platform twists (6, d)) of the d motions that extend at the closed sample p.

        The twists are ``[dx / L; dtheta]`` per unit of the dimensionless joint motion (None: a probe fell in
        between).
        """
        null = self.null(p)
        joints, poses = [], []
        for i in range(null.shape[1]):
            ends = [self.project(p, sign * PROBE * null[:, i]) for sign in (1.0, -1.0)]
            if ends[0] is None or ends[1] is None:
                return None
            joints.append(self.moved(ends[1], ends[0]) / (2 * PROBE))
            a, b = self.pose(ends[1]), self.pose(ends[0])
            twist = np.r_[(b.translation - a.translation) / self.length, pin.log3(b.rotation @ a.rotation.T)]
            poses.append(twist / (2 * PROBE))
        if not joints:
            return np.zeros((self.model.nv, 0)), np.zeros((6, 0))
        _, s, vt = np.linalg.svd(np.array(joints).T, full_matrices=False)
        if np.any((s > 0.25) & (s < 0.75)):
            return None
        extend = vt[s > 0.5].T  # the probed motions' combinations that extend
        return null @ extend, np.array(poses).T @ extend


def sampled_dimensions(
    mech: pinmob.Mechanism, q: np.ndarray, held: tuple[str, ...] = (), count: int = 6, seed: int = 0
) -> tuple[int, int]:
    """(platform, closed chain) finite DoF at q: the largest over closed samples near q (see the module docstring).

    Every projection falling back onto q (within a tenth of the radius) means q is isolated: (0, 0).
    """
    closed = ClosedSet(mech, held)
    rng = np.random.default_rng(seed)
    null = closed.null(q)
    found, off = [], 0
    for _ in range(count if null.shape[1] else 0):
        u = null @ rng.normal(size=null.shape[1])
        p = closed.project(q, RADIUS * u / np.linalg.norm(u))
        if p is None or not 0.1 * RADIUS < np.linalg.norm(closed.moved(q, p)) < 3 * RADIUS:
            continue  # fell back onto q (or far away)
        off += 1
        dims = closed.dimensions_at(p)
        if dims is not None:
            found.append(dims)
    if not found:
        assert not off, f"{off} closed samples off q, none whose probes tell its dimension"
        return 0, 0  # every projection fell back onto q: q is isolated
    return max(d[1] for d in found), max(d[0] for d in found)


def platform_twists(closed: ClosedSet, q: np.ndarray, rates: np.ndarray) -> np.ndarray:
    """(6, d) the platform's twists ``[v / L; w]`` (world-aligned, at its origin) for the dimensionless joint rates."""
    model, data = closed.model, closed.data
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    jac = pin.getFrameJacobian(model, data, closed.platform, pin.LOCAL_WORLD_ALIGNED) * closed.col
    jac[:3] /= closed.length
    return jac @ rates


def motion_type(twists: np.ndarray, length: float, tol: float = 1e-3) -> str:
    """The motion type (``3T``, ``2T1R``, ``3H``, ...) of the span of the twists ``[v / L; w]`` (6, d), by hand.

    Its dimension d' (singular values above ``tol`` of the largest); the translations are the span's members with
    no rotation (d' minus the rank of the rotation parts); on the rest the principal pitches are the generalised
    eigenvalues of ``(sym(w_i . v_j), w_i . w_j)`` over a complement of the translations (v in metres): zero
    (``|h| <= tol L``) a rotation, else a screw. Named ``<t>T<r>R<h>H`` without the zero counts (``rigid``: none).
    """
    u, s, _ = np.linalg.svd(twists, full_matrices=False)
    basis = u[:, s > tol * max(float(s[0]), 1e-300)] if s.size else np.zeros((6, 0))
    if basis.shape[1] == 0:
        return "rigid"
    import scipy.linalg

    _, sw, vt = np.linalg.svd(basis[3:], full_matrices=True)
    rot = int(np.sum(sw > tol))
    t = basis.shape[1] - rot
    translations = basis[:3] @ vt[rot:].T  # (3, t) their directions
    turning = basis @ vt[:rot].T  # a complement of the translations in the span
    v, w = turning[:3] * length, turning[3:]
    # a rotation part with a component along the translations can have its pitch cancelled by them: a rotation
    along = np.linalg.qr(translations)[0].T @ w if t else np.zeros((0, rot))
    keep = np.eye(rot)
    if along.size:
        _, sa, va = np.linalg.svd(along, full_matrices=True)
        keep = va[int(np.sum(sa > tol)) :].T  # the rotation parts orthogonal to the translations
    v, w = v @ keep, w @ keep
    pitches = scipy.linalg.eigh((w.T @ v + v.T @ w) / 2, w.T @ w, eigvals_only=True) if w.shape[1] else np.zeros(0)
    h = int(np.sum(np.abs(pitches) > tol * length))
    return "".join(f"{n}{k}" for n, k in ((t, "T"), (rot - h, "R"), (h, "H")) if n)


def trace(closed: ClosedSet, q: np.ndarray, direction: np.ndarray, distance: float, steps: int) -> np.ndarray | None:
    """Continuation along the closed set from q, starting along ``direction`` (dimensionless joint rates).

    Each step moves ``distance / steps`` along the previous direction projected on the first-order motions where
    it stands (``null``), then Newton brings it back (:meth:`ClosedSet.project`). None when a step does not close
    or lands farther than twice the step from where it was aimed.
    """
    x, d = q.copy(), direction / np.linalg.norm(direction)
    h = distance / steps
    for _ in range(steps):
        null = closed.null(x)
        d = null @ (null.T @ d)
        d /= np.linalg.norm(d)
        nxt = closed.project(x, h * d)
        if nxt is None or np.linalg.norm(closed.moved(x, nxt)) > 2 * h:
            return None
        d = closed.moved(x, nxt)
        x = nxt
    return x
