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
from pinmob.screw.algebra import Array

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
def _axis_rotation(a: Array, c: float, s: float, out: Array) -> None:
    """Rotation by the angle of cosine ``c`` and sine ``s`` about the unit axis ``a`` (Rodrigues) into ``out``."""
    t = 1.0 - c
    x, y, z = a[0], a[1], a[2]
    out[0, 0], out[0, 1], out[0, 2] = c + t * x * x, t * x * y - s * z, t * x * z + s * y
    out[1, 0], out[1, 1], out[1, 2] = t * x * y + s * z, c + t * y * y, t * y * z - s * x
    out[2, 0], out[2, 1], out[2, 2] = t * x * z - s * y, t * y * z + s * x, c + t * z * z


@njit
def _column(cols: Array, k: int, r: Array, p: Array, local: Array, angular: bool) -> None:
    """World column ``k`` at the world origin of a joint at (r, p) whose local motion is ``local`` (unit rate)."""
    u0 = r[0, 0] * local[0] + r[0, 1] * local[1] + r[0, 2] * local[2]
    u1 = r[1, 0] * local[0] + r[1, 1] * local[1] + r[1, 2] * local[2]
    u2 = r[2, 0] * local[0] + r[2, 1] * local[1] + r[2, 2] * local[2]
    if angular:  # a rotation about the axis through p: v = p x w at the world origin
        cols[0, k], cols[1, k], cols[2, k] = p[1] * u2 - p[2] * u1, p[2] * u0 - p[0] * u2, p[0] * u1 - p[1] * u0
        cols[3, k], cols[4, k], cols[5, k] = u0, u1, u2
    else:
        cols[0, k], cols[1, k], cols[2, k] = u0, u1, u2
        cols[3, k], cols[4, k], cols[5, k] = 0.0, 0.0, 0.0


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
) -> None:
    """Frame placements (``out_r`` (B, F, 3, 3), ``out_p`` (B, F, 3)) and Jacobians (``out_j`` (B, F, 6, nv)).

    ``qs`` (B, nq); the tables: per elementary joint ``parent`` (-1: the world), ``kind``, unit ``axis`` (3,),
    first configuration and velocity index ``iq``, ``iv``, placement in the parent ``rot0``, ``pos0``; per frame
    its elementary joint ``f_parent`` (-1: the world) and placement ``f_rot``, ``f_pos``. ``reference``:
    :data:`LOCAL`, :data:`LOCAL_WORLD_ALIGNED` or :data:`WORLD`.
    """
    ne, nf = parent.shape[0], f_parent.shape[0]
    nv = out_j.shape[3]
    o_r = np.empty((ne, 3, 3))
    o_p = np.empty((ne, 3))
    cols = np.zeros((6, nv))
    rj = np.empty((3, 3))
    pj = np.empty(3)
    rq = np.empty((3, 3))
    pq = np.empty(3)
    unit = np.empty(3)
    for b in range(qs.shape[0]):
        q = qs[b]
        for e in range(ne):
            # the joint's frame before its motion: parent placement * placement in the parent
            if parent[e] < 0:
                rj[:, :] = rot0[e]
                pj[:] = pos0[e]
            else:
                pr, pp = o_r[parent[e]], o_p[parent[e]]
                for i in range(3):
                    pj[i] = pp[i] + pr[i, 0] * pos0[e, 0] + pr[i, 1] * pos0[e, 1] + pr[i, 2] * pos0[e, 2]
                    for j in range(3):
                        rj[i, j] = pr[i, 0] * rot0[e, 0, j] + pr[i, 1] * rot0[e, 1, j] + pr[i, 2] * rot0[e, 2, j]
            # its motion (rq, pq) in that frame
            k, a, i0 = kind[e], axis[e], iq[e]
            pq[:] = 0.0
            if k == REVOLUTE:
                _axis_rotation(a, np.cos(q[i0]), np.sin(q[i0]), rq)
            elif k == REVOLUTE_UNBOUNDED:
                _axis_rotation(a, q[i0], q[i0 + 1], rq)
            elif k == PRISMATIC:
                rq[:, :] = 0.0
                for i in range(3):
                    rq[i, i] = 1.0
                    pq[i] = a[i] * q[i0]
            elif k == SPHERICAL:
                _quaternion(q[i0], q[i0 + 1], q[i0 + 2], q[i0 + 3], rq)
            elif k == FREE:
                _quaternion(q[i0 + 3], q[i0 + 4], q[i0 + 5], q[i0 + 6], rq)
                pq[0], pq[1], pq[2] = q[i0], q[i0 + 1], q[i0 + 2]
            elif k == PLANAR:
                unit[0], unit[1], unit[2] = 0.0, 0.0, 1.0
                _axis_rotation(unit, q[i0 + 2], q[i0 + 3], rq)
                pq[0], pq[1] = q[i0], q[i0 + 1]
            else:  # TRANSLATION
                rq[:, :] = 0.0
                for i in range(3):
                    rq[i, i] = 1.0
                    pq[i] = q[i0 + i]
            r, p = o_r[e], o_p[e]
            for i in range(3):
                p[i] = pj[i] + rj[i, 0] * pq[0] + rj[i, 1] * pq[1] + rj[i, 2] * pq[2]
                for j in range(3):
                    r[i, j] = rj[i, 0] * rq[0, j] + rj[i, 1] * rq[1, j] + rj[i, 2] * rq[2, j]
            if not with_jacobians:
                continue
            # its columns of the world Jacobian (the motion subspace in the moved frame, seen from the world)
            v0 = iv[e]
            if k == REVOLUTE or k == REVOLUTE_UNBOUNDED:
                _column(cols, v0, r, p, a, True)
            elif k == PRISMATIC:
                _column(cols, v0, r, p, a, False)
            else:
                for c in range(3):
                    unit[:] = 0.0
                    unit[c] = 1.0
                    if k == SPHERICAL:
                        _column(cols, v0 + c, r, p, unit, True)
                    elif k == FREE:
                        _column(cols, v0 + c, r, p, unit, False)
                        _column(cols, v0 + 3 + c, r, p, unit, True)
                    elif k == TRANSLATION:
                        _column(cols, v0 + c, r, p, unit, False)
                    elif c < 2:  # PLANAR: x and y translations, then the rotation about z
                        _column(cols, v0 + c, r, p, unit, False)
                    else:
                        _column(cols, v0 + 2, r, p, unit, True)
        for f in range(nf):
            e = f_parent[f]
            fr, fp = out_r[b, f], out_p[b, f]
            if e < 0:
                fr[:, :] = f_rot[f]
                fp[:] = f_pos[f]
            else:
                r, p = o_r[e], o_p[e]
                for i in range(3):
                    fp[i] = p[i] + r[i, 0] * f_pos[f, 0] + r[i, 1] * f_pos[f, 1] + r[i, 2] * f_pos[f, 2]
                    for j in range(3):
                        fr[i, j] = r[i, 0] * f_rot[f, 0, j] + r[i, 1] * f_rot[f, 1, j] + r[i, 2] * f_rot[f, 2, j]
            if not with_jacobians:
                continue
            jac = out_j[b, f]
            jac[:, :] = 0.0
            while e >= 0:  # the joints supporting the frame: its joint and that joint's ancestors
                for c in range(iv[e], iv[e] + KIND_NV[kind[e]]):
                    w0, w1, w2 = cols[3, c], cols[4, c], cols[5, c]
                    v0_, v1, v2 = cols[0, c], cols[1, c], cols[2, c]
                    if reference != WORLD:  # the velocity of the frame's origin: v - p x w
                        v0_, v1, v2 = (
                            v0_ - (fp[1] * w2 - fp[2] * w1),
                            v1 - (fp[2] * w0 - fp[0] * w2),
                            v2 - (fp[0] * w1 - fp[1] * w0),
                        )
                    if reference == LOCAL:  # in the frame's axes
                        for i in range(3):
                            jac[i, c] = fr[0, i] * v0_ + fr[1, i] * v1 + fr[2, i] * v2
                            jac[3 + i, c] = fr[0, i] * w0 + fr[1, i] * w1 + fr[2, i] * w2
                    else:
                        jac[0, c], jac[1, c], jac[2, c] = v0_, v1, v2
                        jac[3, c], jac[4, c], jac[5, c] = w0, w1, w2
                e = parent[e]
