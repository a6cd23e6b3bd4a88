"""Higher-order conditions on the closure equations: which first-order motions extend, and to which order.

With the loops of :mod:`pinmob.analysis.finite.loop_screws` and the couplings' rows of
:mod:`pinmob.analysis.finite.coupling_rows` (``n`` joint and cut coordinates, first-order matrix ``A``), a closed
curve through q has derivatives ``x^(1), x^(2), ...`` with ``Phi^(n) = A x^(n+1) + R_n(x^(1..n)) = 0``
for every n (:mod:`pinmob.screw.lie`). With ``N`` an orthonormal basis of ``null A`` (the instantaneous
motions, ``x^(1) = N y``) and ``C`` one of ``null A^T`` (the combinations of loop equations no joint rate
changes), the condition of order ``k >= 2`` is

    g_k = C^T R_(k-1)(x^(1), ..., x^(k-1)) = 0,   x^(i) = -A^+ R_(i-1) + N z_i  (z_i free),

Müller's higher-order conditions (J. Mechanisms Robotics 8(4):041013, 2016), built from Lie brackets of
the instantaneous joint screws only. ``g_2 = Q(y)`` is a quadratic form per row of C; ``g_k`` is affine
in the newest ``z_(k-1)``. A first-order motion y is *blocked at order k* when no choice of the
``z_i`` (and, for a motion given up to internal motions, of those) satisfies ``g_2 .. g_k``; the
set of y passing order 2, ``Q(y) = 0``, is the second-order tangent cone, whose linear components are
the tangent spaces of the motion branches through q.

Every residual is compared with ``tol = order_tol * max(1, sigma_max(A))`` after scaling by ``|y|^k``
(the conditions are homogeneous), so the answer does not depend on units or on the size of y (A is
dimensionless: its natural scale is 1, the floor under a small A).
The cone itself is split into its linear components by :mod:`pinmob.analysis.finite.tangent_cone`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from pinmob.analysis.finite.loop_screws import MechanismLoops
from pinmob.exceptions import ArgumentError
from pinmob.frozen import ReadOnlyArrays
from pinmob.screw import Array, decide_rank, decision, svd

#: Default bound on the order of the conditions checked.
ORDER = 4
#: Default relative tolerance of a condition's residual (times ``max(1, sigma_max(A))``).
ORDER_TOL = 1e-7
#: A condition's residual within this factor of its tolerance (either side) decides nothing ("cannot decide").
MARGIN = 10.0

#: Valid order bounds.
ORDERS = range(2, 9)


def check_order(order: object) -> int:
    """A validated order bound: an integer in 2..8.

    Raises:
        ArgumentError: naming the value and the valid range (its ``parameter``: ``finite_order``).
    """
    if isinstance(order, bool) or not isinstance(order, int) or order not in ORDERS:
        raise ArgumentError(
            f"the order bound of the finite analysis must be an integer from {ORDERS[0]} to {ORDERS[-1]}, got {order!r}",
            "finite_order",
            order,
        )
    return order


#: Budget of function evaluations of a joint (non-linear) solve over every free parameter.
JOINT_SOLVE_EVALUATIONS = 400


@dataclass(frozen=True)
class OrderTest(ReadOnlyArrays):
    """Whether a first-order motion extends to a closed curve, order by order.

    Attributes:
        blocked_at: the lowest order k (2 .. ``order``) whose condition no choice satisfies; None: every
            condition up to ``order`` holds.
        order: the bound checked.
        residuals: the smallest residual found at orders 2, 3, ... (up to ``blocked_at`` or ``order``),
            relative (``|g_k| / |y|^k``), to compare with ``tolerance``.
        tolerance: the threshold on them.
        rates: (n,) the first-order rates found (joint and cut coordinates, dimensionless, unit norm).
    """

    blocked_at: int | None
    order: int
    residuals: tuple[float, ...]
    tolerance: float
    rates: Array = field(repr=False)

    @property
    def deciding(self) -> tuple[int, float]:
        """(order, residual) that decided: the blocking order's, or (passing) the largest one's."""
        if self.blocked_at is not None:
            return self.blocked_at, self.residuals[-1]
        k = int(np.argmax(self.residuals)) if self.residuals else 0
        return k + 2, self.residuals[k] if self.residuals else 0.0

    @property
    def margin(self) -> float:
        """How clearly decided: ``residual / tol`` of the blocking order, or ``tol / residual`` of the largest."""
        order, residual = self.deciding
        if not self.residuals:
            return float("inf")
        if self.blocked_at is not None:
            return residual / self.tolerance
        return self.tolerance / max(residual, 1e-300)


class HigherOrder:
    """The conditions of orders 2, 3, ... at one configuration (some coordinates may be held).

    Args:
        loops: the mechanism's loops at the configuration.
        rtol: relative tolerance of the rank decision on ``A``.
        held: joint coordinates (tree columns) held fixed, e.g. locked actuators.
        order_tol: relative tolerance of the conditions (see the module docstring).
    """

    def __init__(self, loops: MechanismLoops, rtol: float, held: Sequence[int] = (), order_tol: float = ORDER_TOL):
        self.loops = loops
        self.system = system = loops.equations
        a = system.first_order()
        n = system.size
        free = np.ones(n, bool)
        free[list(held)] = False
        a_free = a[:, free]
        if a_free.size:  # one SVD gives the rank decision, the kernel, the cokernel and A^+
            u, s, vt = svd(a_free, full_matrices=True)
            dec = decision(s, vt, rtol)
        else:
            dec = decide_rank(a_free, rtol, n=int(free.sum()))
            u, s = np.eye(a.shape[0]), np.zeros(0)
        self.decision = dec
        rank = dec.rank
        self.kernel = np.zeros((n, n - int((~free).sum()) - rank))
        self.kernel[free] = dec.null_space.T
        self.cokernel = u[:, rank:]
        pinv = np.zeros((n, a.shape[0]))
        if rank:
            pinv[free] = dec.row_space.T @ np.diag(1.0 / s[:rank]) @ u[:, :rank].T
        self.pinv = pinv
        self.tol = order_tol * max(1.0, float(s[0]) if s.size else 1.0)
        self._forms: Array | None = None

    @property
    def m(self) -> int:
        """Instantaneous DoF (with the held coordinates held): the dimension of y."""
        return int(self.kernel.shape[1])

    @property
    def r(self) -> int:
        """Number of independent second- and higher-order conditions per order (rows of C)."""
        return int(self.cokernel.shape[1])

    def chain(self, y: Array, zs: Sequence[Array], order: int) -> Array:
        """(b, order - 1, r) the conditions ``g_2 .. g_order`` for a batch of y (b, m) and ``z_2..`` (each (b, m))."""
        system = self.system
        x = np.zeros((y.shape[0], order, system.size))
        x[:, 0] = y @ self.kernel.T
        out = np.zeros((y.shape[0], order - 1, self.r))
        for n in range(1, order):
            phi = system.jets(x[:, : n + 1])[:, n]
            out[:, n - 1] = phi @ self.cokernel
            if n < order - 1:
                x[:, n] = -phi @ self.pinv.T + zs[n - 1] @ self.kernel.T
        return out

    def forms(self) -> Array:
        """(r, m, m) the symmetric quadratic forms of order 2: ``g_2(y)_l = y^T H_l y``."""
        if self._forms is None and self.m == 0:
            self._forms = np.zeros((self.r, 0, 0))
        if self._forms is None:
            m, eye = self.m, np.eye(self.m)
            pairs = [(a, b) for a in range(m) for b in range(a, m)]
            ys = np.array([eye[a] + eye[b] for a, b in pairs] + list(eye)).reshape(-1, m)
            g = self.chain(ys, [], 2)[:, 0] if ys.size else np.zeros((0, self.r))
            diag = g[len(pairs) :]
            h = np.zeros((self.r, m, m))
            for i, (a, b) in enumerate(pairs):
                h[:, a, b] = h[:, b, a] = diag[a] if a == b else (g[i] - diag[a] - diag[b]) / 2
            self._forms = h
        return self._forms

    def test(
        self, y0: Array, lifts: Array | None = None, order: int = ORDER, rng: np.random.Generator | None = None
    ) -> OrderTest:
        """Whether ``y0 + lifts w`` (some w) extends to order ``order``.

        Args:
            y0: (m,) the first-order motion in kernel coordinates.
            lifts: (m, g) directions it may be combined with (e.g. internal motions that leave the
                platform still), or None.
            order: the highest order checked (>= 2).
            rng: for the restarts of the order-2 solve (default: seeded).
        """
        rng = rng or np.random.default_rng(0)
        g = np.zeros((self.m, 0)) if lifts is None else lifts
        scale = float(np.linalg.norm(y0)) or 1.0
        y0 = y0 / scale
        h = self.forms()

        def second(w: Array) -> Array:
            y = y0 + g @ w
            return np.einsum("lab,a,b->l", h, y, y) / max(float(y @ y), 1e-300)

        best = np.zeros(g.shape[1])
        if g.shape[1] and self.r:  # from no lift, then (if that does not do) from two random ones
            for w in [best] + [rng.normal(scale=0.5, size=g.shape[1]) for _ in range(2)]:
                from scipy.optimize import least_squares  # SciPy is loaded when a finite analysis runs

                fit = least_squares(second, w, method="trf", xtol=1e-15, ftol=1e-15, gtol=1e-15)
                if not np.any(best) or np.max(np.abs(fit.fun)) < np.max(np.abs(second(best))):
                    best = fit.x
                if np.max(np.abs(second(best))) <= self.tol:
                    break
        residuals = [float(np.max(np.abs(second(best)))) if self.r else 0.0]
        y = (y0 + g @ best) / np.linalg.norm(y0 + g @ best)
        rates = self.kernel @ y
        if residuals[0] > self.tol:
            return OrderTest(2, order, tuple(residuals), self.tol, rates)
        zs: list[Array] = []
        for k in range(3, order + 1):
            z, res = self._newest(y, zs, k)
            if res <= self.tol:
                zs.append(z)
            else:  # the newest free part alone does not do: solve every parameter together
                y, zs, res = self._joint(y, g, zs, k)
                rates = self.kernel @ y
            residuals.append(res)
            if res > self.tol:
                return OrderTest(k, order, tuple(residuals), self.tol, rates)
        return OrderTest(None, order, tuple(residuals), self.tol, rates)

    def _newest(self, y: Array, zs: list[Array], k: int) -> tuple[Array, float]:
        """Least-squares ``z_(k-1)`` for ``g_k`` (affine in it) with the rest fixed: (z, relative residual)."""
        m = self.m
        trial = np.vstack([np.zeros(m), np.eye(m)])
        batch = [np.repeat(z[None], m + 1, axis=0) for z in zs] + [trial]
        g = self.chain(np.repeat(y[None], m + 1, axis=0), batch, k)[:, k - 2]
        c, jac = g[0], (g[1:] - g[0]).T
        z = np.linalg.lstsq(jac, -c, rcond=None)[0] if m else np.zeros(0)
        return z, float(np.max(np.abs(c + jac @ z))) if c.size else 0.0

    def _joint(self, y: Array, g: Array, zs: list[Array], k: int) -> tuple[Array, list[Array], float]:
        """Every parameter (lift w and z_2 .. z_(k-1)) solved together for ``g_2 .. g_k``; the order-k residual."""
        m, nw = self.m, g.shape[1]
        base = y.copy()

        def unpack(p: Array) -> tuple[Array, list[Array]]:
            yy = base + g @ p[:nw]
            return yy / np.linalg.norm(yy), [p[nw + i * m : nw + (i + 1) * m][None] for i in range(k - 2)]

        def fun(p: Array) -> Array:
            yy, zz = unpack(p)
            return self.chain(yy[None], zz, k)[0].ravel()

        p0 = np.concatenate([np.zeros(nw)] + list(zs) + [np.zeros(m)] * (k - 2 - len(zs)))
        from scipy.optimize import least_squares  # SciPy is loaded when a finite analysis runs

        fit = least_squares(fun, p0, method="trf", max_nfev=JOINT_SOLVE_EVALUATIONS, xtol=1e-15, ftol=1e-15)
        yy, zz = unpack(fit.x)
        out = self.chain(yy[None], zz, k)[0]
        worst = float(np.max(np.abs(out[:-1]))) if k > 2 and out[:-1].size else 0.0
        res = max(worst, float(np.max(np.abs(out[-1]))) if out[-1].size else 0.0)
        return yy, [z[0] for z in zz], res
