"""Motion branches through a configuration: their dimension and how the platform moves on each.

A linear component T of the second-order tangent cone that passes every condition up to the
order bound (:func:`pinmob.analysis.finite.tangent_cone.cone`) is the tangent space of a motion branch:
its dimension is the branch's DoF. The platform's motion on the branch is that of its generic
points: at q the platform's first-order image ``J_p T`` may be smaller (the Sarrus linkage with
both limbs stretched moves its platform only to second order), so when ``rank J_p T`` is below
``min(dim T, 6)`` the branch is followed a short way (:func:`pinmob.analysis.follow.motion_path.follow_rates`)
to a nearby point p, whose tangent space on the branch (the whole kernel when its dimension is
``dim T``, else the cone component at p closest to T) gives the platform's rank there. Only when
it is higher than at q (the platform moves less at q, to first order) are the branch's motions
those of p, classified like the instantaneous ones, and the branch says ``near q``; otherwise (a
regular point, where the platform simply has fewer DoF than the branch, e.g. the Delta's idle rod
spins) they are those at q. The tracing is also the branch's numerical confirmation.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pinmob.analysis.chain.closed_chain import closed_chain_columns, frame_rows
from pinmob.analysis.chain.joint_rates import canonical_rates, joint_rates
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.finite.higher_order import HigherOrder, OrderTest
from pinmob.analysis.finite.loop_screws import mechanism_loops
from pinmob.analysis.finite.tangent_cone import ConeComponent, cone
from pinmob.analysis.follow.motion_path import follow_rates
from pinmob.analysis.motion import Motion, motions_of
from pinmob.frozen import ReadOnlyArrays
from pinmob.screw import Array, classify_twists, decide_rank, motion_type, subspace_gap, twist_scaling

#: How far a branch is followed to reach a generic point and confirm it [rad, or m / L].
BRANCH_STEP = 0.03


@dataclass(frozen=True)
class Branch(ReadOnlyArrays):
    """One motion branch through q.

    Attributes:
        dimension: its DoF (the dimension of its tangent space).
        dof: the platform's DoF on it (None without a platform).
        motion_type: the platform's motion type on it (None without a platform).
        motions: the platform's motions on it, classified at ``where``.
        where: ``q`` (the platform moves on the branch to first order at q) or ``near q`` (classified
            at a nearby point of the branch: at q the platform moves less, to first order).
        rates: (nv, dimension) orthonormal tangent joint rates (dimensionless).
        test: the higher-order conditions along a random tangent direction (None: a mode seen only at closed
            samples near q, whose tangent cone at q is not linear; :mod:`pinmob.analysis.finite.sample_modes`).
        traced: distance the tracer followed a tangent direction (largest of both ways, joint metric).
        note: why a part of it could not be decided ("" when all is clear).
    """

    dimension: int
    dof: int | None
    motion_type: str | None
    motions: tuple[Motion, ...]
    where: str
    rates: Array = field(repr=False)
    test: OrderTest | None = field(repr=False)
    traced: float = 0.0
    note: str = ""

    def to_dict(self, joints: list[dict[str, float]]) -> dict[str, Any]:
        """The branch as plain JSON (``joints``: its tangent rates by joint name)."""
        return {
            "dimension": self.dimension,
            "dof": self.dof,
            "motion_type": self.motion_type,
            "motions": [m.to_dict() for m in self.motions],
            "classified_at": self.where,
            "joints": joints,
            "order": None if self.test is None else self.test.order,
            "traced": self.traced,
            "note": self.note,
        }


def platform_motions(conf: Configuration, rates: Array, rtol: float) -> tuple[int, str, tuple[Motion, ...]]:
    """(dof, motion type, motions) of the platform moved by the joint rates ``rates`` (nv, d) at conf."""
    mech = conf.mechanism
    image = frame_rows(conf, mech.platform) @ rates
    if image.size == 0:
        return 0, "rigid", ()
    dec = decide_rank(image.T, rtol, 6, at_least=1.0)
    system = classify_twists(dec.row_space.T / twist_scaling(mech.length_scale)[:, None], mech.length_scale, rtol)
    return dec.rank, motion_type(system), motions_of(system)


def tangent_rates(ho: HigherOrder, basis: Array) -> Array:
    """(nv, d) orthonormal joint rates spanning the tree part of the kernel directions ``basis`` (m, d)."""
    tree = ho.kernel[: ho.loops.nv] @ basis
    return np.linalg.qr(tree)[0] if tree.size else tree


def nearby_tangent(conf: Configuration, rates: Array, rtol: float, held: tuple[int, ...]) -> Array | None:
    """(nv, d) the branch's tangent rates at conf (a point near q), closest to ``rates``; None if none fits."""
    ho = HigherOrder(mechanism_loops(conf), rtol, held)
    d = rates.shape[1]
    if ho.m == d:
        return tangent_rates(ho, np.eye(d))
    if ho.m < d:
        return None
    spans = [tangent_rates(ho, c.basis) for c in cone(ho, 2).components if c.dimension == d]
    best = min(spans, key=lambda s: subspace_gap(s, rates), default=None)
    return best if best is not None and subspace_gap(best, rates) < 0.3 else None


def branch_of(
    conf: Configuration,
    ho: HigherOrder,
    component: ConeComponent,
    rtol: float,
    held: tuple[int, ...] = (),
    seed: int = 0,
) -> Branch:
    """The :class:`Branch` whose tangent space is ``component`` (kernel coordinates of ``ho``)."""
    mech = conf.mechanism
    rates = tangent_rates(ho, component.basis)
    d = rates.shape[1]
    direction = rates @ np.random.default_rng(seed).normal(size=d)
    path = follow_rates(mech, conf, direction, amplitude=BRANCH_STEP, steps=1, held=held, rtol=rtol, halvings=2)
    traced = max(path.reached)
    if not mech.has_platform:
        return Branch(d, None, None, (), "q", rates, component.test, traced)
    dof, kind, motions = platform_motions(conf, rates, rtol)
    if dof == min(d, 6) or traced == 0.0:
        note = "" if traced else "the tracer could not follow it"
        return Branch(d, dof, kind, motions, "q", rates, component.test, traced, note)
    end = path.forward[-1] if path.reached[0] >= path.reached[1] else path.backward[-1]
    near = Configuration.from_checked(mech, end, conf.closure_tol)
    there = nearby_tangent(near, rates, rtol, held)
    if there is None:
        note = "no tangent space of the same dimension at a nearby point of it"
        return Branch(d, None, None, (), "q", rates, component.test, traced, note)
    dof_near, kind_near, motions_near = platform_motions(near, there, rtol)
    if dof_near <= dof:  # the platform moves as much at q as nearby (a regular point): classified at q
        return Branch(d, dof, kind, motions, "q", rates, component.test, traced)
    return Branch(d, dof_near, kind_near, motions_near, "near q", rates, component.test, traced)


def branch_order(branch: Branch) -> tuple[Any, ...]:
    """The key branches are listed by, the same on every machine.

    The cone's groups come in an order round-off decides. Listed: the larger first (DoF, then the platform's),
    those with a linear tangent space before the modes seen only at samples, then by motion type, then by the
    canonical basis of the tangent rates (3 decimals).
    """
    rates = canonical_rates(branch.rates)
    return (
        -branch.dimension,
        -(branch.dof or 0),
        branch.test is None,
        branch.motion_type or "",
        tuple(np.round(rates.T, 3).ravel().tolist()),
    )


def branch_joints(conf: Configuration, branch: Branch) -> list[dict[str, float]]:
    """A branch's tangent rates by joint name (largest 1), one dictionary per basis vector."""
    col = closed_chain_columns(conf)
    rates = canonical_rates(branch.rates)  # one basis of the tangent space, whatever the SVD gave
    return [joint_rates(conf.mechanism, col * rates[:, i]) for i in range(rates.shape[1])]


# ------------------------------------------------------------------ a branch point in words
#
# A branch point in words: how many motion branches meet, each one's DoF and the platform's motion type on it.
#
# ``two 3-DoF branches meet: 3T and 3H`` (the Delta with horizontal rods), ``a 4-DoF and a 2-DoF branch meet:
# 3T1R and 2R`` (the 4-RUU at its parallel-axes configuration). The DoF named are the platform's on each
# branch (the closed chain's, and no motion type, for a mechanism without a platform); the branches are
# named in the order the analysis lists them (:func:`pinmob.analysis.finite.branches.branch_order`, the same on
# every machine). The text, the JSON (``branch_point``) and the viewer's panel say it alike.

#: Words for small counts.
COUNTS = {2: "two", 3: "three", 4: "four", 5: "five", 6: "six", 7: "seven", 8: "eight", 9: "nine"}


def _and(items: Sequence[str]) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def branch_point_name(branches: Sequence[Branch]) -> str | None:
    """The branch point's name (None where fewer than two branches pass through q)."""
    if len(branches) < 2:
        return None
    dofs = [b.dimension if b.dof is None else b.dof for b in branches]
    kinds = [b.motion_type for b in branches if b.motion_type is not None]
    if len(set(dofs)) == 1:
        head = f"{COUNTS.get(len(dofs), str(len(dofs)))} {dofs[0]}-DoF branches meet"
    elif len(dofs) == 2:
        head = f"a {dofs[0]}-DoF and a {dofs[1]}-DoF branch meet"
    else:
        head = f"branches of {_and([str(d) for d in dofs])} DoF meet"
    return head + (f": {_and(kinds)}" if len(kinds) == len(branches) else "")
