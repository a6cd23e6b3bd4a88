"""The compiled loop of :mod:`pinmob.model.compiled_kinematics` (numba, the optional ``fast`` extra).

:func:`frames_kernel` runs the tables that module builds from a ``pin.Model``: the model's joints as a chain of
elementary joints (a universal joint is two revolute ones, a composite joint its parts), each with its parent, its
placement in the parent, its kind and axis and its configuration and velocity indices; the frames asked for with
their parent joint and placement. For each configuration of a stack it computes the world placement of every
elementary joint (as ``pin.forwardKinematics``), the world columns of the joint Jacobian (as
``pin.computeJointJacobians``' ``data.J``) and, for each frame, its placement and its Jacobian in the reference
asked for (as ``pin.getFrameJacobian``). No allocation inside the loop over the stack; one compiled function for
every model (the model is data), so it compiles once per installation (its cache: :mod:`pinmob.jit_cache`).
Importing this module imports numba.
"""

from __future__ import annotations

import numpy as np

from pinmob.jit_cache import njit
from pinmob.screw import Array

#: Elementary joint kinds (the codes of the ``kind`` table).
REVOLUTE, PRISMATIC, REVOLUTE_UNBOUNDED, SPHERICAL, FREE, PLANAR, TRANSLATION = range(7)
#: Velocity dimension of each kind.
KIND_NV = (1, 1, 1, 3, 6, 3, 3)
#: Frame Jacobian references (the codes of the ``reference`` argument): Pinocchio's LOCAL, LOCAL_WORLD_ALIGNED, WORLD.
LOCAL, LOCAL_WORLD_ALIGNED, WORLD = range(3)


@njit
def _quaternion(x: float, y: float, z: float, w: float, out: Array) -> None:
    """Rotation of the unit quaternion (x, y, z, w) into ``out`` (Eigen's ``toRotationMatrix``)."""
    tx, ty, tz = 2.0 * x, 2.0 * y, 2.0 * z
    twx, twy, twz = tx * w, ty * w, tz * w
    txx, txy, txz = tx * x, ty * x, tz * x
    tyy, tyz, tzz = ty * y, tz * y, tz * z
    out[0, 0], out[0, 1], out[0, 2] = 1.0 - (tyy + tzz), txy - twz, txz + twy
    out[1, 0], out[1, 1], out[1, 2] = txy + twz, 1.0 - (txx + tzz), tyz - twx
    out[2, 0], out[2, 1], out[2, 2] = txz - twy, tyz + twx, 1.0 - (txx + tyy)


@njit
def _axis_rotation(x: float, y: float, z: float, c: float, s: float, out: Array) -> None:
    """Rotation by the angle of cosine ``c`` and sine ``s`` about the unit axis (x, y, z) (Rodrigues) into ``out``."""
    t = 1.0 - c
    out[0, 0], out[0, 1], out[0, 2] = c + t * x * x, t * x * y - s * z, t * x * z + s * y
    out[1, 0], out[1, 1], out[1, 2] = t * x * y + s * z, c + t * y * y, t * y * z - s * x
    out[2, 0], out[2, 1], out[2, 2] = t * x * z - s * y, t * y * z + s * x, c + t * z * z


@njit
def _column(cols: Array, k: int, r: Array, e: int, p: Array, x: float, y: float, z: float, angular: bool) -> None:
    """World column ``k`` at the world origin of joint ``e`` at (r[e], p[e]), along or about the local (x, y, z)."""
    u0 = r[e, 0, 0] * x + r[e, 0, 1] * y + r[e, 0, 2] * z
    u1 = r[e, 1, 0] * x + r[e, 1, 1] * y + r[e, 1, 2] * z
    u2 = r[e, 2, 0] * x + r[e, 2, 1] * y + r[e, 2, 2] * z
    if angular:  # a rotation about the axis through p: v = p x w at the world origin
        p0, p1, p2 = p[e, 0], p[e, 1], p[e, 2]
        cols[0, k], cols[1, k], cols[2, k] = p1 * u2 - p2 * u1, p2 * u0 - p0 * u2, p0 * u1 - p1 * u0
        cols[3, k], cols[4, k], cols[5, k] = u0, u1, u2
    else:
        cols[0, k], cols[1, k], cols[2, k] = u0, u1, u2
        cols[3, k], cols[4, k], cols[5, k] = 0.0, 0.0, 0.0


@njit
def _unit_columns(cols: Array, r: Array, e: int, p: Array, v0: int, angular: bool) -> None:
    """Columns ``v0``... of joint ``e`` along (or about) its three local axes, into ``cols``."""
    for c in range(3):
        _column(cols, v0 + c, r, e, p, 1.0 if c == 0 else 0.0, 1.0 if c == 1 else 0.0, 1.0 if c == 2 else 0.0,
                angular)  # fmt: skip


@njit
def frames_kernel(
    qs: Array,
    parent: Array,
    kind: Array,
    axis: Array,
    iq: Array,
    iv: Array,
    rot0: Array,
    pos0: Array,
    f_parent: Array,
    f_rot: Array,
    f_pos: Array,
    reference: int,
    with_jacobians: bool,
    out_r: Array,
    out_p: Array,
    out_j: Array,
    out_world: Array,
) -> None:
    """Frame placements (``out_r`` (B, F, 3, 3), ``out_p`` (B, F, 3)) and Jacobians (``out_j`` (B, F, 6, nv)).

    With ``out_world`` of B rows (else none), the world joint Jacobian into it (B, 6, nv): Pinocchio's ``data.J``
    after ``computeJointJacobians``, every joint's twist at the world origin in world axes.

    ``qs`` (B, nq); the tables: per elementary joint ``parent`` (-1: the world), ``kind``, unit ``axis`` (3,),
    first configuration and velocity index ``iq``, ``iv``, placement in the parent ``rot0``, ``pos0``; per frame
    its elementary joint ``f_parent`` (-1: the world) and placement ``f_rot``, ``f_pos``. ``reference``:
    :data:`LOCAL`, :data:`LOCAL_WORLD_ALIGNED` or :data:`WORLD`. Scalar indexing throughout (no array views:
    each would count references).
    """
    ne, nf = parent.shape[0], f_parent.shape[0]
    nv = out_j.shape[3]
    world = out_world.shape[0] > 0
    o_r = np.empty((ne, 3, 3))
    o_p = np.empty((ne, 3))
    cols = np.zeros((6, nv))
    rj = np.empty((3, 3))
    pj = np.empty(3)
    rq = np.empty((3, 3))
    pq = np.empty(3)
    for b in range(qs.shape[0]):
        for e in range(ne):
            # the joint's frame before its motion: parent placement * placement in the parent
            g = parent[e]
            if g < 0:
                for i in range(3):
                    pj[i] = pos0[e, i]
                    for j in range(3):
                        rj[i, j] = rot0[e, i, j]
            else:
                for i in range(3):
                    pj[i] = (
                        o_p[g, i] + o_r[g, i, 0] * pos0[e, 0] + o_r[g, i, 1] * pos0[e, 1] + o_r[g, i, 2] * pos0[e, 2]
                    )
                    for j in range(3):
                        rj[i, j] = (
                            o_r[g, i, 0] * rot0[e, 0, j] + o_r[g, i, 1] * rot0[e, 1, j] + o_r[g, i, 2] * rot0[e, 2, j]
                        )
            # its motion (rq, pq) in that frame
            k, i0 = kind[e], iq[e]
            ax, ay, az = axis[e, 0], axis[e, 1], axis[e, 2]
            pq[0], pq[1], pq[2] = 0.0, 0.0, 0.0
            if k == REVOLUTE:
                angle = qs[b, i0]
                _axis_rotation(ax, ay, az, np.cos(angle), np.sin(angle), rq)
            elif k == REVOLUTE_UNBOUNDED:
                _axis_rotation(ax, ay, az, qs[b, i0], qs[b, i0 + 1], rq)
            elif k == PRISMATIC:
                _axis_rotation(ax, ay, az, 1.0, 0.0, rq)
                pq[0], pq[1], pq[2] = ax * qs[b, i0], ay * qs[b, i0], az * qs[b, i0]
            elif k == SPHERICAL:
                _quaternion(qs[b, i0], qs[b, i0 + 1], qs[b, i0 + 2], qs[b, i0 + 3], rq)
            elif k == FREE:
                _quaternion(qs[b, i0 + 3], qs[b, i0 + 4], qs[b, i0 + 5], qs[b, i0 + 6], rq)
                pq[0], pq[1], pq[2] = qs[b, i0], qs[b, i0 + 1], qs[b, i0 + 2]
            elif k == PLANAR:
                _axis_rotation(0.0, 0.0, 1.0, qs[b, i0 + 2], qs[b, i0 + 3], rq)
                pq[0], pq[1] = qs[b, i0], qs[b, i0 + 1]
            else:  # TRANSLATION
                _axis_rotation(1.0, 0.0, 0.0, 1.0, 0.0, rq)
                pq[0], pq[1], pq[2] = qs[b, i0], qs[b, i0 + 1], qs[b, i0 + 2]
            for i in range(3):
                o_p[e, i] = pj[i] + rj[i, 0] * pq[0] + rj[i, 1] * pq[1] + rj[i, 2] * pq[2]
                for j in range(3):
                    o_r[e, i, j] = rj[i, 0] * rq[0, j] + rj[i, 1] * rq[1, j] + rj[i, 2] * rq[2, j]
            if not (with_jacobians or world):
                continue
            # its columns of the world Jacobian (the motion subspace in the moved frame, seen from the world)
            v0 = iv[e]
            if k == REVOLUTE or k == REVOLUTE_UNBOUNDED:
                _column(cols, v0, o_r, e, o_p, ax, ay, az, True)
            elif k == PRISMATIC:
                _column(cols, v0, o_r, e, o_p, ax, ay, az, False)
            elif k == SPHERICAL:
                _unit_columns(cols, o_r, e, o_p, v0, True)
            elif k == FREE:
                _unit_columns(cols, o_r, e, o_p, v0, False)
                _unit_columns(cols, o_r, e, o_p, v0 + 3, True)
            elif k == TRANSLATION:
                _unit_columns(cols, o_r, e, o_p, v0, False)
            else:  # PLANAR: x and y translations, then the rotation about z
                _column(cols, v0, o_r, e, o_p, 1.0, 0.0, 0.0, False)
                _column(cols, v0 + 1, o_r, e, o_p, 0.0, 1.0, 0.0, False)
                _column(cols, v0 + 2, o_r, e, o_p, 0.0, 0.0, 1.0, True)
        if world:
            for i in range(6):
                for c in range(nv):
                    out_world[b, i, c] = cols[i, c]
        for f in range(nf):
            e = f_parent[f]
            if e < 0:
                for i in range(3):
                    out_p[b, f, i] = f_pos[f, i]
                    for j in range(3):
                        out_r[b, f, i, j] = f_rot[f, i, j]
            else:
                for i in range(3):
                    out_p[b, f, i] = (o_p[e, i] + o_r[e, i, 0] * f_pos[f, 0] + o_r[e, i, 1] * f_pos[f, 1]
                                      + o_r[e, i, 2] * f_pos[f, 2])  # fmt: skip
                    for j in range(3):
                        out_r[b, f, i, j] = (o_r[e, i, 0] * f_rot[f, 0, j] + o_r[e, i, 1] * f_rot[f, 1, j]
                                             + o_r[e, i, 2] * f_rot[f, 2, j])  # fmt: skip
            if not with_jacobians:
                continue
            for i in range(6):
                for c in range(nv):
                    out_j[b, f, i, c] = 0.0
            fp0, fp1, fp2 = out_p[b, f, 0], out_p[b, f, 1], out_p[b, f, 2]
            while e >= 0:  # the joints supporting the frame: its joint and that joint's ancestors
                for c in range(iv[e], iv[e] + KIND_NV[kind[e]]):
                    w0, w1, w2 = cols[3, c], cols[4, c], cols[5, c]
                    u0, u1, u2 = cols[0, c], cols[1, c], cols[2, c]
                    if reference != WORLD:  # the velocity of the frame's origin: v - p x w
                        u0, u1, u2 = u0 - (fp1 * w2 - fp2 * w1), u1 - (fp2 * w0 - fp0 * w2), u2 - (fp0 * w1 - fp1 * w0)
                    if reference == LOCAL:  # in the frame's axes
                        for i in range(3):
                            out_j[b, f, i, c] = out_r[b, f, 0, i] * u0 + out_r[b, f, 1, i] * u1 + out_r[b, f, 2, i] * u2
                            out_j[b, f, 3 + i, c] = (out_r[b, f, 0, i] * w0 + out_r[b, f, 1, i] * w1
                                                     + out_r[b, f, 2, i] * w2)  # fmt: skip
                    else:
                        out_j[b, f, 0, c], out_j[b, f, 1, c], out_j[b, f, 2, c] = u0, u1, u2
                        out_j[b, f, 3, c], out_j[b, f, 4, c], out_j[b, f, 5, c] = w0, w1, w2
                e = parent[e]


#: The kinds :func:`integrate_kernel` moves (a free-flyer or planar joint: Pinocchio's ``integrate``).
INTEGRABLE = (REVOLUTE, PRISMATIC, REVOLUTE_UNBOUNDED, SPHERICAL, TRANSLATION)


@njit
def integrate_kernel(q: Array, dv: Array, kind: Array, iq: Array, iv: Array, out: Array) -> None:
    """``pin.integrate(model, q, dv)`` into ``out`` (nq,) for the elementary joints of :data:`INTEGRABLE` kinds.

    Revolute, prismatic and translation coordinates add their rates; an unbounded revolute's (cos, sin) pair
    and a spherical joint's unit quaternion (x, y, z, w) turn by the rate's rotation (``q * exp3(v)``, in the
    joint's own frame), then are renormalised to first order (``(3 - |x|^2) / 2``), as Pinocchio's do.
    """
    for i in range(q.shape[0]):
        out[i] = q[i]
    for e in range(kind.shape[0]):
        k, a, v = kind[e], iq[e], iv[e]
        if k == REVOLUTE or k == PRISMATIC:
            out[a] = q[a] + dv[v]
        elif k == TRANSLATION:
            for i in range(3):
                out[a + i] = q[a + i] + dv[v + i]
        elif k == REVOLUTE_UNBOUNDED:
            c, s, cv, sv = q[a], q[a + 1], np.cos(dv[v]), np.sin(dv[v])
            r0, r1 = c * cv - s * sv, s * cv + c * sv
            alpha = (3.0 - (r0 * r0 + r1 * r1)) / 2.0
            out[a], out[a + 1] = alpha * r0, alpha * r1
        elif k == SPHERICAL:
            w0, w1, w2 = dv[v], dv[v + 1], dv[v + 2]
            t2 = w0 * w0 + w1 * w1 + w2 * w2
            t = np.sqrt(t2)
            if t < 1e-4:  # sin(t / 2) / t and cos(t / 2) by their series, to round-off
                h, ew = 0.5 - t2 / 48.0, 1.0 - t2 / 8.0
            else:
                h, ew = np.sin(0.5 * t) / t, np.cos(0.5 * t)
            ex, ey, ez = h * w0, h * w1, h * w2
            x, y, z, w = q[a], q[a + 1], q[a + 2], q[a + 3]
            rx = w * ex + x * ew + y * ez - z * ey
            ry = w * ey - x * ez + y * ew + z * ex
            rz = w * ez + x * ey - y * ex + z * ew
            rw = w * ew - x * ex - y * ey - z * ez
            alpha = (3.0 - (rx * rx + ry * ry + rz * rz + rw * rw)) / 2.0
            out[a], out[a + 1], out[a + 2], out[a + 3] = alpha * rx, alpha * ry, alpha * rz, alpha * rw


@njit
def difference_kernel(q0: Array, q1: Array, kind: Array, iq: Array, iv: Array, out: Array) -> None:
    """``pin.difference(model, q0, q1)`` into ``out`` (nv,) for the elementary joints of :data:`INTEGRABLE` kinds.

    The inverse of :func:`integrate_kernel`: revolute, prismatic and translation coordinates subtract; an
    unbounded revolute's angle from ``q0``'s (cos, sin) to ``q1``'s, in (-pi, pi]; a spherical joint's rotation
    vector of ``q0^-1 q1`` (unit quaternions (x, y, z, w), the shorter way: ``2 atan2(|v|, |w|)`` along
    ``sign(w) v``, as Pinocchio's ``quaternion::log3``).
    """
    for e in range(kind.shape[0]):
        k, a, v = kind[e], iq[e], iv[e]
        if k == REVOLUTE or k == PRISMATIC:
            out[v] = q1[a] - q0[a]
        elif k == TRANSLATION:
            for i in range(3):
                out[v + i] = q1[a + i] - q0[a + i]
        elif k == REVOLUTE_UNBOUNDED:
            c0, s0, c1, s1 = q0[a], q0[a + 1], q1[a], q1[a + 1]
            out[v] = np.arctan2(c0 * s1 - s0 * c1, c0 * c1 + s0 * s1)
        elif k == SPHERICAL:
            x, y, z, w = -q0[a], -q0[a + 1], -q0[a + 2], q0[a + 3]  # the conjugate of q0
            bx, by, bz, bw = q1[a], q1[a + 1], q1[a + 2], q1[a + 3]
            rx = w * bx + x * bw + y * bz - z * by
            ry = w * by - x * bz + y * bw + z * bx
            rz = w * bz + x * by - y * bx + z * bw
            rw = w * bw - x * bx - y * by - z * bz
            if rw < 0.0:  # q and -q are the same rotation: the shorter angle
                rx, ry, rz, rw = -rx, -ry, -rz, -rw
            n = np.sqrt(rx * rx + ry * ry + rz * rz)
            scale = 2.0 / rw if n < 1e-8 else 2.0 * np.arctan2(n, rw) / n  # 2 atan2(n, w) / n to round-off
            out[v], out[v + 1], out[v + 2] = scale * rx, scale * ry, scale * rz
