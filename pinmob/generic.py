"""Ranks at generic configurations: the reference a singularity is measured against.

A rank that drops at a configuration is singular only compared with its value
at *generic* configurations. The limb twist ranks come with the mechanism
(:attr:`pinmob.mechanism.Limb.generic_twist_rank`); the rank of the stacked
wrenches of every set of limbs is estimated here, from random closed
configurations (:func:`generic_configurations`), once per mechanism and
tolerance. Rank decisions on a limb use its dimensionless joint screws with
unit columns (:func:`limb_decisions`), so that neither the unit of length nor
the units of the joint rates matter.
"""

from __future__ import annotations

import weakref
from collections import Counter
from itertools import combinations
from typing import Any

import numpy as np
import pinocchio as pin

from .closure import assemble_joints, closed_kinematics
from .exceptions import PinmobError
from .mechanism import Mechanism
from .mobility import limb_twists
from .screw import RTOL, Array, RankDecision, decide_rank, twist_scaling

#: Largest limb set whose generic rank is estimated (a minimal deficient set has at most 6 limbs).
MAX_SET = 6

_CACHE: dict[tuple[Any, ...], tuple[weakref.ref, Any]] = {}


def unit_columns(matrix: Array) -> Array:
    """The columns scaled to unit length (zero columns kept): ``A_i`` free of the joints' rate units."""
    norms = np.linalg.norm(matrix, axis=-2, keepdims=True)
    return matrix / np.where(norms > 0, norms, 1.0)


def limb_decisions(mech: Mechanism, twists: list[Array], rtol: float) -> list[RankDecision]:
    """Rank decision on each limb's joint screws ``U_i`` (dimensionless, unit columns), transposed.

    Its rank is the limb's twist rank, its null space the limb's wrench basis
    ``W_i`` (dimensionless, orthonormal; the span of :func:`pinmob.analyze`'s
    wrenches, whose rank decision is made on the columns as they are). A limb
    with loops inside it: its screws are ``[v / L; w]`` per orthonormal basis
    of the dimensionless loop-closing rates (:func:`pinmob.mobility.limb_rates`),
    taken as they are: their singular values do not depend on which basis, while
    unit columns would.
    """
    st = twist_scaling(mech.length_scale)[:, None]
    return [
        decide_rank((st * t if limb.closures else unit_columns(st * t)).T, rtol, n=6)
        for limb, t in zip(mech.limbs, twists)
    ]


def wrench_blocks(decisions: list[RankDecision]) -> list[Array]:
    """Dimensionless orthonormal wrench bases ``W_i`` (6, 6 - r_i)."""
    return [d.null_space.T for d in decisions]


def stacked_rank(blocks: list[Array], rtol: float) -> int:
    stacked = np.hstack(blocks)
    return decide_rank(stacked.T, rtol, n=6).rank if stacked.shape[1] else 0


def _cached(key: tuple[Any, ...], mech: Mechanism) -> Any:
    hit = _CACHE.get((id(mech), *key))
    return hit[1] if hit is not None and hit[0]() is mech else None


def _store(key: tuple[Any, ...], mech: Mechanism, value: Any) -> Any:
    _CACHE[(id(mech), *key)] = (weakref.ref(mech), value)
    return value


def generic_configurations(mech: Mechanism, samples: int = 4, seed: int = 0) -> list[Array]:
    """Random closed configurations near each named configuration (cached per mechanism).

    Joints perturbed by ``N(0, 0.05)`` [rad, or L x 0.05 m for prismatic
    joints] and closed again by :func:`pinmob.closure.assemble_joints`.

    Raises:
        PinmobError: no closed configuration could be built.
    """
    hit = _cached(("configurations", samples, seed), mech)
    if hit is not None:
        return list(hit)
    rng = np.random.default_rng(seed)
    model = mech.model
    unit = np.array(
        [
            mech.length_scale if model.joints[j].shortname().startswith("JointModelP") else 1.0
            for j in range(1, model.njoints)
            for _ in range(model.joints[j].nv)
        ]
    )
    closed = []
    for name in mech.configurations:
        try:
            q0 = mech.configuration(name)
        except PinmobError:
            continue
        for _ in range(samples):
            q = pin.integrate(model, q0, rng.normal(0.0, 0.05, model.nv) * unit)
            try:
                closed.append(assemble_joints(mech, {}, q))
            except PinmobError:
                continue
    if not closed:
        raise PinmobError(
            f"cannot estimate the generic constraint rank of {mech.name!r}: no named configuration closes; "
            "declare generic_rank in the mechanism file"
        )
    return list(_store(("configurations", samples, seed), mech, tuple(closed)))


def generic_set_ranks(
    mech: Mechanism, rtol: float = RTOL, samples: int = 4, seed: int = 0
) -> dict[tuple[int, ...], int]:
    """Generic rank of the stacked wrenches of limb sets: every set of 2 to ``MAX_SET`` limbs, and all limbs.

    The most frequent rank (ties: the larger) over :func:`generic_configurations`,
    decided with the looser tolerance ``sqrt(rtol)``: a mechanism whose whole
    workspace is singular (3-PUU-flat) closes a hair's breadth off its singular
    manifold (closure holds to second order there), and the tight tolerance
    would see the hair. Cached per mechanism and tolerance.

    Returns:
        ``{limb indices (sorted tuple): rank}``.
    """
    hit = _cached(("sets", rtol, samples, seed), mech)
    if hit is not None:
        return dict(hit)
    k = len(mech.limbs)
    sets = [s for size in range(2, min(k, MAX_SET) + 1) for s in combinations(range(k), size)]
    sets.append(tuple(range(k)))
    loose = float(np.sqrt(rtol))
    counts: dict[tuple[int, ...], Counter[int]] = {s: Counter() for s in sets}
    for q in generic_configurations(mech, samples, seed):
        blocks = wrench_blocks(limb_decisions(mech, limb_twists(mech, closed_kinematics(mech, q)), loose))
        for s in counts:
            counts[s][stacked_rank([blocks[i] for i in s], loose)] += 1
    ranks = {s: _mode(c) for s, c in counts.items()}
    return dict(_store(("sets", rtol, samples, seed), mech, ranks))


def _mode(counts: Counter[int]) -> int:
    """The most frequent rank; ties: the larger."""
    return max(counts, key=lambda r: (counts[r], r))


def generic_constraint_rank(mech: Mechanism, samples: int = 4, seed: int = 0, rtol: float = RTOL) -> int:
    """The mechanism's constraint rank at generic configurations.

    The declared ``generic_rank`` when the mechanism file has one; otherwise the
    rank of all limbs' stacked wrenches in :func:`generic_set_ranks`.

    Raises:
        PinmobError: no closed configuration could be built.
    """
    if mech.generic_rank is not None:
        return mech.generic_rank
    return generic_set_ranks(mech, rtol, samples, seed)[tuple(range(len(mech.limbs)))]


def dependent_limbs(
    mech: Mechanism, blocks: list[Array], rtol: float = RTOL, generic_rank: int | None = None
) -> tuple[str, ...]:
    """Limbs whose wrenches became dependent, compared with generic configurations.

    A limb set S is *deficient* when ``rank [W_i, i in S] < g_S``, its rank at
    generic configurations (:func:`generic_set_ranks`; for all limbs, the
    generic constraint rank ``generic_rank`` when given). The dependent limbs
    are the union of the minimal deficient sets: the dependencies that generic
    configurations also have (e.g. four couples in a plane) name no limb.
    Empty at a configuration that is not constraint-singular (except for sets
    of limbs whose loss the others make up for).

    Args:
        blocks: per limb, (6, m_i) dimensionless orthonormal wrench basis ``W_i``.
    """
    k = len(mech.limbs)
    try:
        generic = generic_set_ranks(mech, rtol)
    except PinmobError:
        generic = {}
    if generic_rank is not None:
        generic[tuple(range(k))] = generic_rank
    minimal: list[set[int]] = []
    for s in sorted(generic, key=len):
        if generic[s] == 0 or any(m <= set(s) for m in minimal):
            continue
        if stacked_rank([blocks[i] for i in s], rtol) < generic[s]:
            minimal.append(set(s))
    union = set().union(*minimal)
    return tuple(limb.name for i, limb in enumerate(mech.limbs) if i in union)
