"""Assertions for users' own test suites: ``assert_mobility``; and :func:`kinematics_calls`, a cost count.

Example (pytest)::

    import pinmob
    from pinmob.testing import assert_mobility

    def test_my_robot_translates():
        mech = pinmob.load("my_robot.toml")
        assert_mobility(mech, "home", dof=3, motion_type="3T",
                        directions={"T": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]})

On failure an ``AssertionError`` says what was expected and what was found,
with the singular values of the stacked constraint wrenches and the
tolerance of the rank decision, so a near-miss is visible at once. Bad
arguments (an unknown kind, a zero or non-finite direction, an unknown
method) raise a :class:`pinmob.ConfigurationError`.

``method="mechanism"`` checks the platform frame's motion on the whole closed
chain (``pinmob.analyze(...).mechanism_mobility``) instead of the limb-wise wrenches
(``pinmob.analyze(...).mobility``); both agree on limbs-and-platform mechanisms.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from pinmob.analysis import FrameMobility, Mobility, analyze
from pinmob.exceptions import ConfigurationError
from pinmob.model import Mechanism
from pinmob.screw import RTOL, Array, subspace_gap

KINDS = ("T", "R", "H")
METHODS = ("limbs", "mechanism")


def _fmt(values: ArrayLike) -> str:
    return "[" + ", ".join(f"{x:.3g}" for x in np.asarray(values, float)) + "]"


def _span(kind: str, vectors: Sequence[Sequence[float]] | Array) -> Array:
    """(3, k) unit columns of the directions given for ``kind``; a ConfigurationError for bad ones."""
    try:
        a = np.asarray(vectors, float)
    except (TypeError, ValueError):
        raise ConfigurationError(f"directions[{kind!r}] must be a list of 3-vectors, got {vectors!r}") from None
    if a.size == 0:
        return np.zeros((3, 0))
    if a.ndim == 1:
        a = a[None, :]
    if a.ndim != 2 or a.shape[1] != 3:
        raise ConfigurationError(f"directions[{kind!r}] must be 3-vectors, got shape {a.shape}")
    norms = np.linalg.norm(a, axis=1)
    bad = [i for i, (row, n) in enumerate(zip(a, norms)) if not np.isfinite(row).all() or n < 1e-12]
    if bad:
        raise ConfigurationError(
            f"directions[{kind!r}][{bad[0]}] = {a[bad[0]].tolist()} is not a direction: give finite, non-zero "
            "3-vectors (any length; they are normalised)"
        )
    return (a / norms[:, None]).T


def found_directions(mob: Mobility | FrameMobility, kind: str) -> Array:
    """(3, k) unit directions of the motions of ``kind`` (``T``, ``R`` or ``H``) in ``mob``."""
    vecs = [m.direction for m in mob.motions if m.kind.value == kind]
    return np.column_stack(vecs) if vecs else np.zeros((3, 0))


def assert_mobility(
    mech: Mechanism,
    q: Array | str,
    *,
    dof: int | None = None,
    motion_type: str | None = None,
    directions: Mapping[str, Sequence[Sequence[float]]] | None = None,
    through: Sequence[float] | None = None,
    method: str = "limbs",
    rtol: float = RTOL,
    atol: float = 1e-6,
) -> Mobility | FrameMobility:
    """Assert the platform's mobility at q; returns the analysis result for further checks.

    Args:
        mech: the mechanism.
        q: closed configuration (nq,) or the name of a configuration of ``mech``.
        dof: expected number of degrees of freedom.
        motion_type: expected label, e.g. ``"3T"``, ``"1T2R"``, ``"1H"``, ``"rigid"``.
        directions: expected directions per kind, e.g. ``{"T": [[0, 0, 1]], "R": [[1, 0, 0], [0, 1, 0]]}``.
            The span of the found directions of that kind must equal the span
            given (largest principal-angle sine ``<= atol``), so any basis of a
            repeated direction space is accepted.
        through: a world point [m] every rotation and screw axis must pass
            through (distance ``<= atol * L``), e.g. the centre of a spherical
            mechanism.
        method: ``"limbs"`` (the platform mobility of :func:`pinmob.analyze`, returns a :class:`Mobility`) or
            ``"mechanism"`` (the platform frame of the whole-mechanism analysis,
            returns a :class:`FrameMobility`), e.g. for limbs with closures inside them.
        rtol: relative tolerance of the rank decisions (as in :func:`pinmob.analyze`).
        atol: tolerance of the direction and point comparisons.

    Raises:
        AssertionError: listing every mismatch, the expected and found values,
            the singular values and the tolerance.
        ConfigurationError: an unknown kind or method, or a direction that is zero or not finite.
    """
    if method not in METHODS:
        raise ConfigurationError(f"method {method!r}; valid: {', '.join(METHODS)}")
    for kind in directions or {}:
        if kind not in KINDS:
            raise ConfigurationError(f"directions key {kind!r}; valid: {', '.join(KINDS)}")
    wanted = {kind: _span(kind, vecs) for kind, vecs in (directions or {}).items()}
    result: Mobility | FrameMobility
    report = analyze(mech, q, rtol=rtol, frames=[mech.platform])
    configuration, origin = report.configuration, report.state.platform_origin
    if method == "limbs":
        if report.mobility is None:
            raise ConfigurationError(f"{mech.name!r} has no platform frame: use method='mechanism' with a frame")
        mob = report.mobility
        result, sv, tol, what = mob, mob.singular_values, mob.tolerance, "the constraint wrenches"
    else:
        mm = report.mechanism_mobility
        result, sv, tol, what = mm.frames[0], mm.singular_values, mm.tolerance, "the closure Jacobian"
    problems = []
    if dof is not None and result.dof != dof:
        problems.append(f"dof: expected {dof}, found {result.dof}")
    if motion_type is not None and result.motion_type != motion_type:
        problems.append(f"motion type: expected {motion_type}, found {result.motion_type}")
    for kind, want in wanted.items():
        got = found_directions(result, kind)
        gap = subspace_gap(want, got)
        if gap > atol:
            problems.append(
                f"{kind} directions: expected span of {[_fmt(c) for c in want.T]}, found "
                f"{[_fmt(c) for c in got.T]} (largest principal-angle sine {gap:.2e} > {atol:g})"
            )
    if through is not None:
        p = np.asarray(through, float) - origin
        for m in result.motions:
            if m.point is None:
                continue
            off = (p - m.point) - np.dot(p - m.point, m.direction) * m.direction
            dist = float(np.linalg.norm(off))
            if dist > atol * mech.length_scale:
                problems.append(f"{m.label}: axis misses the point {_fmt(through)} m by {dist:.3g} m")
    if problems:
        where = f" at {configuration!r}" if configuration else ""
        motions = "; ".join(
            f"{m.label}" + ("" if m.pitch in (None, 0.0) else f" (pitch {m.pitch:.4g} m/rad)") for m in result.motions
        )
        raise AssertionError(
            f"mobility of {mech.name!r}{where} ({method} method) differs from the expectation:\n  "
            + "\n  ".join(problems)
            + f"\n  found motions: {motions or 'none'}"
            + f"\n  singular values of {what} {_fmt(sv)}, "
            f"tolerance {tol:.3g} (rtol {rtol:g} x largest), L = {mech.length_scale:.4g} m"
        )
    return result


def kinematics_calls(fn: Callable[[], Any]) -> int:
    """How many times ``fn()`` calls ``pinocchio.computeJointJacobians``: the kinematics computations it costs.

    Only that function is counted (the one every assembly step and analysis calls); ``forwardKinematics`` and
    ``framesForwardKinematics`` calls (reading a pose without Jacobians) are not.

    Counted by a wrapper put in place of the Pinocchio function for the call (restored afterwards, also when
    ``fn`` raises); code that bound the function to another name before the call is not counted.
    """
    original, count = pin.computeJointJacobians, [0]

    def counting(*args: Any) -> Any:
        count[0] += 1
        return original(*args)

    pin.computeJointJacobians = counting
    try:
        fn()
    finally:
        pin.computeJointJacobians = original
    return count[0]
