"""A coordinate's Taylor series along a joint curve: joint values, fixed tendons, tendons straight between sites.

Along a curve with derivatives ``x^(1), x^(2), ...`` at t = 0 (the dimensionless coordinates of a
:class:`~pinmob.screw.lie.LoopSystem`), a coordinate's change ``c(t) - c(0) = sum_m c_m t^m`` has exact
coefficients:

- linear in joint values (a joint's value, a fixed tendon's length ``sum_j coef_j q_j``): ``c_m = a . x^(m) / m!``;
- the length of a tendon routed straight between sites (a spatial tendon with no wrapping geom and no
  pulley, MuJoCo's ``ten_length = sum_i |p_(i+1) - p_i|``): each site p on body b moves with the body's twist
  ``V_b = [v; w]`` (at the reference point, ``[v / L; w]``), ``p' = v + w x p``, so that

      p^(n+1) = v^(n) + sum_(a=0..n) C(n, a) w^(a) x p^(n-a)

  from the bodies' twists' derivatives (:meth:`~pinmob.screw.lie.LoopSystem.jets_and_twists`); each segment's
  squared length is a product of series and its length the series' square root
  (``r_0 = sqrt(s_0)``, ``r_m = (s_m - sum_(j=1..m-1) r_j r_(m-j)) / (2 r_0)``).

:mod:`pinmob.analysis.finite.coupling_rows` composes them with a coupling's polynomial.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from math import comb, factorial

import numpy as np

from pinmob.screw.algebra import Array


def truncated_product(a: Array, b: Array) -> Array:
    """(batch, k + 1) the product of two power series per row (or per (..., k + 1) row), truncated at degree k."""
    k = a.shape[-1]
    out = np.zeros(np.broadcast_shapes(a.shape, b.shape))
    for i in range(k):
        out[..., i:] += a[..., i : i + 1] * b[..., : k - i]
    return out


def _sqrt_series(s: Array) -> Array:
    """(batch, k + 1) the square root of a power series with ``s_0 > 0``, truncated at degree k."""
    r = np.zeros_like(s)
    r[:, 0] = np.sqrt(s[:, 0])
    for m in range(1, s.shape[1]):
        r[:, m] = (s[:, m] - np.sum(r[:, 1:m] * r[:, m - 1 : 0 : -1], axis=1)) / (2.0 * r[:, 0])
    return r


@dataclass(frozen=True)
class Coordinate:
    """A joint value, a fixed tendon's length or a tendon path between sites, near q (see the module docstring).

    Attributes:
        row: (n,) its rate on the dimensionless coordinates, when linear (zeros for a site path).
        value: its value at q [rad or m].
        bodies: (P,) the loop system's bodies carrying the path's sites (empty when linear).
        points: (P, 3) the sites at q, ``(p - reference) / L``.
        length: L [m]: a site path's series is in metres.
    """

    row: Array
    value: float
    bodies: tuple[int, ...] = ()
    points: Array = field(default_factory=lambda: np.zeros((0, 3)))
    length: float = 1.0

    @property
    def is_path(self) -> bool:
        """A path between sites (its series needs the bodies' twists)."""
        return bool(self.bodies)

    def series(self, x: Array, twists: Array | None) -> Array:
        """(b, k + 1) the Taylor coefficients of its change along ``x`` (b, k, n); ``twists`` (b, k, B, 6) for a path."""
        batch, k, _ = x.shape
        out = np.zeros((batch, k + 1))
        if not self.is_path:
            out[:, 1:] = (x @ self.row) / np.array([factorial(m + 1) for m in range(k)])
            return out
        assert twists is not None
        total = np.zeros((batch, k + 1))
        jets = [self._site(twists, b, p) for b, p in zip(self.bodies, self.points, strict=True)]  # (b, k + 1, 3)
        for a, b in zip(jets[:-1], jets[1:], strict=True):
            d = b - a
            total += _sqrt_series(np.sum(truncated_product(np.moveaxis(d, 1, 2), np.moveaxis(d, 1, 2)), axis=1))
        out[:, 1:] = self.length * total[:, 1:]
        return out

    @staticmethod
    def _site(twists: Array, body: int, point: Array) -> Array:
        """(b, k + 1, 3) the Taylor coefficients of a site's position on ``body`` (``p^(m) / m!``)."""
        batch, k = twists.shape[0], twists.shape[1]
        v, w = twists[:, :, body, :3], twists[:, :, body, 3:]
        p = np.zeros((batch, k + 1, 3))  # derivatives first
        p[:, 0] = point
        for n in range(k):
            p[:, n + 1] = v[:, n] + sum(comb(n, a) * np.cross(w[:, a], p[:, n - a]) for a in range(n + 1))
        return p / np.array([float(factorial(m)) for m in range(k + 1)])[None, :, None]
