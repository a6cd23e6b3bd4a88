"""``log6`` of a placement and its Jacobian ``Jlog6``, compiled (numba): the compiled pose solve's residual.

Pinocchio's formulas written anew (a compiled function cannot call Pinocchio), the rotation vector
:func:`~pinmob.assembly.batched.batch_newton_kernel.log3`'s; below ``SERIES_BELOW`` the coefficients are their series,
where the closed forms lose digits (Pinocchio's ``Jlog6`` is 7e-7 off at 3e-4 rad: ``tests/test_pose_solve_kernel.py``).
Importing this module imports numba.
"""

from __future__ import annotations

import numpy as np

from pinmob.assembly.batched.batch_newton_kernel import log3
from pinmob.jit_cache import njit
from pinmob.screw import Array

#: Below this angle [rad] the coefficients of log6 and Jlog6 are their series (the closed forms lose digits).
SERIES_BELOW = 0.1


@njit
def log6_jlog6(r: Array, p: Array, e: Array, jlog: Array) -> None:
    """``log6`` of the placement (r, p) into ``e`` (6,) ([v; w]) and its ``Jlog6`` into ``jlog`` (6, 6).

    With w the rotation vector (angle t) and ``a = (t/2) cot(t/2)``, ``b = (1 - a) / t^2``,
    ``c = b'(t) / t``: ``v = a p - w x p / 2 + b (w.p) w``; ``Jlog6 = [J3, (C J3); 0, J3]`` with
    ``J3 = b w w^T + a I + [w]x / 2`` and ``C = (c (w.p) w - (t^2 c + 2 b) p) w^T + b w p^T + b (w.p) I + [p]x / 2``.
    """
    w = np.empty(3)
    log3(r, w)
    t2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2]
    t = np.sqrt(t2)
    if t < SERIES_BELOW:  # b = 1/12 + t^2/720 + t^4/30240 + t^6/1209600 + ..., c = b' / t
        b = 1.0 / 12.0 + t2 * (1.0 / 720.0 + t2 * (1.0 / 30240.0 + t2 * (1.0 / 1209600.0 + t2 / 47900160.0)))
        c = 1.0 / 360.0 + t2 * (1.0 / 7560.0 + t2 * (1.0 / 201600.0 + t2 / 5987520.0))
    else:
        half = 0.5 * t
        sh = np.sin(half)
        b = 1.0 / t2 - np.cos(half) / (2.0 * t * sh)
        c = -2.0 / (t2 * t2) + (1.0 + np.sin(t) / t) / (t2 * 4.0 * sh * sh)
    a = 1.0 - t2 * b
    wp = w[0] * p[0] + w[1] * p[1] + w[2] * p[2]
    cross = np.empty(3)  # w x p
    cross[0], cross[1], cross[2] = w[1] * p[2] - w[2] * p[1], w[2] * p[0] - w[0] * p[2], w[0] * p[1] - w[1] * p[0]
    for i in range(3):
        e[i] = a * p[i] - 0.5 * cross[i] + b * wp * w[i]
        e[3 + i] = w[i]
    j3 = np.empty((3, 3))
    cm = np.empty((3, 3))
    k1, k2 = c * wp, t2 * c + 2.0 * b
    for i in range(3):
        v3 = k1 * w[i] - k2 * p[i]
        for j in range(3):
            j3[i, j] = b * w[i] * w[j]
            cm[i, j] = v3 * w[j] + b * w[i] * p[j]
        j3[i, i] += a
        cm[i, i] += wp * b
    _add_half_skew(w, j3)
    _add_half_skew(p, cm)
    for i in range(3):
        for j in range(3):
            jlog[i, j] = j3[i, j]
            jlog[3 + i, 3 + j] = j3[i, j]
            jlog[3 + i, j] = 0.0
            jlog[i, 3 + j] = cm[i, 0] * j3[0, j] + cm[i, 1] * j3[1, j] + cm[i, 2] * j3[2, j]


@njit
def _add_half_skew(v: Array, out: Array) -> None:
    """``out += [v]x / 2`` (the cross-product matrix of ``v``, halved)."""
    out[0, 1] -= 0.5 * v[2]
    out[0, 2] += 0.5 * v[1]
    out[1, 0] += 0.5 * v[2]
    out[1, 2] -= 0.5 * v[0]
    out[2, 0] -= 0.5 * v[1]
    out[2, 1] += 0.5 * v[0]
