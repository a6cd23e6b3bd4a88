"""One side of the finite-mobility analysis: the mechanism as it is, or with some joints held.

:func:`analyse_side` runs every step of :mod:`pinmob.analysis.finite.finite_mobility` on the closed chain with the
joints ``held`` kept still (none, or the actuated ones): the higher-order conditions and their
cone (:mod:`pinmob.analysis.finite.tangent_cone`), the branches (:mod:`pinmob.analysis.finite.branches`), a
verdict per instantaneous motion (:mod:`pinmob.analysis.finite.verdicts`), each motion traced, and the
local-dimension estimate from closed samples (:mod:`pinmob.analysis.finite.local_dimension`). The finite
DoF are those of the branches; where the samples, the tracer or the cone do not confirm them, the
fallback of :mod:`pinmob.analysis.finite.sample_modes` decides (``Side.evidence`` says how), and where it
cannot either they are None and a note says why.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
import pinocchio as pin

from pinmob.analysis.chain.closed_chain import closed_chain, closed_chain_columns, frame_rows
from pinmob.analysis.chain.joint_rates import canonical_rates, joint_rates
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.finite.branches import Branch, branch_of, branch_order, platform_motions, tangent_rates
from pinmob.analysis.finite.higher_order import HigherOrder
from pinmob.analysis.finite.local_dimension import LocalDimension, local_dimension
from pinmob.analysis.finite.loop_screws import mechanism_loops
from pinmob.analysis.finite.motion_tracing import trace_motion, trace_rates
from pinmob.analysis.finite.sample_modes import decide_by_samples
from pinmob.analysis.finite.tangent_cone import cone
from pinmob.analysis.finite.verdicts import MotionVerdict, Verdict, judge, motions_to_judge, orthonormal, settle_side
from pinmob.analysis.motion import Motion
from pinmob.screw import Array, decide_rank, twist_scaling


class Unwritten(NamedTuple):
    """A closure whose higher derivatives are not written (:func:`pinmob.analysis.finite.sampled_side.unwritten`).

    Attributes:
        what: ``coupling 'c' on tendons 't1', 't2'``, or the quoted name of an actuator held at its length.
        why: why its derivatives are not written (:attr:`~pinmob.model.tendon.Tendon.unwritten_why`).
        held: an actuator held at its length (MuJoCo's :class:`~pinmob.io.mjcf.actuator_lengths.ActuatorLength`).
    """

    what: str
    why: str
    held: bool = False

    def __str__(self) -> str:
        """``coupling 'c' on tendon 't' (why)``, or ``actuator 'a' held at its length (why)``."""
        return f"actuator {self.what} held at its length ({self.why})" if self.held else f"{self.what} ({self.why})"


@dataclass(frozen=True)
class Side:
    """The finite analysis of the closed chain, free or with some joints held.

    Attributes:
        held: the joints held (names).
        dof: the platform's instantaneous DoF (None without a platform).
        motion_type: the platform's instantaneous motion type (None without a platform).
        mechanism_dof: the closed chain's instantaneous DoF.
        finite_dof: the platform's finite DoF (None: no platform, or cannot decide).
        finite_mechanism_dof: the closed chain's finite DoF (None: cannot decide).
        branches: the motion branches through q.
        motions: a verdict per instantaneous platform motion.
        internal: a verdict per internal motion (platform still to first order; free side only).
        samples: the local-dimension estimate.
        notes: why a finite DoF could not be decided.
        tolerance: the absolute tolerance of the conditions (None where they were not written: ``unwritten``).
        evidence: what decided where the conditions up to the order bound did not ('' when they did;
            :mod:`pinmob.analysis.finite.sample_modes`).
        unwritten: the closures whose higher derivatives are not written (:class:`Unwritten`): the
            order conditions were not used, the closed samples alone decided
            (:mod:`pinmob.analysis.finite.sampled_side`).
    """

    held: tuple[str, ...]
    dof: int | None
    motion_type: str | None
    mechanism_dof: int
    finite_dof: int | None
    finite_mechanism_dof: int | None
    branches: tuple[Branch, ...]
    motions: tuple[MotionVerdict, ...]
    internal: tuple[MotionVerdict, ...]
    samples: LocalDimension
    notes: tuple[str, ...]
    tolerance: float | None
    evidence: str = ""
    unwritten: tuple[Unwritten, ...] = ()


def held_names(model: pin.Model, held: tuple[int, ...]) -> tuple[str, ...]:
    """The names of the joints whose velocity indices are ``held``."""
    return tuple(
        model.names[j] for j in range(1, model.njoints) if model.joints[j].nv and model.joints[j].idx_v in held
    )


def internal_motions(conf: Configuration, rates: Array) -> list[tuple[str, Array]]:
    """Internal motions (orthonormal columns of ``rates`` (nv, g)) split by limb: (label, rates) each.

    The motions moving only one limb's joints come first (``limb A``, or ``limb A 1``, ``limb A 2``),
    then the rest (``coupled 1``, ...); a mechanism without limbs gives ``motion 1``, ``motion 2``, ...
    """
    mech = conf.mechanism
    g = rates.shape[1]
    if g == 0:
        return []
    if not mech.limbs:
        every = canonical_rates(rates)  # one basis, whatever the SVD gave
        return [(f"motion {i + 1}", every[:, i]) for i in range(every.shape[1])]
    out: list[tuple[str, Array]] = []
    found: list[Array] = []
    for limb in mech.limbs:
        outside = np.ones(mech.model.nv, bool)
        outside[limb.screw_v_indices] = False
        local = decide_rank(rates[outside], 1e-9, n=g, at_least=1.0).null_space.T
        own = canonical_rates(rates @ local)  # one basis of the limb's own motions, whatever the SVD gave
        for i in range(own.shape[1]):
            label = f"limb {limb.name}" + (f" {i + 1}" if own.shape[1] > 1 else "")
            out.append((label, own[:, i]))
        found.append(local)
    taken = orthonormal(found, g)
    rest = decide_rank(taken.T, 1e-9, n=g, at_least=1.0).null_space.T if taken.size else np.eye(g)
    coupled = canonical_rates(rates @ rest)
    out += [(f"coupled {i + 1}", coupled[:, i]) for i in range(coupled.shape[1])]
    return out


def analyse_side(
    conf: Configuration,
    rtol: float,
    order: int,
    order_tol: float,
    held: tuple[int, ...] = (),
    seed: int = 0,
    given: tuple[Motion, ...] | None = None,
) -> Side:
    """The :class:`Side` of ``conf`` with the joints of velocity indices ``held`` kept still.

    ``given``: the platform motions to judge (default: the closed chain's, classified here); the
    report passes those of its first-order blocks (the free motions, or the uncontrolled ones with
    the actuators held), so that the labels are the same. They are used when they are as many as
    this side's instantaneous platform DoF and each lies in its image; else this side's own are.
    """
    mech = conf.mechanism
    nv = mech.model.nv
    rng = np.random.default_rng(seed)
    ho = HigherOrder(mechanism_loops(conf), rtol, held, order_tol)
    found = cone(ho, order, seed)
    branches = tuple(
        sorted((branch_of(conf, ho, c, rtol, held, seed + i) for i, c in enumerate(found.components)), key=branch_order)
    )
    kernel = tangent_rates(ho, np.eye(ho.m))
    notes: list[str] = []
    jacobian_dof = ho.m if held else closed_chain(conf, rtol).null.shape[1]
    ambiguous = ho.m != jacobian_dof  # a first-order rank: stays said, not decided by samples
    if ambiguous:
        notes.append(
            f"the loop screws give {ho.m} instantaneous DoF, the closure Jacobian "
            f"{jacobian_dof}: a rank decision is too close to its tolerance"
        )
    if not found.linear:
        notes.append("the second-order cone is not a union of linear spaces: its branches cannot be told apart")
    if found.undecided:
        notes.append(f"cannot decide the second-order cone: {found.undecided}")
    notes += [f"branch {i + 1}: {b.note}" for i, b in enumerate(branches) if b.note]
    col = closed_chain_columns(conf)
    names = held_names(mech.model, held)
    motions: list[MotionVerdict] = []
    internal: list[MotionVerdict] = []
    vectors: list[Array] = []
    internal_vectors: list[Array] = []
    dof = kind = None
    lifts = np.eye(ho.m)
    if mech.has_platform:
        rows = frame_rows(conf, mech.platform)
        on_kernel = rows @ ho.kernel[:nv]
        dof, kind, found_motions = platform_motions(conf, kernel, rtol)
        w = twist_scaling(mech.length_scale)
        found_motions = motions_to_judge(found_motions, given, dof, on_kernel, mech.length_scale)
        lifts = decide_rank(on_kernel, rtol, n=ho.m, at_least=1.0).null_space.T
        spans = [orthonormal([rows @ b.rates], 6) for b in branches]
        for mo in found_motions:
            target = w * mo.twist
            test = ho.test(np.asarray(np.linalg.lstsq(on_kernel, target, rcond=None)[0], float), lifts, order, rng)
            traced = (
                trace_motion(conf, mo, rtol) if not held else trace_rates(conf, test.rates[:nv], held, rtol, target)
            )
            motions.append(judge(mo.label, target, spans, test, traced, motion=mo))
            vectors.append(target)
    if not held:
        spans = [b.rates for b in branches]
        for label, rates in internal_motions(conf, ho.kernel[:nv] @ lifts):
            y = np.asarray(np.linalg.lstsq(ho.kernel[:nv], rates, rcond=None)[0], float)
            test = ho.test(y, None, order, rng)
            traced = trace_rates(conf, rates, held, rtol)
            internal.append(judge(label, rates, spans, test, traced, joint_rates(mech, col * rates)))
            internal_vectors.append(rates)
    finite_mech = max((b.dimension for b in branches), default=0)
    finite_dof = max((b.dof or 0 for b in branches), default=0) if mech.has_platform else None
    undecided = [v.label for v in motions + internal if v.verdict is Verdict.UNDECIDED]
    if undecided:
        notes.append(f"the verdict on {', '.join(undecided)} is undecided, so the finite DoF too")
    fallback = None
    if notes and not ambiguous:  # the conditions do not decide, whatever the estimate below: the fallback decides
        fallback = decide_by_samples(conf, ho.kernel[:nv], ho, branches, held, rtol, seed)
    platform_note = None
    if fallback is not None and fallback.how:
        samples = fallback.samples  # its samples are the estimate (local_dimension's would go unused)
    else:
        samples = local_dimension(conf, kernel, [b.rates for b in branches], held, rtol=rtol, seed=seed)
        if samples.unexplained:
            notes.append(f"{samples.unexplained} closed sample(s) near q lie on none of the branches found")
        if samples.dimension != finite_mech:
            notes.append(
                f"the closed samples span {samples.dimension} dimension(s) on a branch, the branches {finite_mech}"
            )
        if finite_dof is not None and samples.platform != finite_dof:
            platform_note = f"the samples' platform poses span {samples.platform} dimension(s), the branches' platform motions {finite_dof}"
    evidence = ""
    if (notes or platform_note) and not ambiguous:  # the conditions up to the order bound do not decide
        if fallback is None:
            fallback = decide_by_samples(conf, ho.kernel[:nv], ho, branches, held, rtol, seed)
        if fallback.how:
            evidence, notes, platform_note = fallback.how, [], None
            finite_mech, finite_dof = fallback.finite_mechanism_dof or 0, fallback.finite_dof
            branches = tuple(sorted(fallback.branches, key=branch_order))
            rows = frame_rows(conf, mech.platform) if mech.has_platform else np.zeros((6, nv))
            motions, internal = settle_side(
                motions, vectors, internal, internal_vectors, branches, rows, fallback.reach, finite_dof, finite_mech
            )
        else:
            notes.append(f"closed samples: {fallback.conflict}")
    decided = not notes
    return Side(
        names,
        dof,
        kind,
        ho.m,
        finite_dof if decided and platform_note is None else None,
        finite_mech if decided else None,
        branches,
        tuple(motions),
        tuple(internal),
        samples,
        tuple(notes + ([platform_note] if platform_note else [])),
        ho.tol,
        evidence,
    )
