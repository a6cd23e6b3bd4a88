"""Per-motion verdicts: is an instantaneous motion finite, blocked at some order, or where branches meet?

Each instantaneous motion (a platform motion, or an internal motion of the mechanism) gets two
independent answers:

- from the higher-order conditions (:mod:`pinmob.analysis.finite.tangent_cone`): the motion is tangent
  to a motion branch (its twist lies in the branch's first-order platform image, or its joint rates
  in the branch's tangent rates): *finite*; it is a combination of the tangents of two or more
  branches and of none alone: *branch point*; else the lowest order k at which no choice (of the
  internal motions it may be combined with, and of the higher derivatives) satisfies the
  conditions: *blocked at order k* (shaky: first-order free, impossible at order k);
- from tracing it with the path follower: the distance it could be followed (either way).

A condition whose residual lies within a factor ``MARGIN`` of its tolerance decides nothing: the
motion is then *cannot decide*, with the numbers.

The verdict is *finite* when the motion is on a branch and the tracer moved; *blocked* when the
conditions block it and the tracer could not move at all; *branch point* from the conditions (the
tracer's distance is reported, not judged: along a combination of branch tangents it lands on one
branch). Every other combination is *cannot decide*, with both answers in the note.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from enum import StrEnum
from typing import Any

import numpy as np

from pinmob.analysis.finite.branches import Branch
from pinmob.analysis.finite.higher_order import MARGIN, OrderTest
from pinmob.analysis.motion import Motion
from pinmob.frozen import ReadOnlyArrays
from pinmob.screw import Array, decide_rank, twist_scaling

#: A motion lies in a span when the sine of its angle to it is at most this.
MEMBER_SIN = 1e-4
#: A motion is a combination of the modes seen at closed samples when its sine to their tangents' span is at most this.
COMBINATION_SIN = 0.1


class Verdict(StrEnum):
    """What became of an instantaneous motion at finite amplitude."""

    FINITE = "finite"
    BLOCKED = "blocked"
    BRANCH_POINT = "branch point"
    UNDECIDED = "cannot decide"


@dataclass(frozen=True)
class MotionVerdict(ReadOnlyArrays):
    """One instantaneous motion's verdict.

    Attributes:
        label: the motion's label (``T1 z``, ``limb A``, ...).
        verdict: finite, blocked, branch point or cannot decide.
        order: the order at which it is blocked (None unless blocked).
        branches: indices (from 1) of the branches it is tangent to (finite) or combines (branch point).
        traced: the largest distance the tracer followed it (m for translations, rad for rotations and
            screws, the dimensionless joint metric for joint motions).
        test: the higher-order conditions along it.
        note: the numbers behind a "cannot decide", or a remark.
        joints: its rates by joint name (internal motions; empty for platform motions).
        motion: the platform motion (None for an internal motion).
    """

    label: str
    verdict: Verdict
    order: int | None
    branches: tuple[int, ...]
    traced: float
    test: OrderTest = field(repr=False)
    note: str = ""
    joints: dict[str, float] = field(default_factory=dict)
    motion: Motion | None = field(default=None, repr=False)

    def line(self, many: bool = False, origin: Array | None = None, length: float = 1.0) -> str:
        """The motion's line of the instantaneous report (or its label and joints) and the verdict.

        Args:
            many: several branches pass through q.
            origin: (3,) world position [m] of the platform origin (the axis point is printed in world coordinates).
            length: the mechanism's length scale L [m].
        """
        if self.motion is not None:
            head = self.motion.line(np.zeros(3) if origin is None else origin, length)
        else:
            items = list(self.joints.items())
            rates = ", ".join(f"{k} {v:+.3g}" for k, v in items[:4]) + (" ..." if len(items) > 4 else "")
            head = f"  {self.label:<10} {rates}"
        return f"{head}: {self.words(many)}"

    @property
    def finite(self) -> bool | None:
        """True: finite; False: blocked or only a combination of branches; None: cannot decide."""
        return None if self.verdict is Verdict.UNDECIDED else self.verdict is Verdict.FINITE

    def words(self, many: bool = False) -> str:
        """``finite``, ``blocked at order 2 (shaky)``, ``branch point (...)``, ``cannot decide: ...``.

        Args:
            many: several branches pass through q (then a finite motion names its branch).
        """
        on = ", ".join(str(b) for b in self.branches)
        if self.verdict is Verdict.FINITE:
            return f"finite (on branch{'es' if len(self.branches) > 1 else ''} {on})" if many else "finite"
        if self.verdict is Verdict.BLOCKED:
            if self.order is None:
                return "blocked (shaky: no closed sample near q moves along it)"
            return f"blocked at order {self.order} (shaky)"
        if self.verdict is Verdict.BRANCH_POINT:
            return f"branch point: only a combination of branches {on}"
        return f"cannot decide: {self.note}"

    def to_dict(self) -> dict[str, Any]:
        """``{label, finite, verdict, order, branches, traced, residuals, note}`` (+ ``joints``)."""
        out: dict[str, Any] = {
            "label": self.label,
            "kind": None if self.motion is None else self.motion.kind.value,
            "finite": self.finite,
            "verdict": self.verdict.value,
            "order": self.order,
            "branches": list(self.branches),
            "traced": self.traced,
            "residuals": list(self.test.residuals),
            "note": self.note,
        }
        if self.joints:
            out["joints"] = dict(self.joints)
        return out


def sine_to(vector: Array, basis: Array) -> float:
    """Sine of the angle between ``vector`` and the column span of the orthonormal ``basis`` (1 when empty)."""
    size = float(np.linalg.norm(vector))
    if size == 0.0:
        return 0.0
    if basis.size == 0:
        return 1.0
    return float(np.linalg.norm(vector - basis @ (basis.T @ vector))) / size


def orthonormal(columns: list[Array], rows: int) -> Array:
    """(rows, k) orthonormal basis of the span of the given column blocks (directions below 1e-9 dropped)."""
    stacked = np.hstack(columns) if columns else np.zeros((rows, 0))
    if stacked.size == 0:
        return np.zeros((rows, 0))
    return decide_rank(stacked.T, 1e-9, at_least=1.0).row_space.T  # the one rank rule, natural scale 1


def motions_to_judge(
    own: tuple[Motion, ...], given: tuple[Motion, ...] | None, dof: int, image: Array, length: float
) -> tuple[Motion, ...]:
    """The platform motions a side judges: ``given`` when it has ``dof`` motions, each in ``image``'s span; else ``own``.

    Args:
        own: the side's own instantaneous platform motions (classified from its first-order motions).
        given: the report's (its free or uncontrolled motions: the same labels), or None.
        dof: the side's instantaneous platform DoF.
        image: (6, k) dimensionless platform twists spanning those of the side's first-order motions.
        length: the mechanism's length scale L [m].
    """
    w = twist_scaling(length)
    span = orthonormal([image], 6)
    if given is not None and len(given) == dof and all(sine_to(w * g.twist, span) <= MEMBER_SIN for g in given):
        return given
    return own


def judge(
    label: str,
    vector: Array,
    spans: list[Array],
    test: OrderTest,
    traced: float,
    joints: dict[str, float] | None = None,
    motion: Motion | None = None,
) -> MotionVerdict:
    """The verdict of one motion (see the module docstring).

    Args:
        label: the motion's label.
        vector: the motion in the space the branches are described in (dimensionless platform twist,
            or joint rates).
        spans: per branch, an orthonormal basis of its image in that space (its tangent).
        test: the higher-order conditions along the motion.
        traced: the tracer's largest distance along it.
        joints: its rates by joint name, for internal motions.
        motion: the platform motion, for platform motions.
    """
    on = tuple(i + 1 for i, s in enumerate(spans) if s.size and sine_to(vector, s) <= MEMBER_SIN)
    joints = joints or {}
    if on:
        if traced > 0:
            return MotionVerdict(label, Verdict.FINITE, None, on, traced, test, "", joints, motion)
        note = f"it is tangent to branch {on[0]}, but the tracer could not follow it"
        return MotionVerdict(label, Verdict.UNDECIDED, None, on, traced, test, note, joints, motion)
    used = tuple(i + 1 for i, s in enumerate(spans) if s.size)
    if len(used) > 1 and sine_to(vector, orthonormal([s for s in spans if s.size], vector.size)) <= MEMBER_SIN:
        return MotionVerdict(label, Verdict.BRANCH_POINT, None, used, traced, test, "", joints, motion)
    if test.margin < MARGIN:
        order, residual = test.deciding
        note = (
            f"the order-{order} condition's residual {residual:.2e} is within a factor {MARGIN:g} of its tolerance "
            f"{test.tolerance:.2e}"
            + (f"; the tracer followed it {traced:.3g}" if traced else "; the tracer could not follow it")
        )
        return MotionVerdict(label, Verdict.UNDECIDED, None, (), traced, test, note, joints, motion)
    if test.blocked_at is not None and traced == 0.0:
        return MotionVerdict(label, Verdict.BLOCKED, test.blocked_at, (), traced, test, "", joints, motion)
    if test.blocked_at is not None:
        note = (
            f"the conditions block it at order {test.blocked_at} (residual {test.residuals[-1]:.2e}, tolerance "
            f"{test.tolerance:.2e}), yet the tracer followed it {traced:.3g}"
        )
    else:
        note = (
            f"every condition up to order {test.order} holds (largest residual {max(test.residuals):.2e}, tolerance "
            f"{test.tolerance:.2e}) but it is on no branch found"
            + ("" if traced else ", and the tracer could not follow it")
        )
    return MotionVerdict(label, Verdict.UNDECIDED, None, (), traced, test, note, joints, motion)


def settle(
    verdict: MotionVerdict, vector: Array, spans: list[Array | None], reach: Array, still: bool
) -> MotionVerdict:
    """A verdict decided again from the modes the closed samples found (:mod:`pinmob.analysis.finite.sample_modes`).

    Args:
        verdict: the verdict from the conditions and the tracer.
        vector: the motion (dimensionless platform twist, or joint rates).
        spans: per branch, an orthonormal basis of its image at q (None: a mode whose tangent cone at q
            is not linear).
        reach: orthonormal basis of the span of every mode's tangents, in the space of ``vector``.
        still: the samples show that the motion's kind of motion cannot happen (the platform, or the
            closed chain, does not move at any closed sample near q).

    A motion tangent to a linear branch and traced is finite there; with ``still`` it is blocked (at the
    order the conditions found, if they found one by more than ``MARGIN``); traced and on no linear branch, it is finite on the other modes;
    not traced, several branches meet and it lies in the span of their tangents (sine at most
    ``COMBINATION_SIN``), it is only a combination of them; else blocked.
    """
    v = verdict
    order = v.test.blocked_at if v.test.margin >= MARGIN else None  # an order within the margin: not named
    linear = [i + 1 for i, s in enumerate(spans) if s is not None and s.size and sine_to(vector, s) <= MEMBER_SIN]
    others = tuple(i + 1 for i, s in enumerate(spans) if s is None)
    if still:
        return MotionVerdict(v.label, Verdict.BLOCKED, order, (), v.traced, v.test, "", v.joints, v.motion)
    if linear and v.traced > 0:
        return MotionVerdict(v.label, Verdict.FINITE, None, tuple(linear), v.traced, v.test, "", v.joints, v.motion)
    if v.traced > 0 and others:
        return MotionVerdict(v.label, Verdict.FINITE, None, others, v.traced, v.test, "", v.joints, v.motion)
    if len(spans) > 1 and sine_to(vector, reach) <= COMBINATION_SIN:
        every = tuple(range(1, len(spans) + 1))
        return MotionVerdict(v.label, Verdict.BRANCH_POINT, None, every, v.traced, v.test, "", v.joints, v.motion)
    return MotionVerdict(v.label, Verdict.BLOCKED, order, (), v.traced, v.test, "", v.joints, v.motion)


def settle_side(
    motions: Sequence[MotionVerdict],
    vectors: Sequence[Array],
    internal: Sequence[MotionVerdict],
    internal_vectors: Sequence[Array],
    branches: Sequence[Branch],
    rows: Array,
    reach: Array,
    finite_dof: int | None,
    finite_mechanism_dof: int | None,
) -> tuple[list[MotionVerdict], list[MotionVerdict]]:
    """Every verdict of a side settled (:func:`settle`) by the modes closed samples found: (platform, internal).

    Args:
        motions: the platform motions' verdicts (from the conditions, or undecided, and the tracer).
        vectors: their dimensionless platform twists, one per verdict.
        internal: the internal motions' verdicts.
        internal_vectors: their joint rates (dimensionless), one per verdict.
        branches: the modes the samples found (:mod:`pinmob.analysis.finite.sample_modes`; a branch without a
            test is a mode whose tangent cone at q is not linear).
        rows: (6, nv) the platform's dimensionless twist per joint rate (zeros without a platform).
        reach: (nv, r) orthonormal joint rates spanning every mode's tangents at the samples.
        finite_dof: the platform's finite DoF the samples decided (0: the platform cannot move near q).
        finite_mechanism_dof: the closed chain's (0: q is isolated).
    """
    plat = [None if b.test is None else orthonormal([rows @ b.rates], 6) for b in branches]
    joints = [None if b.test is None else b.rates for b in branches]
    reach_plat = orthonormal([rows @ reach], 6)
    return (
        [settle(v, x, plat, reach_plat, finite_dof == 0) for v, x in zip(motions, vectors, strict=True)],
        [
            settle(v, x, joints, reach, finite_mechanism_dof == 0)
            for v, x in zip(internal, internal_vectors, strict=True)
        ],
    )
