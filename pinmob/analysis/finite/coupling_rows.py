"""Couplings as higher-order constraint rows: polynomials in coordinates whose derivatives are exact.

A coupling closure (:data:`pinmob.model.closure.COUPLINGS`) is no cut joint between two frames but one
scalar equation between coordinates: MuJoCo's ``<equality joint>``, ``q1 - r1 = P(q2 - r2)``, and
``<equality tendon>``, ``l1 - r1 = P(l2 - r2)``, on fixed tendons (``l = sum_j c_j q_j``, linear in joint values:
:class:`~pinmob.model.tendon.FixedTendon`) or tendons routed straight between sites (``l = sum_i |p_(i+1) - p_i|``);
a tendon actuator held is the tendon equality ``l - l(q) = 0`` (:func:`hold_tendons`). Near q, with ``c1(t)``,
``c2(t)`` the two coordinates along a curve (:class:`~pinmob.analysis.finite.coupling_rows.Coordinate`: their
Taylor series are exact), each coupling is

    f(t) = s (c1(t) - c1(0)) - P~(c2(t) - c2(0)) = 0,     P~(u) = s (P(u0 + u) - P(u0)),

``u0 = c2(0) - r2`` and ``s = 1 / L`` when coordinate 1 is a length (else 1). With ``x^(1), x^(2), ...`` the
curve's derivatives at t = 0, ``f^(n+1) = (n + 1)! [t^(n+1)] f`` from the truncated power series of the
composition: ``A x^(n+1) + R_n(x^(1..n))`` as for the loops' rows (:mod:`pinmob.screw.lie`).
:class:`CoupledSystem` appends these rows to a :class:`~pinmob.screw.lie.LoopSystem`, so that
:class:`pinmob.analysis.finite.higher_order.HigherOrder` treats them as it treats the loops. A tendon that wraps geoms
or runs over a pulley has no such series here (:func:`~pinmob.analysis.finite.sampled_side.unwritten`), nor
has an actuator's length that MuJoCo computes: a side with a coupling on one (or such an actuator held) is
decided from closed samples alone and never reaches :func:`coupling_rows`.
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from math import comb, factorial

import numpy as np
import pinocchio as pin

from pinmob.analysis.chain.closed_chain import closed_chain_columns
from pinmob.analysis.configuration import Configuration
from pinmob.exceptions import ConfigurationError
from pinmob.model import Closure, ClosureType, FixedTendon, Tendon, Transmission, make_tendon_coupling
from pinmob.screw import Array, LoopSystem


@dataclass(frozen=True)
class CouplingRow:
    """One coupling ``f = s (c1 - c1(q)) - P~(c2 - c2(q))`` on the n coordinates of a loop system.

    Attributes:
        name: the closure's name.
        first: coordinate 1 (:class:`~pinmob.analysis.finite.coupling_rows.Coordinate`).
        second: coordinate 2 (None for a coupling of one coordinate).
        poly: coefficients of ``P~`` (``poly[0] == 0``), already times ``scale``.
        scale: ``1 / L`` when coordinate 1 is a length, else 1.
    """

    name: str
    first: Coordinate
    second: Coordinate | None
    poly: tuple[float, ...]
    scale: float = 1.0

    @property
    def needs_twists(self) -> bool:
        """Either coordinate is a path between sites."""
        return self.first.is_path or (self.second is not None and self.second.is_path)

    def series(self, x: Array, twists: Array | None) -> Array:
        """(b, k + 1) the Taylor coefficients of f along ``x`` (b, k, n)."""
        out = self.scale * self.first.series(x, twists)
        if self.second is not None and len(self.poly) > 1:
            inner = self.second.series(x, twists)
            power = np.zeros_like(inner)
            power[:, 0] = 1.0
            for coefficient in self.poly[1:]:
                power = truncated_product(power, inner)
                out -= coefficient * power
        return out


@dataclass(frozen=True)
class CoupledSystem:
    """A loop system and coupling rows: the closure equations near q, loops first, then one row per coupling.

    Same interface as :class:`~pinmob.screw.lie.LoopSystem` (``size``, ``first_order``, ``jets``).

    Attributes:
        loops: the loops' system.
        rows: the couplings.
    """

    loops: LoopSystem
    rows: tuple[CouplingRow, ...] = ()

    @property
    def size(self) -> int:
        """Number of coordinates n (joint and cut)."""
        return self.loops.size

    def first_order(self) -> Array:
        """(6 c + k, n) the loops' ``A`` then the couplings' rows (their first derivatives along each coordinate).

        With couplings, ``Phi^(0)`` along each unit coordinate rate, loops and couplings in one pass (the loops'
        part is ``A``'s column, exactly).
        """
        if not self.rows:
            return self.loops.first_order()
        return self.jets(np.eye(self.size)[:, None, :])[:, 0].T

    def jets(self, x: Array) -> Array:
        """The derivatives ``Phi^(0..k-1)`` of the loops' twists then of the couplings (see the module docstring).

        Args:
            x: (k, n) or (b, k, n), ``x[..., i, :] = x^(i+1)``.

        Returns:
            (k, 6 c + r) or (b, k, 6 c + r).
        """
        if not self.rows:
            return self.loops.jets(x)
        xb = x[None] if x.ndim == 2 else x
        if any(r.needs_twists for r in self.rows):
            loops, twists = self.loops.jets_and_twists(xb)
        else:
            loops, twists = self.loops.jets(xb), None
        k = xb.shape[1]
        factorials = np.array([float(factorial(i + 1)) for i in range(k)])
        out = np.stack([factorials * row.series(xb, twists)[:, 1:] for row in self.rows], axis=-1)
        both = np.concatenate([loops, out], axis=-1)
        return both if x.ndim == 3 else both[0]


def has_series(tendon: Tendon) -> bool:
    """True for a tendon whose length's Taylor series is written: a fixed tendon, or one straight between sites."""
    return isinstance(tendon, FixedTendon) or bool(tendon.site_frames())


def is_polynomial(closure: Closure) -> bool:
    """True for a coupling the higher-order analysis writes as a row.

    A joint coupling, or a tendon coupling on tendons that each have a written series (:func:`has_series`).
    """
    return closure.type is ClosureType.JOINT or all(has_series(t) for t in closure.tendons)


def _linear(
    model: pin.Model, q: Array, col: Array, n: int, joints: tuple[str, ...], coefs: tuple[float, ...]
) -> Coordinate:
    """The :class:`Coordinate` ``sum_j c_j q_j`` (one-degree joints)."""
    row, value = np.zeros(n), 0.0
    for joint, c in zip(joints, coefs, strict=True):
        j = model.joints[model.getJointId(joint)]
        value += c * float(q[j.idx_q])
        row[j.idx_v] += c * float(col[j.idx_v])
    return Coordinate(row, value)


def _path(conf: Configuration, frames: tuple[int, ...], reference: Array, n: int) -> Coordinate:
    """The :class:`Coordinate` of a tendon straight between the sites of ``frames`` (its length [m])."""
    model, length = conf.mechanism.model, conf.mechanism.length_scale
    points = np.array([conf.frame_placement(f).translation for f in frames])
    value = float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1)))
    bodies = tuple(int(model.frames[f].parentJoint) for f in frames)
    return Coordinate(np.zeros(n), value, bodies, (points - reference) / length, length)


def _tendon(conf: Configuration, tendon: Tendon, closure: Closure, col: Array, reference: Array, n: int) -> Coordinate:
    if isinstance(tendon, FixedTendon):
        return _linear(conf.mechanism.model, conf.q, col, n, tendon.joints, tendon.coefficients)
    if has_series(tendon):
        path = _path(conf, tendon.site_frames(), reference, n)
        if np.min(np.linalg.norm(np.diff(path.points, axis=0), axis=1)) <= 1e-12:
            raise ConfigurationError(
                f"the higher-order (finite mobility) analysis cannot treat tendon coupling {closure.name!r}: two "
                f"consecutive sites of tendon {tendon.name!r} coincide at this configuration (its length is not "
                "differentiable there); analyse without `finite=True`"
            ).naming("finite")
        return path
    # finite_mobility sends a side with such a coupling to the closed samples (sampled_side): never here
    raise AssertionError(f"tendon {tendon.name!r} of coupling {closure.name!r} has no written series")


def coupling_rows(
    conf: Configuration, closures: tuple[Closure, ...], col: Array, n: int, reference: Array
) -> tuple[CouplingRow, ...]:
    """The :class:`CouplingRow` of each coupling closure among ``closures`` at ``conf`` (n coordinates).

    ``reference``: (3,) the loop system's reference point [m].

    Raises:
        ConfigurationError: a tendon coupling on a tendon that wraps geoms or runs over a pulley (named).
    """
    model = conf.mechanism.model
    out = []
    for c in closures:
        if not c.is_coupling:
            continue
        if c.type is ClosureType.JOINT:
            coords = [_linear(model, conf.q, col, n, (j,), (1.0,)) for j in c.joints]
            linear = "Prismatic" in model.joints[model.getJointId(c.joints[0])].shortname()
        else:
            coords = [_tendon(conf, t, c, col, reference, n) for t in c.tendons]
            linear = c.tendons[0].linear
        s = 1.0 / conf.mechanism.length_scale if linear else 1.0
        second, coefs = None, np.zeros(1)
        if len(coords) > 1:
            second = coords[1]
            poly = np.polynomial.Polynomial(c.polycoef)
            coefs = np.array(poly(np.polynomial.Polynomial([second.value - c.reference[1], 1.0])).coef, float)
            coefs[0] = 0.0
        out.append(CouplingRow(c.name, coords[0], second, tuple(float(v) * s for v in coefs), s))
    return tuple(out)


def hold_tendons(conf: Configuration) -> tuple[Configuration, tuple[str, ...], tuple[Transmission, ...]]:
    """``conf`` with its tendon actuators (and MuJoCo's other actuators with a length) held as tendon equalities.

    An actuator on a tendon held keeps the tendon's length at its value: the tendon closure ``l - l(q) = 0``
    (one coordinate, ``polycoef = 0``), written on the closed chain's residual too, so that the tracing and the
    closed samples hold it as the conditions do. On a fixed tendon or one straight between sites it is a row
    exact at every order; on a tendon that wraps geoms or runs over a pulley, and on an actuator's slider-crank,
    ball-joint or site length (:class:`~pinmob.io.mjcf.actuator_lengths.ActuatorLength`), it has no written series
    (:func:`~pinmob.analysis.finite.sampled_side.unwritten`), and the side with it is decided from closed samples alone.

    Returns:
        the configuration of the mechanism with those closures (``conf`` itself when there are none), the
        names of the actuators held so, and the other transmissions (on a site without a reference site, a free joint:
        not held).
    """
    mech = conf.mechanism
    model = mech.model
    extra, held, others = [], [], []
    taken = {c.name for c in mech.all_closures}
    for t in mech.actuated_tendons:
        tendon = t.driven_tendon(model)
        if tendon is None:
            others.append(t)
            continue
        length, row = tendon.length(model, conf.data)
        frames = list(tendon.site_frames())
        if not frames:  # a fixed or wrapping tendon: placed on the frames of the joints that move it at q
            ids = {j for j in range(1, model.njoints) if np.any(row[model.idx_vs[j] : model.idx_vs[j] + model.nvs[j]])}
            ids = ids or set(tendon.joint_ids(model))
            frames = [i for i, f in enumerate(model.frames) if f.parentJoint in ids and f.type == pin.FrameType.JOINT]
            frames = frames or [0]
        name = f"actuator {t.name}"
        while name in taken:
            name += "'"
        extra.append(make_tendon_coupling(model, name, (tendon,), (0.0,), (length,), (frames[0], frames[-1])))
        held.append(t.name)
    if not extra:
        return conf, (), tuple(others)
    locked = replace(mech, closures=mech.closures + tuple(extra), actuated_tendons=tuple(others))
    return Configuration.from_checked(locked, conf.q, conf.closure_tol, name=conf.name), tuple(held), tuple(others)


#: Sine of the angle above which an actuator's moment arms and its length's derivative are not one direction.
ROW_SINE = 1e-6


def moments_off_lengths(conf: Configuration) -> tuple[str, ...]:
    """The held actuators whose moment arms at q are not along their length's derivative.

    The moment arms (:meth:`~pinmob.model.tendon.Transmission.rate_row`, MuJoCo's ``actuator_moment``) are what
    the first-order actuation holds; the length's derivative is what the finite analysis holds
    (:func:`hold_tendons`). MuJoCo's moment arms leave out the expmap's Jacobian on a ball turned away from its
    zero and the reference site's turning on a site transmission. Directions are compared on the dimensionless joint rates (sine above
    :data:`ROW_SINE`, or one of the two rows zero and not the other).
    """
    mech = conf.mechanism
    if not mech.actuated_tendons:
        return ()
    model, col = mech.model, closed_chain_columns(conf)
    out = []
    for t in mech.actuated_tendons:
        tendon = t.driven_tendon(model)
        if tendon is None:
            continue
        a, b = t.rate_row(model, conf.q) * col, tendon.length(model, conf.data)[1] * col
        na, nb = float(np.linalg.norm(a)), float(np.linalg.norm(b))
        if na == 0 or nb == 0:
            off = na != nb
        else:
            a, b = a / na, b / nb
            off = float(np.linalg.norm(b - (a @ b) * a)) > ROW_SINE
        if off:
            out.append(t.name)
    return tuple(out)


# ------------------------------------------------------------------ coordinate series
#
# A coordinate's Taylor series along a joint curve: joint values, fixed tendons, tendons straight between sites.
#
# Along a curve with derivatives ``x^(1), x^(2), ...`` at t = 0 (the dimensionless coordinates of a
# :class:`~pinmob.screw.lie.LoopSystem`), a coordinate's change ``c(t) - c(0) = sum_m c_m t^m`` has exact
# coefficients:
#
# - linear in joint values (a joint's value, a fixed tendon's length ``sum_j coef_j q_j``): ``c_m = a . x^(m) / m!``;
# - the length of a tendon routed straight between sites (a spatial tendon with no wrapping geom and no
#   pulley, MuJoCo's ``ten_length = sum_i |p_(i+1) - p_i|``): each site p on body b moves with the body's twist
#   ``V_b = [v; w]`` (at the reference point, ``[v / L; w]``), ``p' = v + w x p``, so that
#
#       p^(n+1) = v^(n) + sum_(a=0..n) C(n, a) w^(a) x p^(n-a)
#
#   from the bodies' twists' derivatives (:meth:`~pinmob.screw.lie.LoopSystem.jets_and_twists`); each segment's
#   squared length is a product of series and its length the series' square root
#   (``r_0 = sqrt(s_0)``, ``r_m = (s_m - sum_(j=1..m-1) r_j r_(m-j)) / (2 r_0)``).
#
# The coupling rows above compose them with a coupling's polynomial.


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
