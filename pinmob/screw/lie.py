"""Lie brackets of twists, and the time derivatives of loop twists along joint-space curves.

Pure numpy. The bracket (screw product) of two twists ``a = [v_a; w_a]`` and
``b = [v_b; w_b]`` is

    [a, b] = ad_a b = [w_a x v_b + v_a x w_b;  w_a x w_b]

(Pinocchio's ``Motion.cross``). It is covariant under a change of reference point and under
the unit scaling ``[v / L; w]``, so it may be applied to dimensionless twists.

Kinematic tree. Joint columns ``S_j`` (instantaneous joint screws, world frame) each belong to
a body (the child of their joint); ``support[b, j] = 1`` when column j moves body b. Along a
joint-space curve ``x(t)`` the spatial twist of body b is ``V_b = sum_j support[b, j] S_j x_j'``
and every column moves with its body (Müller, J. Mechanisms Robotics 8(4):041013, 2016):

    dS_j / dt = [V_body(j), S_j].

The n-th derivatives follow by Leibniz's rule: with ``x^(i)`` the i-th derivative of x at t = 0,

    S_j^(n+1) = sum_{a=0..n} C(n, a) [V_body(j)^(a), S_j^(n-a)],
    U_j^(n)   = sum_{b=0..n} C(n, b) S_j^(b) x_j^(n+1-b),     V^(n) = support U^(n).

A loop closes when two bodies keep the same pose: its loop twist ``Phi = V_b - V_e`` vanishes
along the curve, i.e. ``Phi^(n) = loops U^(n) = 0`` for every n (``loops = support[b] - support[e]``).
``Phi^(n) = A x^(n+1) + R_n(x^(1), ..., x^(n))``, with ``A`` the first-order (instantaneous)
constraint matrix: a jet ``(x^(1), ..., x^(k))`` solves the closure to order k when
``Phi^(0..k-1) = 0``. These are the higher-order conditions of Müller's local analysis.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import comb

import numpy as np

from pinmob.screw.algebra import Array


def bracket(a: Array, b: Array) -> Array:
    """Lie bracket ``[a, b]`` of twists ``[v; w]`` in rows: (6,) or (k, 6) each (broadcast), same shape out.

    The cross products are written out by component (``np.cross`` costs more than the products on the
    small arrays of a loop system: the finite analysis's conditions spend most of their time here).
    """
    a, b = np.broadcast_arrays(a, b)
    out = np.empty(a.shape)
    ax, ay, az, bx, by, bz = a[..., 3], a[..., 4], a[..., 5], b[..., 3], b[..., 4], b[..., 5]  # w_a, w_b
    out[..., 3] = ay * bz - az * by
    out[..., 4] = az * bx - ax * bz
    out[..., 5] = ax * by - ay * bx
    vx, vy, vz, ux, uy, uz = b[..., 0], b[..., 1], b[..., 2], a[..., 0], a[..., 1], a[..., 2]  # v_b, v_a
    out[..., 0] = ay * vz - az * vy + uy * bz - uz * by
    out[..., 1] = az * vx - ax * vz + uz * bx - ux * bz
    out[..., 2] = ax * vy - ay * vx + ux * by - uy * bx
    return out


@dataclass(frozen=True)
class LoopSystem:
    """Joint screws of a kinematic tree and the loops that close it (dimensionless, one reference point).

    Attributes:
        screws: (n, 6) column screws ``[v / L; w]`` at the configuration.
        body: (n,) index of the body each column moves (the child body of its joint).
        support: (B, n) 0/1: column j moves body b (j on the path from the ground to b).
        loops: (c, n) in {-1, 0, 1}: ``support[b_c] - support[e_c]`` for loop c closing body b_c on e_c.
    """

    screws: Array
    body: Array
    support: Array
    loops: Array

    @property
    def size(self) -> int:
        """Number of columns n."""
        return int(self.screws.shape[0])

    def first_order(self) -> Array:
        """(6 c, n) the instantaneous constraint matrix ``A``: ``Phi^(0) = A x'``, loop after loop."""
        c, n = self.loops.shape
        return (self.loops[:, None, :] * self.screws.T[None, :, :]).reshape(6 * c, n)

    def jets(self, x: Array) -> Array:
        """The loop twists' derivatives ``Phi^(0..k-1)`` along a curve with derivatives ``x``.

        Args:
            x: (k, n), or a batch (b, k, n): ``x[..., i, :]`` is ``x^(i+1)``, the (i+1)-th derivative
                of the joint coordinates at t = 0 (dimensionless rates).

        Returns:
            (k, 6 c), or (b, k, 6 c): row n is ``Phi^(n)`` (6 per loop, loop after loop).
        """
        out, _ = self.jets_and_twists(x)
        return out

    def jets_and_twists(self, x: Array) -> tuple[Array, Array]:
        """:meth:`jets`, and the bodies' twists' derivatives ``V^(0..k-1)``: (k, B, 6), or (b, k, B, 6)."""
        xb = x[None] if x.ndim == 2 else x
        batch, k, _ = xb.shape
        s = [np.broadcast_to(self.screws, (batch, *self.screws.shape))]
        out = np.zeros((batch, k, self.loops.shape[0] * 6))
        v: list[Array] = []
        for n in range(k):
            if n > 0:
                s.append(np.sum([comb(n - 1, a) * bracket(v[a][:, self.body], s[n - 1 - a]) for a in range(n)], axis=0))
            u = np.sum([comb(n, b) * s[b] * xb[:, n - b, :, None] for b in range(n + 1)], axis=0)
            v.append(self.support @ u)
            out[:, n] = (self.loops @ u).reshape(batch, -1)
        twists = np.stack(v, axis=1)
        return (out[0], twists[0]) if x.ndim == 2 else (out, twists)
