"""One side of the finite analysis decided by closed samples alone, where the order conditions are not written.

A coupling on a tendon that wraps geoms or runs over a pulley (:func:`unwritten`),
such a tendon's actuator held, or an actuator held at the length MuJoCo gives it (a slider-crank, a ball joint,
a site with a reference site), has a residual and a Jacobian (MuJoCo's length and its row) but no written
higher derivatives: the conditions of :mod:`pinmob.analysis.finite.higher_order` cannot be written for the
closure equations. :func:`sampled_side` decides the :class:`~pinmob.analysis.finite.finite_side.Side` from what
needs only the residual and its Jacobian:

1. the first-order motions (the closure Jacobian's kernel, held joints still) as the one candidate branch,
   traced a short way along a random direction;
2. closed samples near q, each probed (:func:`pinmob.analysis.finite.sample_modes.decide_by_samples`, every
   sample probed: none is taken for a regular point of the candidate); with one first-order motion left, the
   order at which the reduced closure equation starts;
3. each instantaneous motion traced, then judged by the modes the samples found
   (:func:`pinmob.analysis.finite.verdicts.settle`): finite on a confirmed branch and traced, blocked where the
   samples never move it, a combination where modes meet.

The finite DoF are the samples'; the report says that they decided and that the order conditions were not used
(``Side.unwritten``). Where the samples conflict the DoF are None and a note gives the numbers.
"""

from __future__ import annotations

import numpy as np

from pinmob.analysis.chain.closed_chain import closed_chain_columns, frame_rows
from pinmob.analysis.chain.joint_rates import joint_rates
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.finite.branches import BRANCH_STEP, Branch, branch_order, platform_motions
from pinmob.analysis.finite.coupling_rows import has_series, is_polynomial
from pinmob.analysis.finite.finite_side import Side, Unwritten, held_names, internal_motions
from pinmob.analysis.finite.higher_order import OrderTest
from pinmob.analysis.finite.local_dimension import LocalDimension
from pinmob.analysis.finite.motion_tracing import trace_motion, trace_rates
from pinmob.analysis.finite.sample_modes import RADIUS, decide_by_samples
from pinmob.analysis.finite.verdicts import MotionVerdict, Verdict, motions_to_judge, settle_side
from pinmob.analysis.follow.motion_path import follow_rates
from pinmob.analysis.follow.path_follower import closed_rates
from pinmob.analysis.motion import Motion
from pinmob.model import Closure, ClosureType
from pinmob.screw import Array, decide_rank, twist_scaling


def unwritten(closures: tuple[Closure, ...]) -> tuple[Unwritten, ...]:
    """Each coupling among ``closures`` whose rows are not written, per kind of tendon without a written series.

    Such a coupling is on a tendon that wraps geoms or runs over a pulley (named with the tendons concerned,
    :attr:`~pinmob.model.tendon.Tendon.noun`), or holds an actuator's length that MuJoCo computes (a
    slider-crank, a ball joint, a site, held by :func:`~pinmob.analysis.finite.coupling_rows.hold_tendons`:
    named by the actuator): its residual and Jacobian are known (MuJoCo's length and its row), its higher
    derivatives are not; the side it is on is decided here, from closed samples alone.
    """
    out = []
    for c in closures:
        if c.is_coupling and c.type is not ClosureType.JOINT and not is_polynomial(c):
            blind = [t for t in c.tendons if not has_series(t)]
            for kind in dict.fromkeys(type(t) for t in blind):
                names = [repr(t.name) for t in blind if type(t) is kind]
                if kind.noun == "actuator length":  # an actuator held (hold_tendons): one length, named by it
                    out.append(Unwritten(names[0], kind.unwritten_why, held=True))
                    continue
                what = f"coupling {c.name!r} on {kind.noun}{'s' if len(names) > 1 else ''} {', '.join(names)}"
                out.append(Unwritten(what, kind.unwritten_why))
    return tuple(out)


def unwritten_words(items: tuple[Unwritten, ...]) -> str:
    """The items in words, those with one reason together.

    For example ``coupling 'c' on tendon 't'; actuators 'a', 'b' held at their lengths (why)``.
    """
    parts = []
    for why in dict.fromkeys(u.why for u in items):
        phrases = [u.what for u in items if u.why == why and not u.held]
        held = [u.what for u in items if u.why == why and u.held]
        if held:
            many = len(held) > 1
            lengths = "their lengths" if many else "its length"
            phrases.append(f"actuator{'s' if many else ''} {', '.join(held)} held at {lengths}")
        parts.append(f"{'; '.join(phrases)} ({why})")
    return "; ".join(parts)


def untested(rates: Array) -> OrderTest:
    """The :class:`OrderTest` of a motion no condition beyond the first order was written for (order 1, no residual)."""
    return OrderTest(None, 1, (), 0.0, rates)


def sampled_side(
    conf: Configuration,
    rtol: float,
    held: tuple[int, ...],
    unwritten: tuple[Unwritten, ...],
    seed: int = 0,
    given: tuple[Motion, ...] | None = None,
) -> Side:
    """The :class:`Side` of ``conf`` (joints of velocity indices ``held`` still) from closed samples alone.

    Args:
        conf: the closed configuration.
        rtol: relative tolerance of the rank decisions.
        held: velocity indices of the joints held.
        unwritten: the couplings whose higher derivatives are not written (named in the report).
        seed: of the random directions.
        given: the platform motions to judge, as for :func:`pinmob.analysis.finite.finite_side.analyse_side`.
    """
    mech = conf.mechanism
    nv = mech.model.nv
    col = closed_chain_columns(conf)
    kernel = closed_rates(conf, held, rtol)  # (nv, m) dimensionless, orthonormal
    m = kernel.shape[1]
    rng = np.random.default_rng(seed)
    dof = kind = None
    found_motions: tuple[Motion, ...] = ()
    rows = frame_rows(conf, mech.platform) if mech.has_platform else np.zeros((6, nv))
    w = twist_scaling(mech.length_scale)
    if mech.has_platform:
        dof, kind, found_motions = platform_motions(conf, kernel, rtol)
        found_motions = motions_to_judge(found_motions, given, dof, rows @ kernel, mech.length_scale)
    candidates: tuple[Branch, ...] = ()
    notes: list[str] = []
    if m:
        path = follow_rates(
            mech, conf, kernel @ rng.normal(size=m), amplitude=BRANCH_STEP, steps=1, held=held, rtol=rtol, halvings=2
        )
        candidates = (Branch(m, dof, kind, found_motions, "q", kernel, untested(kernel), max(path.reached)),)
    evidence = decide_by_samples(conf, kernel, None, candidates, held, rtol, seed) if m else None
    finite_mech: int | None
    finite_dof: int | None
    branches: tuple[Branch, ...]
    if evidence is None:  # the closure Jacobian has full rank: q is isolated (the implicit function theorem)
        how = "the closure Jacobian (no first-order motion: q is isolated)"
        samples = LocalDimension(0, 0, RADIUS, 0, 0 if mech.has_platform else None, (), 0, 0)
        finite_mech, finite_dof, branches, reach = 0, (0 if mech.has_platform else None), (), kernel
        conflict = ""
    else:
        how, samples, reach = evidence.how, evidence.samples, evidence.reach
        finite_mech, finite_dof = evidence.finite_mechanism_dof, evidence.finite_dof
        branches = tuple(sorted(evidence.branches, key=branch_order))
        conflict = evidence.conflict
        notes = [] if how else [f"closed samples: {conflict}"]
    motions: list[MotionVerdict] = []
    internal: list[MotionVerdict] = []
    vectors: list[Array] = []
    internal_vectors: list[Array] = []
    lifts = np.eye(m)
    if mech.has_platform and m:
        on_kernel = rows @ kernel
        lifts = decide_rank(on_kernel, rtol, n=m, at_least=1.0).null_space.T
        for mo in found_motions:
            target = w * mo.twist
            rates = kernel @ np.linalg.lstsq(on_kernel, target, rcond=None)[0]
            traced = trace_motion(conf, mo, rtol) if not held else trace_rates(conf, rates, held, rtol, target)
            motions.append(MotionVerdict(mo.label, Verdict.UNDECIDED, None, (), traced, untested(rates), "", motion=mo))
            vectors.append(target)
    if not held and m:
        for label, rates in internal_motions(conf, kernel @ lifts):
            traced = trace_rates(conf, rates, held, rtol)
            by_name = joint_rates(mech, col * rates)
            internal.append(MotionVerdict(label, Verdict.UNDECIDED, None, (), traced, untested(rates), "", by_name))
            internal_vectors.append(rates)
    if how:
        motions, internal = settle_side(
            motions, vectors, internal, internal_vectors, branches, rows, reach, finite_dof, finite_mech
        )
    else:  # the samples conflict: every verdict stays undecided, with the numbers
        motions = [_undecided(v, conflict) for v in motions]
        internal = [_undecided(v, conflict) for v in internal]
    return Side(
        held_names(mech.model, held),
        dof,
        kind,
        m,
        finite_dof if how else None,
        finite_mech if how else None,
        branches,
        tuple(motions),
        tuple(internal),
        samples,
        tuple(notes),
        None,  # no condition written: no tolerance
        how,
        unwritten,
    )


def _undecided(v: MotionVerdict, why: str) -> MotionVerdict:
    return MotionVerdict(v.label, Verdict.UNDECIDED, None, (), v.traced, v.test, why, v.joints, v.motion)
