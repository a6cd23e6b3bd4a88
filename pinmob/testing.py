"""Assertions for users' own test suites: ``assert_mobility``.

Example (pytest)::

    import pinmob
    from pinmob.testing import assert_mobility

    def test_my_robot_translates():
        mech = pinmob.load("my_robot.toml")
        assert_mobility(mech, "home", dof=3, motion_type="3T",
                        directions={"T": [[1, 0, 0], [0, 1, 0], [0, 0, 1]]})

On failure an ``AssertionError`` says what was expected and what was found,
with the singular values of the stacked constraint wrenches and the
tolerance of the rank decision, so a near-miss is visible at once.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import ArrayLike

from .mechanism import Mechanism
from .mobility import Mobility, analyze
from .screw import RTOL, Array, subspace_gap

KINDS = ("T", "R", "H")


def _fmt(values: ArrayLike) -> str:
    return "[" + ", ".join(f"{x:.3g}" for x in np.asarray(values, float)) + "]"


def _span(vectors: Sequence[Sequence[float]] | Array) -> Array:
    a = np.asarray(vectors, float)
    if a.size == 0:
        return np.zeros((3, 0))
    if a.ndim == 1:
        a = a[None, :]
    if a.shape[1] != 3:
        raise ValueError(f"directions must be 3-vectors, got shape {a.shape}")
    return (a / np.linalg.norm(a, axis=1, keepdims=True)).T


def found_directions(mob: Mobility, kind: str) -> Array:
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
    rtol: float = RTOL,
    atol: float = 1e-6,
) -> Mobility:
    """Assert the platform's mobility at q; returns the :class:`Mobility` for further checks.

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
        rtol: relative tolerance of the rank decisions (as in :func:`pinmob.analyze`).
        atol: tolerance of the direction and point comparisons.

    Raises:
        AssertionError: listing every mismatch, the expected and found values,
            the singular values and the tolerance.
    """
    mob = analyze(mech, q, rtol=rtol)
    problems = []
    if dof is not None and mob.dof != dof:
        problems.append(f"dof: expected {dof}, found {mob.dof}")
    if motion_type is not None and mob.motion_type != motion_type:
        problems.append(f"motion type: expected {motion_type}, found {mob.motion_type}")
    for kind, expected in (directions or {}).items():
        if kind not in KINDS:
            raise ValueError(f"directions key {kind!r}; valid: {', '.join(KINDS)}")
        want, got = _span(expected), found_directions(mob, kind)
        gap = subspace_gap(want, got)
        if gap > atol:
            problems.append(
                f"{kind} directions: expected span of {[_fmt(c) for c in want.T]}, found "
                f"{[_fmt(c) for c in got.T]} (largest principal-angle sine {gap:.2e} > {atol:g})"
            )
    if through is not None:
        p = np.asarray(through, float) - mob.platform_origin
        for m in mob.motions:
            if m.point is None:
                continue
            off = (p - m.point) - np.dot(p - m.point, m.direction) * m.direction
            dist = float(np.linalg.norm(off))
            if dist > atol * mob.length_scale:
                problems.append(f"{m.label}: axis misses the point {_fmt(through)} m by {dist:.3g} m")
    if problems:
        where = f" at {mob.configuration!r}" if mob.configuration else ""
        motions = "; ".join(
            f"{m.label}" + ("" if m.pitch in (None, 0.0) else f" (pitch {m.pitch:.4g} m/rad)") for m in mob.motions
        )
        raise AssertionError(
            f"mobility of {mech.name!r}{where} differs from the expectation:\n  "
            + "\n  ".join(problems)
            + f"\n  found motions: {motions or 'none'}"
            + f"\n  singular values of the constraint wrenches {_fmt(mob.singular_values)}, "
            f"tolerance {mob.tolerance:.3g} (rtol {rtol:g} x largest), L = {mob.length_scale:.4g} m"
        )
    return mob
