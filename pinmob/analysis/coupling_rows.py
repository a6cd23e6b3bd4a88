"""Couplings as higher-order constraint rows: polynomials in joint values, differentiated exactly.

A coupling closure (:data:`pinmob.model.closure.COUPLINGS`) is no cut joint between two frames but one
scalar equation between coordinates: MuJoCo's ``<equality joint>``, ``q1 - r1 = P(q2 - r2)``, and
``<equality tendon>`` on fixed tendons, ``l1 - r1 = P(l2 - r2)`` with ``l = sum_j c_j q_j`` linear in the
joint values (:class:`~pinmob.model.tendon.FixedTendon`); a fixed-tendon actuator held is the tendon
equality ``l - l(q) = 0`` (:func:`hold_tendons`). Near q, with ``x`` the dimensionless joint coordinates
(``dq = col x``, :func:`pinmob.analysis.closure_jacobian.closed_chain_columns`) and ``dx = x(t) - x(0)``, each is

    f(t) = a . dx(t) - P~(b . dx(t)) = 0,     P~(s) = P(s0 + s) - P(s0),

``a`` and ``b`` the rows of coordinates 1 and 2 on x (divided by L when coordinate 1 is a length), ``s0``
coordinate 2's offset at q. Along a curve with derivatives ``x^(1), x^(2), ...`` at t = 0,
``dx(t) = sum_i x^(i) t^i / i!``; the derivative of order ``n + 1`` of f is then exact:

    f^(n+1) = a . x^(n+1) - (n + 1)! [t^(n+1)] P~(sum_i (b . x^(i)) t^i / i!),

the power series of the composition truncated at degree ``n + 1``: ``A x^(n+1) + R_n(x^(1..n))`` as for the
loops' rows (:mod:`pinmob.screw.lie`). :class:`CoupledSystem` appends these rows to a
:class:`~pinmob.screw.lie.LoopSystem`, so that :class:`pinmob.analysis.higher_order.HigherOrder` treats them
as it treats the loops. A tendon routed over sites and wrapping geoms (a spatial tendon) has a length that is
no polynomial in joint values: a coupling or held actuator on one is refused (:func:`coupling_rows`) or left
unheld (:func:`hold_tendons`), by name.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from math import factorial

import numpy as np
import pinocchio as pin

from pinmob.analysis.configuration import Configuration
from pinmob.exceptions import ConfigurationError
from pinmob.model.closure import Closure, ClosureType, make_tendon_coupling
from pinmob.model.tendon import FixedTendon, Tendon, TendonActuator, Transmission
from pinmob.screw.algebra import Array
from pinmob.screw.lie import LoopSystem


@dataclass(frozen=True)
class CouplingRow:
    """One coupling ``f = a . dx - P~(b . dx)`` on the n coordinates of a loop system (module docstring).

    Attributes:
        name: the closure's name.
        first: (n,) the row ``a``.
        second: (n,) the row ``b`` (zeros for a coupling of one coordinate).
        poly: coefficients of ``P~`` (``poly[0] == 0``), already divided by L where ``a`` is.
    """

    name: str
    first: Array
    second: Array
    poly: tuple[float, ...]


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
        """(6 c + k, n) the loops' ``A`` then the couplings' rows ``a - P~'(0) b``."""
        rows = [r.first - (r.poly[1] if len(r.poly) > 1 else 0.0) * r.second for r in self.rows]
        return np.vstack([self.loops.first_order(), np.array(rows).reshape(len(rows), self.size)])

    def jets(self, x: Array) -> Array:
        """The derivatives ``Phi^(0..k-1)`` of the loops' twists then of the couplings (see the module docstring).

        Args:
            x: (k, n) or (b, k, n), ``x[..., i, :] = x^(i+1)``.

        Returns:
            (k, 6 c + r) or (b, k, 6 c + r).
        """
        loops = self.loops.jets(x)
        if not self.rows:
            return loops
        xb = x[None] if x.ndim == 2 else x
        k = xb.shape[1]
        scale = np.array([1.0 / factorial(i + 1) for i in range(k)])
        out = np.empty((xb.shape[0], k, len(self.rows)))
        for c, row in enumerate(self.rows):
            series = np.zeros((xb.shape[0], k + 1))  # b . dx(t): coefficients of t^0 .. t^k
            series[:, 1:] = (xb @ row.second) * scale
            composed = np.zeros_like(series)  # P~(series), truncated at degree k
            power = np.zeros_like(series)
            power[:, 0] = 1.0
            for coefficient in row.poly[1:]:
                power = _truncated_product(power, series)
                composed += coefficient * power
            factorials = np.array([float(factorial(i + 1)) for i in range(k)])
            out[:, :, c] = xb @ row.first - factorials * composed[:, 1:]
        both = np.concatenate([loops if x.ndim == 3 else loops[None], out], axis=-1)
        return both if x.ndim == 3 else both[0]


def _truncated_product(a: Array, b: Array) -> Array:
    """(batch, k + 1) the product of two power series per row, truncated at degree k."""
    k = a.shape[1]
    out = np.zeros_like(a)
    for i in range(k):
        out[:, i:] += a[:, i : i + 1] * b[:, : k - i]
    return out


def _joint_index(model: pin.Model, name: str) -> tuple[int, int]:
    """(q index, velocity index) of a one-degree joint."""
    joint = model.joints[model.getJointId(name)]
    return joint.idx_q, joint.idx_v


def is_polynomial(closure: Closure) -> bool:
    """True for a coupling the higher-order analysis writes as a row: a joint one, or a tendon one on fixed tendons."""
    return closure.type is ClosureType.JOINT or all(isinstance(t, FixedTendon) for t in closure.tendons)


def _fixed(tendon: Tendon, closure: Closure) -> FixedTendon:
    if not isinstance(tendon, FixedTendon):
        raise ConfigurationError(
            f"the higher-order (finite mobility) analysis cannot treat tendon coupling {closure.name!r} on spatial "
            f"tendon {tendon.name!r} (routed over sites or wrapping geoms: its length is no polynomial in joint "
            "values); analyse without --finite"
        )
    return tendon


def _coordinate(
    model: pin.Model, q: Array, col: Array, n: int, joints: tuple[str, ...], coefs: tuple[float, ...]
) -> tuple[float, Array]:
    """(value at q, (n,) row on the dimensionless coordinates) of ``sum_j c_j q_j``."""
    row, value = np.zeros(n), 0.0
    for joint, c in zip(joints, coefs, strict=True):
        iq, iv = _joint_index(model, joint)
        value += c * float(q[iq])
        row[iv] += c * float(col[iv])
    return value, row


def coupling_rows(conf: Configuration, closures: tuple[Closure, ...], col: Array, n: int) -> tuple[CouplingRow, ...]:
    """The :class:`CouplingRow` of each coupling closure among ``closures`` at ``conf`` (n coordinates).

    Raises:
        ConfigurationError: a tendon coupling on a spatial tendon (named, with the closure).
    """
    mech = conf.mechanism
    model, q, length = mech.model, conf.q, mech.length_scale
    out = []
    for c in closures:
        if not c.is_coupling:
            continue
        parts: list[tuple[tuple[str, ...], tuple[float, ...]]]
        if c.type is ClosureType.JOINT:
            parts = [((j,), (1.0,)) for j in c.joints]
            linear = "Prismatic" in model.joints[model.getJointId(c.joints[0])].shortname()
        else:
            tendons = [_fixed(t, c) for t in c.tendons]
            parts = [(t.joints, t.coefficients) for t in tendons]
            linear = c.tendons[0].linear
        _, first = _coordinate(model, q, col, n, *parts[0])
        poly = np.polynomial.Polynomial(c.polycoef)
        if len(parts) > 1:
            value, second = _coordinate(model, q, col, n, *parts[1])
            shifted = poly(np.polynomial.Polynomial([value - c.reference[1], 1.0]))
            coefs = np.array(shifted.coef, float)
            coefs[0] = 0.0
        else:
            second, coefs = np.zeros(n), np.zeros(1)
        s = 1.0 / length if linear else 1.0
        out.append(CouplingRow(c.name, s * first, second, tuple(float(v) * s for v in coefs)))
    return tuple(out)


def hold_tendons(conf: Configuration) -> tuple[Configuration, tuple[str, ...], tuple[Transmission, ...]]:
    """``conf`` with its fixed-tendon actuators held as tendon equalities at their lengths at q.

    An actuator on a fixed tendon held keeps ``l = sum_j c_j q_j`` at its value: the tendon closure
    ``l - l(q) = 0`` (one coordinate, ``polycoef = 0``), exact at every order, and written on the closed
    chain's residual too, so that the tracing and the closed samples hold it as the conditions do.

    Returns:
        the configuration of the mechanism with those closures (``conf`` itself when there are none), the
        names of the actuators held so, and the other transmissions (a spatial tendon's, a site's, ...:
        their moment arms change with q in a way no polynomial in joint values gives; not held).
    """
    mech = conf.mechanism
    model = mech.model
    fixed = [t for t in mech.actuated_tendons if isinstance(t, TendonActuator)]
    others = tuple(t for t in mech.actuated_tendons if not isinstance(t, TendonActuator))
    if not fixed:
        return conf, (), others
    extra = []
    taken = {c.name for c in mech.all_closures}
    for t in fixed:
        linear = any("Prismatic" in model.joints[model.getJointId(j)].shortname() for j in t.joints)
        tendon = FixedTendon(t.tendon, t.joints, t.coefficients, linear)
        length, _ = _coordinate(model, conf.q, np.ones(model.nv), model.nv, t.joints, t.coefficients)
        frames = [
            i
            for j in t.joints
            for i, f in enumerate(model.frames)
            if f.parentJoint == model.getJointId(j) and f.type == pin.FrameType.JOINT
        ]
        name = f"actuator {t.name}"
        while name in taken:
            name += "'"
        extra.append(make_tendon_coupling(model, name, (tendon,), (0.0,), (length,), (frames[0], frames[-1])))
    held = replace(mech, closures=mech.closures + tuple(extra), actuated_tendons=others)
    return (
        Configuration(held, conf.q, closure_tol=conf.closure_tol, name=conf.name),
        tuple(t.name for t in fixed),
        others,
    )
