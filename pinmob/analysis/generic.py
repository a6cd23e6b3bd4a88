"""Ranks at generic configurations: the reference a singularity is measured against.

A rank that drops at a configuration is singular only compared with its value
at *generic* configurations. Estimated here once per mechanism (and tolerance)
and cached:

* each limb's generic twist rank (:func:`generic_twist_ranks`): the largest
  rank of its joint screws over seeded random joint values, its internal loops
  closed;
* the generic rank of the stacked wrenches of every set of limbs
  (:func:`generic_set_ranks`), from random closed configurations
  (:func:`generic_configurations`), hence the generic constraint rank.

Rank decisions on a limb use its dimensionless joint screws with unit columns
(:func:`pinmob.analysis.limbs.limb_decisions`), so that neither the unit of
length nor the units of the joint rates matter.
"""

from __future__ import annotations

import sys
import threading
from collections import Counter
from contextlib import closing
from dataclasses import replace
from itertools import combinations

import numpy as np
import pinocchio as pin

from pinmob.analysis.configuration import Configuration, parked
from pinmob.analysis.limbs import limb_decisions, limb_screws, limb_twists, rate_scale, wrench_blocks
from pinmob.assembly import (
    CLOSURE_TOL,
    PoseProblem,
    assemble_joints,
    closed_configuration,
    pose_vector,
    project,
    random_configuration,
    solve_poses,
)
from pinmob.exceptions import ClosureError, PinmobError
from pinmob.model import Mechanism
from pinmob.progress import step
from pinmob.screw import RTOL, Array, decide_rank, twist_scaling

#: Largest limb set whose generic rank is estimated (a minimal deficient set has at most 6 limbs).
MAX_SET = 6
#: The batched solver's compiled loop: where it is loaded already, the generic configurations are closed by it.
KERNEL = "pinmob.assembly.batched.batch_newton_kernel"
#: Named configurations (the file's first that close) near which generic configurations are sampled: a file
#: may name thousands (a recorded trajectory), and the generic ranks need a few samples, not one per name.
MAX_NAMED = 8


def generic_twist_ranks(mech: Mechanism, samples: int = 3) -> tuple[int, ...]:
    """Each limb's generic twist rank: the largest rank of its joint screws over seeded random configurations.

    The screws are those of :func:`pinmob.analysis.limbs.limb_twists` at the
    limb's tip (with its internal loops closed: each sample is first projected
    onto them, and used as it is only where that fails), made dimensionless
    with the mechanism's length scale, ranked with :data:`~pinmob.screw.rank.RTOL`.
    One random configuration of the whole mechanism a sample, its kinematics shared by every limb (a limb's
    screws depend on its own joints only). Cached per mechanism.
    """

    def compute() -> tuple[int, ...]:
        rng = np.random.default_rng(0)
        best = [0] * len(mech.limbs)
        st = twist_scaling(mech.length_scale)[:, None]
        loops = [tuple(c for c in mech.closures if c.name in limb.closures) for limb in mech.limbs]
        alone = [replace(mech, limbs=(), platform="", closures=own) if own else None for own in loops]
        for _ in range(samples):  # one random configuration a sample, shared by the limbs without loops
            drawn = random_configuration(mech, rng, spread=1.0)
            shared = Configuration.unchecked(mech, drawn)
            for i, limb in enumerate(mech.limbs):
                conf, closed = shared, alone[i]
                if closed is not None:  # the limb's own loops closed on the sample
                    try:
                        q = project(closed, drawn).q
                    except ClosureError:
                        q = drawn
                    conf = Configuration.unchecked(mech, q)
                screws = limb_screws(conf, limb, RTOL, np.array(conf.data.oMf[limb.tip_id].translation))
                best[i] = max(best[i], decide_rank((st * screws).T, RTOL).rank)
        return tuple(best)

    return mech.memo(("twist ranks", samples), compute)


def stacked_rank(blocks: list[Array], rtol: float) -> int:
    """Rank of the stacked dimensionless wrench bases (0 when there are none)."""
    stacked = np.hstack(blocks)
    return decide_rank(stacked.T, rtol, n=6).rank if stacked.shape[1] else 0


def generic_configurations(
    mech: Mechanism, samples: int = 4, seed: int = 0, compiled: bool | None = None
) -> list[Array]:
    """Random closed configurations near the first ``MAX_NAMED`` named configurations that close (cached per mechanism).

    Joints perturbed by ``N(0, 0.05)`` [rad, or L x 0.05 m for prismatic
    joints] and closed again: all in lockstep by the batched solver where every closure is a limb tip
    (:func:`_closed_in_lockstep`: compiled where the compiled solver is loaded, as in a scan's process;
    ``compiled`` forces either), each start it does not close (and every start elsewhere) by
    :func:`pinmob.assembly.assemble.assemble_joints`. The first call for a mechanism is kept (its engine's
    round-off): the ranks decided at them are the same either way.

    Raises:
        PinmobError: no closed configuration could be built.
    """

    def compute() -> tuple[Array, ...]:
        rng = np.random.default_rng(seed)
        model = mech.model
        unit = rate_scale(mech)  # steps of 0.05 L on prismatic joints, 0.05 rad on the others
        closed, used, starts = [], 0, list[Array]()
        total = min(MAX_NAMED, len(mech.configurations))
        with step(f"closing random configurations of {mech.name} (generic ranks)", total) as bar:
            for name in mech.configurations:
                if used == MAX_NAMED:
                    break
                try:
                    q0 = closed_configuration(mech, name)
                except PinmobError:
                    continue
                used += 1
                bar.update()
                starts.extend(pin.integrate(model, q0, rng.normal(0.0, 0.05, model.nv) * unit) for _ in range(samples))
            for q, done in zip(starts, _closed_in_lockstep(mech, starts, compiled)):
                if done is not None:
                    closed.append(done)
                    continue
                try:
                    closed.append(assemble_joints(mech, {}, q))
                except PinmobError:
                    continue
        if not closed:
            raise PinmobError(
                f"cannot estimate the generic constraint rank of {mech.name!r}: no named configuration closes; "
                "declare generic_rank in the mechanism file"
            )
        return tuple(closed)

    return list(mech.memo(("configurations", samples, seed), compute))


def generic_states(mech: Mechanism, samples: int = 4, seed: int = 0) -> list[Configuration]:
    """The :class:`Configuration` at each of :func:`generic_configurations` (closure checked at ``CLOSURE_TOL``).

    Cached per mechanism and thread (not pickled with it), so that the generic ranks and a grid's held
    coordinates (:func:`pinmob.scan.coordinates.constant_coordinates`) share their kinematics and what each one
    caches. Each state gives its ``pin.Data`` back to the pool once closed, and its users after each use
    (:func:`~pinmob.analysis.configuration.parked`): a 6-UPS's twelve states held 3 MB and took 1 ms to make
    each. So that one thread's parking never takes the kinematics from under another's analysis, each thread has
    states of its own. A ``pin`` object read from a state's :attr:`~Configuration.data` (an SE3 of
    ``frame_placement``, ``data.J``) is another configuration's once the state is parked, in this thread too:
    copy what is kept (``np.array``), or read it again.

    Raises:
        PinmobError: no closed configuration could be built, or one does not close within ``CLOSURE_TOL``.
    """

    def compute() -> tuple[Configuration, ...]:
        return tuple(
            parked(
                Configuration.from_checked(mech, q, CLOSURE_TOL) for q in generic_configurations(mech, samples, seed)
            )
        )

    key = ("configuration states", samples, seed, threading.get_ident())
    return list(mech.memo(key, compute, transient=True))


def _closed_in_lockstep(mech: Mechanism, starts: list[Array], compiled: bool | None = None) -> list[Array | None]:
    """Per start, its configuration closed by the batched solver in lockstep, or None (left to the single solver).

    Where every closure is a limb tip on the platform (no other loops): the platform pose is free (all six
    coordinates follow, from each start's own), so the steps close the limbs on it as
    :func:`pinmob.assembly.assemble.assemble_joints` with no joint held does, on a stack
    (:func:`pinmob.assembly.batched.batch_solver.solve_poses`); a start it does not close to ``1e-12`` (dimensionless) is
    None. Every start is None for a mechanism with other loops or without a platform.

    ``compiled`` (None: where the solver's compiled loop, :data:`KERNEL`, is loaded already: a scan's process, whose
    spec loads it first, :func:`pinmob.scan.scan_spec.grid_spec`): that loop (numba), else its numpy steps and
    Pinocchio's kinematics (an analysis does not load numba, nor compile pinmob's kernels). Five to seven times faster compiled; the steps differ in round-off, and so,
    where the closures leave a continuum of configurations, may the point of it a start closes to (1e-5 apart on
    the 3-PRRR). Only ranks are decided at them, the same from either (``tests/test_generic_configurations.py``).
    """
    if not starts or not PoseProblem.covers(mech):
        return [None] * len(starts)
    compiled = KERNEL in sys.modules if compiled is None else compiled
    problem = PoseProblem(mech, tuple(range(6)), compiled=compiled)
    qs = np.array(starts, float)
    _, frames = problem.kinematics(qs)
    poses = np.array([pose_vector(pin.SE3(h)) for h in frames[:, 0]])  # frames[0]: the platform's
    sol = solve_poses(problem, qs, poses)
    out: list[Array | None] = [None] * len(starts)
    if sol.converged.any():
        done = problem.finish(mech, sol.q[sol.converged], "pose")
        for i, q in zip(np.flatnonzero(sol.converged), done):
            out[int(i)] = q
    return out


def generic_set_ranks(
    mech: Mechanism, rtol: float = RTOL, samples: int = 4, seed: int = 0
) -> dict[tuple[int, ...], int]:
    """Generic rank of the stacked wrenches of limb sets: every set of 2 to ``MAX_SET`` limbs, and all limbs.

    The most frequent rank (ties: the larger) over :func:`generic_configurations` (ranking stops once the
    configurations left could not change it for any set: the same mode as over all of them),
    decided with the looser tolerance ``sqrt(rtol)``: a mechanism whose whole
    workspace is singular (3-PUU-flat) closes a hair's breadth off its singular
    manifold (closure holds to second order there), and the tight tolerance
    would see the hair. Cached per mechanism and tolerance.

    Returns:
        ``{limb indices (sorted tuple): rank}``.
    """

    def compute() -> dict[tuple[int, ...], int]:
        k = len(mech.limbs)
        sets = [s for size in range(2, min(k, MAX_SET) + 1) for s in combinations(range(k), size) if size < k]
        ranks = _set_ranks(mech, sets, rtol, samples, seed) if sets else {}
        ranks[tuple(range(k))] = _all_limbs_rank(mech, rtol, samples, seed)  # shared with generic_constraint_rank
        return ranks

    return dict(mech.memo(("sets", rtol, samples, seed), compute))


def _set_ranks(
    mech: Mechanism, sets: list[tuple[int, ...]], rtol: float, samples: int, seed: int
) -> dict[tuple[int, ...], int]:
    """:func:`generic_set_ranks` of the limb sets ``sets`` only: each set's mode does not depend on the others."""
    loose = float(np.sqrt(rtol))
    counts: dict[tuple[int, ...], Counter[int]] = {s: Counter() for s in sets}
    states = generic_states(mech, samples, seed)
    with closing(parked(states)) as each:  # the state the loop stops at parked too
        for i, conf in enumerate(each):
            blocks = wrench_blocks(limb_decisions(mech, limb_twists(conf, RTOL), loose))
            for s in counts:
                counts[s][stacked_rank([blocks[i] for i in s], loose)] += 1
            if all(_decided(c, len(states) - 1 - i) for c in counts.values()):
                break
    return {s: _mode(c) for s, c in counts.items()}


def _decided(counts: Counter[int], left: int) -> bool:
    """True when ``left`` more ranks cannot change :func:`_mode`: its rank's count exceeds any other's plus ``left``."""
    top, *rest = sorted(counts.values(), reverse=True)
    return top > (rest[0] if rest else 0) + left


def _mode(counts: Counter[int]) -> int:
    """The most frequent rank; ties: the larger."""
    return max(counts, key=lambda r: (counts[r], r))


def generic_constraint_rank(mech: Mechanism, samples: int = 4, seed: int = 0, rtol: float = RTOL) -> int:
    """The mechanism's constraint rank at generic configurations.

    The declared ``generic_rank`` when the mechanism file has one; otherwise the
    rank of all limbs' stacked wrenches in :func:`generic_set_ranks`, computed for that set alone (cached).

    Raises:
        PinmobError: no closed configuration could be built.
    """
    if mech.generic_rank is not None:
        return mech.generic_rank
    return _all_limbs_rank(mech, rtol, samples, seed)  # the other sets' ranks only where a singularity needs them


def _all_limbs_rank(mech: Mechanism, rtol: float, samples: int, seed: int) -> int:
    """The generic rank of all limbs' stacked wrenches (:func:`_set_ranks` of that set alone; cached)."""
    every = tuple(range(len(mech.limbs)))
    return mech.memo(("all limbs", rtol, samples, seed), lambda: _set_ranks(mech, [every], rtol, samples, seed)[every])


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
        mech: the mechanism.
        blocks: per limb, (6, m_i) dimensionless orthonormal wrench basis ``W_i``.
        rtol: relative tolerance of the rank decisions.
        generic_rank: the generic rank of all limbs together (default: estimated).
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
