"""The second-order tangent cone at a configuration, split into linear components: the motion branches.

The first-order motions y (kernel coordinates of :class:`pinmob.analysis.finite.higher_order.HigherOrder`)
that pass the order-2 conditions form the cone ``{y : y^T H_l y = 0 for every l}``, the quadratic forms
of order 2 (Müller, J. Mechanisms Robotics 8(4):041013, 2016). Where motion branches cross
transversally it is the union of their tangent spaces: :func:`cone` finds those linear components
(definite forms first, exactly; then cone points from random starts, grouped by their polar values),
and checks each to the order bound. A cone that is not a finite union of linear spaces (a quadric
cone: a branch that is itself singular at q) is reported as such: its branches cannot be told apart.

The sampling is adaptive, so that the answer does not hang on the random starts (hence on the
seed, the units or where the mechanism stands, which change the kernel's basis): rounds of
``CONE_STARTS * k`` starts (drawn in joint-rate space, which neither units nor placement change,
projected on the kernel) go on until a round finds no new group of cone points and every group
holds two points or more, at least two rounds and at most ``CONE_ROUNDS``. A finite union of
linear spaces is hit again and again on each component; a continuum of lines keeps leaving lone
points.
A decision within a factor ``MARGIN`` of its tolerance (a definite form's eigenvalue, the forms
vanishing on the whole kernel, a component's higher-order test) decides nothing: ``Cone.undecided``
says which.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinmob.analysis.finite.higher_order import MARGIN, ORDER, HigherOrder, OrderTest
from pinmob.frozen import ReadOnlyArrays
from pinmob.screw import Array, decide_rank

#: Random starts per dimension of the reduced cone in each round of sampling.
CONE_STARTS = 4
#: Most rounds of sampling (see the module docstring for when it stops earlier).
CONE_ROUNDS = 4
#: Gauss-Newton steps of a cone point's search before SciPy's Levenberg-Marquardt takes over.
NEWTON_STEPS = 30
#: Two cone points span a line of the cone when their polar values are below this (relative to max |H|).
POLAR_TOL = 1e-4


@dataclass(frozen=True)
class ConeComponent(ReadOnlyArrays):
    """A linear component of the second-order tangent cone: the tangent space of a motion branch.

    Attributes:
        basis: (m, d) orthonormal basis in kernel coordinates (``x^(1) = N y``).
        test: the higher-order conditions along a random direction of it.
    """

    basis: Array
    test: OrderTest

    @property
    def dimension(self) -> int:
        """Its dimension d."""
        return int(self.basis.shape[1])


@dataclass(frozen=True)
class Cone:
    """The second-order tangent cone at q, split into linear components (:meth:`HigherOrder.cone`).

    Attributes:
        components: its linear components passing every condition up to the order bound.
        blocked: components passing order 2 but blocked at a higher order.
        linear: the cone was found to be a union of linear spaces (False: some cone points lie on no
            linear component of dimension > 0 found, e.g. a quadric cone; the branches cannot be told).
        points: cone points found (directions in kernel coordinates) and starts tried.
        undecided: why a decision on the cone was within ``MARGIN`` of its tolerance ('' when none was).
    """

    components: tuple[ConeComponent, ...]
    blocked: tuple[ConeComponent, ...]
    linear: bool
    points: tuple[int, int]
    undecided: str = ""


def cone_point(h: Array, start: Array) -> Array:
    """A point of ``{y : y^T H_l y = 0, |y| = 1}`` near ``start`` (unnormalised; check ``Q`` at it).

    Gauss-Newton with minimum-norm steps on ``[Q(y); |y|^2 - 1]`` (Jacobian ``[2 H_l y; 2 y]``, the forms symmetric)
    until the step is below 1e-13, at most ``NEWTON_STEPS``; where that does not converge (a start near a singular
    point of the cone), SciPy's Levenberg-Marquardt from the same start.
    """
    y = start / np.linalg.norm(start)
    for _ in range(NEWTON_STEPS):
        f = np.append(np.einsum("lab,a,b->l", h, y, y), y @ y - 1.0)
        jac = np.vstack([2 * np.einsum("lab,b->la", h, y), 2 * y])
        try:  # the minimum-norm step J^T (J J^T)^-1 f (J has more columns than rows but for tiny kernels)
            step = jac.T @ np.linalg.solve(jac @ jac.T, f) if jac.shape[0] <= jac.shape[1] else None
        except np.linalg.LinAlgError:
            step = None
        if step is None or not np.all(np.isfinite(step)):
            step = np.linalg.lstsq(jac, f, rcond=None)[0]
        y = y - step
        if float(np.linalg.norm(step)) < 1e-13:
            return y
    from scipy.optimize import least_squares  # SciPy is loaded when a finite analysis runs

    k = h.shape[1]
    pad = np.zeros(max(0, k - h.shape[0] - 1))

    def fun(y: Array) -> Array:
        return np.concatenate([np.einsum("lab,a,b->l", h, y, y), [y @ y - 1.0], pad])

    def jac_lm(y: Array) -> Array:
        return np.vstack([2 * np.einsum("lab,b->la", h, y), 2 * y, np.zeros((pad.size, k))])

    return np.asarray(least_squares(fun, start, jac=jac_lm, method="lm", xtol=1e-12, ftol=1e-14, gtol=1e-14).x)


def _span(points: Array) -> Array:
    """(m, d) orthonormal basis of the span of unit rows ``points`` (directions closer than 1e-3 merged)."""
    return decide_rank(points, 1e-3).row_space.T  # the one rank rule: relative to the largest


def cone(ho: HigherOrder, order: int = ORDER, seed: int = 0) -> Cone:
    """The second-order cone ``{y : Q(y) = 0}`` at q as a union of linear components, each checked to ``order``.

    When every form vanishes, the cone is the whole kernel. Otherwise points of the cone on the unit
    sphere are found from random starts (:func:`cone_point`: least squares on ``[Q(y); |y|^2 - 1]``, rounds of them, see
    the module docstring); two points lie on one linear component when every polar value
    ``y_i^T H_l y_j`` vanishes (``POLAR_TOL`` of ``max |H|``): components are the groups of pairwise
    polar points, spanned. A component is kept when Q vanishes on its whole span and a random
    direction of it passes the conditions up to ``order``.
    """
    rng = np.random.default_rng(seed)
    m = ho.m
    h = ho.forms()
    if m == 0:
        return Cone((), (), True, (0, 0))
    top = float(np.max(np.abs(h))) if h.size else 0.0
    sub, undecided = definite_reduction(h, ho.tol)
    hs = np.einsum("lab,ai,bj->lij", h, sub, sub)
    largest = float(np.max(np.abs(hs), initial=0.0))
    if sub.shape[1] == 0 or largest <= ho.tol:
        if sub.shape[1] and largest > ho.tol / MARGIN:
            undecided = undecided or _within("the forms on the kernel", largest, ho.tol)
        return _classify([sub] if sub.shape[1] else [], ho, order, rng, True, (sub.shape[1], 0), undecided)
    if largest < ho.tol * MARGIN:
        undecided = undecided or _within("the forms on the kernel", largest, ho.tol)
    k = sub.shape[1]
    to_sub = sub.T @ ho.kernel[: ho.loops.nv].T  # a joint-rate direction's coordinates in the reduced cone's space
    groups: list[list[Array]] = []
    tried = found = 0
    for round_ in range(CONE_ROUNDS):
        known = len(groups)
        for _ in range(CONE_STARTS * max(k, 2)):
            start: Array = np.asarray(to_sub @ rng.normal(size=ho.loops.nv), float)
            if not np.linalg.norm(start) > 1e-9:
                start = np.asarray(rng.normal(size=k), float)
            x = cone_point(hs, start)
            y = sub @ (x / np.linalg.norm(x))
            tried += 1
            if float(np.max(np.abs(np.einsum("lab,a,b->l", h, y, y)))) <= ho.tol:
                found += 1
                _add(groups, y, h, POLAR_TOL * top)
        if round_ and len(groups) == known and all(len(g) > 1 for g in groups):
            break  # a round that found no new group, and every group seen twice
    spans: list[Array] = []
    for group in sorted(groups, key=len, reverse=True):
        if len(group) < 2:
            continue  # a lone point: on no linear component seen twice
        basis = _span(np.array(group))
        restricted = np.einsum("lab,ai,bj->lij", h, basis, basis)
        if float(np.max(np.abs(restricted))) > POLAR_TOL * top:
            continue
        if any(np.linalg.matrix_rank(np.hstack([s, basis]), 1e-3) == s.shape[1] for s in spans):
            continue  # inside a component found already
        spans = [s for s in spans if np.linalg.matrix_rank(np.hstack([s, basis]), 1e-3) > basis.shape[1]] + [basis]
    # a finite union of linear spaces is hit several times per component; a continuum of lines (a
    # quadric cone) leaves lone points
    linear = all(len(g) > 1 for g in groups)
    return _classify(spans, ho, order, rng, linear, (found, tried), undecided)


def _add(groups: list[list[Array]], y: Array, h: Array, tol: float) -> None:
    """Put the cone point y in the first group whose every point is polar to it (else in a new group)."""
    if groups:
        hy = np.einsum("lab,a->lb", h, y)  # the polar forms at y: y^T H_l x = (hy x)_l
        points = np.array([x for g in groups for x in g])
        owner = np.repeat(np.arange(len(groups)), [len(g) for g in groups])
        far = np.max(np.abs(hy @ points.T), axis=0) > tol  # per point: not polar to y
        fits = np.flatnonzero(np.bincount(owner, weights=far, minlength=len(groups)) == 0)
        if fits.size:
            groups[int(fits[0])].append(y)
            return
    groups.append([y])


def _within(what: str, value: float, tol: float) -> str:
    """The note of a decision within a factor ``MARGIN`` of its tolerance."""
    return f"{what}: {value:.2e} is within a factor {MARGIN:g} of the tolerance {tol:.2e}"


def definite_reduction(h: Array, tol: float) -> tuple[Array, str]:
    """(m, k) a basis of the subspace the cone ``{y : y^T H_l y = 0 for all l}`` lies in, from its definite forms.

    A semidefinite form vanishes exactly on its null space, so the cone lies in it: restrict every
    form to that null space and repeat while some non-zero form (or the sum of two) is semidefinite.
    Exact linear algebra; it settles the cones of shaky linkages (sums of squares) at once.

    Returns:
        the basis, and a note when an eigenvalue that decided was within a factor ``MARGIN`` of ``tol``
        ('' otherwise).
    """
    basis = np.eye(h.shape[1])
    note = ""
    while basis.shape[1]:
        hs = np.einsum("lab,ai,bj->lij", h, basis, basis)
        candidates = list(hs) + [hs[i] + sign * hs[j] for i in range(len(hs)) for j in range(i) for sign in (1, -1)]
        for form in candidates:
            values, vectors = np.linalg.eigh(form)
            if np.max(np.abs(values)) > tol and (values.min() >= -tol or values.max() <= tol):
                near = np.abs(values)[(np.abs(values) > tol / MARGIN) & (np.abs(values) < tol * MARGIN)]
                if near.size and not note:
                    note = _within("an eigenvalue of a semidefinite second-order form", float(near[0]), tol)
                basis = basis @ vectors[:, np.abs(values) <= tol]
                break
        else:
            return basis, note
    return basis, note


def _classify(
    spans: list[Array],
    ho: HigherOrder,
    order: int,
    rng: np.random.Generator,
    linear: bool,
    points: tuple[int, int],
    undecided: str = "",
) -> Cone:
    """Each span tested to ``order`` along a random direction: kept or blocked (a test within the margin: undecided)."""
    kept: list[ConeComponent] = []
    blocked: list[ConeComponent] = []
    for basis in spans:
        test = ho.test(basis @ rng.normal(size=basis.shape[1]), None, order, rng)
        if test.margin < MARGIN and not undecided:
            order_k, residual = test.deciding
            undecided = _within(f"a linear component's order-{order_k} condition", residual, test.tolerance)
        (blocked if test.blocked_at else kept).append(ConeComponent(basis, test))
    return Cone(tuple(kept), tuple(blocked), linear, points, undecided)
