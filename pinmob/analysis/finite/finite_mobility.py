"""Finite versus instantaneous mobility: which free motions really exist, to which order, and where branches meet.

The free motions of :func:`pinmob.analyze` are first-order: the null space of a Jacobian. At special
configurations that overstates the mobility (the seed paper's flat 3-PUU: 1T1R instantaneously, yet
the rotation is impossible at finite amplitude). :func:`finite_mobility` answers for the platform and
for the whole closed chain, free and with the actuators held:

1. Müller's higher-order conditions on the closure equations, from the instantaneous joint screws
   and their Lie brackets (:mod:`pinmob.screw.lie`, :mod:`pinmob.analysis.finite.loop_screws`,
   :mod:`pinmob.analysis.finite.tangent_cone`), up to ``order`` (default 4): the second-order tangent cone
   split into linear components, the tangent spaces of the motion branches through q, each checked
   to ``order`` (:mod:`pinmob.analysis.finite.branches`); per instantaneous motion, finite, blocked at order
   k (shaky), or a branch point (:mod:`pinmob.analysis.finite.verdicts`);
2. each motion and branch traced by the predictor-corrector of :mod:`pinmob.analysis.follow.motion_path`;
3. the local dimension estimated from closed samples near q (:mod:`pinmob.analysis.finite.local_dimension`).

The finite DoF are the largest branch's (for the platform, the largest platform DoF on a branch,
taken at the branch's generic points). Where the three disagree, the closed samples' own local dimension
and, with one first-order motion left, the reduced closure equation decide
(:mod:`pinmob.analysis.finite.sample_modes`), and the report says which evidence did; only where that evidence
conflicts is the number None, the notes saying why with the numbers: the analysis never guesses. Redundant closures (Bennett's, Bricard's
linkages) need nothing special: the conditions are written on every loop.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

from pinmob.analysis.configuration import Configuration
from pinmob.analysis.finite.branches import branch_joints, branch_point_name
from pinmob.analysis.finite.coupling_rows import hold_tendons, moments_off_lengths
from pinmob.analysis.finite.finite_side import Side, analyse_side
from pinmob.analysis.finite.higher_order import ORDER, ORDER_TOL, check_order
from pinmob.analysis.finite.sampled_side import sampled_side, unwritten, unwritten_words
from pinmob.analysis.finite.verdicts import MotionVerdict
from pinmob.analysis.motion import Motion
from pinmob.assembly import joint_velocity_indices


@dataclass(frozen=True)
class FiniteMobility:
    """Finite and instantaneous mobility at one configuration (see the module docstring).

    Attributes:
        mechanism, configuration: names.
        order: the bound on the order of the conditions checked (asked for: where a side's conditions are not
            written, ``Side.unwritten``, none is checked).
        tolerance: the absolute tolerance of the free side's conditions (``order_tol * max(1, sigma_max(A))``;
            None where they are not written).
        free: the analysis of the mechanism as it is.
        locked: the analysis with the actuated joints held (None when no actuator is declared).
        platform: the platform frame's name ("" without one).
        unheld: actuators on sites without a reference site and on free joints, not held by ``locked`` (MuJoCo
            gives them no length; it holds joints, and tendons and the other actuators' lengths as tendon
            equalities: :func:`pinmob.analysis.finite.coupling_rows.hold_tendons`).
    """

    mechanism: str
    configuration: str | None
    order: int
    tolerance: float | None
    free: Side
    locked: Side | None
    platform: str
    conf: Configuration
    unheld: tuple[str, ...] = ()

    @property
    def finite_dof(self) -> int | None:
        """The platform's finite DoF (None: no platform, or cannot decide)."""
        return self.free.finite_dof

    @property
    def finite_mechanism_dof(self) -> int | None:
        """The closed chain's finite DoF (None: cannot decide)."""
        return self.free.finite_mechanism_dof

    @property
    def finite_dof_locked(self) -> int | None:
        """With the actuators held: the platform's finite DoF, else (no platform) the closed chain's."""
        if self.locked is None:
            return None
        return self.locked.finite_dof if self.platform else self.locked.finite_mechanism_dof

    @property
    def motions(self) -> tuple[MotionVerdict, ...]:
        """A verdict per instantaneous platform motion."""
        return self.free.motions

    def report_entries(self) -> dict[str, Any]:
        """The keys ``pinmob analyze --finite --json`` adds to the report's document.

        ``finite_dof``, ``finite_mechanism_dof``, ``finite_dof_locked`` (where actuators are declared)
        and ``finite`` (:meth:`to_dict`).
        """
        out: dict[str, Any] = {"finite_dof": self.finite_dof, "finite_mechanism_dof": self.finite_mechanism_dof}
        if self.locked is not None:
            out["finite_dof_locked"] = self.finite_dof_locked
        return out | {"finite": self.to_dict()}

    def to_dict(self) -> dict[str, Any]:
        """The ``finite`` entry of ``pinmob analyze --finite --json`` (plain JSON).

        ``order_bound`` and ``tolerance`` are those of the side's conditions, null where they are not written
        (``conditions_not_written``: the closed samples alone decided).
        """
        out = {
            "order_bound": None if self.free.unwritten else self.order,
            "tolerance": self.free.tolerance,
            "dof": self.free.dof,
            "finite_dof": self.finite_dof,
            "mechanism_dof": self.free.mechanism_dof,
            "finite_mechanism_dof": self.finite_mechanism_dof,
            "motions": [m.to_dict() for m in self.free.motions],
            "internal_motions": [m.to_dict() for m in self.free.internal],
            "branches": [b.to_dict(branch_joints(self.conf, b)) for b in self.free.branches],
            "branch_point": branch_point_name(self.free.branches),
            "samples": self.free.samples.to_dict(),
            "notes": list(self.free.notes),
            "evidence": self.free.evidence or None,
            "conditions_not_written": [str(u) for u in self.free.unwritten],
            "tendons_not_held": list(self.unheld),
        }
        if self.locked is not None:
            lk = self.locked
            out["locked"] = {
                "held": list(lk.held),
                "order_bound": None if lk.unwritten else self.order,
                "tolerance": lk.tolerance,
                "dof": lk.dof if self.platform else lk.mechanism_dof,
                "finite_dof": self.finite_dof_locked,
                "mechanism_dof": lk.mechanism_dof,
                "finite_mechanism_dof": lk.finite_mechanism_dof,
                "motions": [m.to_dict() for m in lk.motions],
                "branches": [b.to_dict(branch_joints(self.conf, b)) for b in lk.branches],
                "branch_point": branch_point_name(lk.branches),
                "samples": lk.samples.to_dict(),
                "notes": list(lk.notes),
                "evidence": lk.evidence or None,
                "conditions_not_written": [str(u) for u in lk.unwritten],
            }
        return out

    def brief(self) -> str:
        """``platform 1 DoF finite, 1T`` (the closed chain's without a platform): ``--brief --finite`` adds it."""
        if self.platform:
            return f"platform {_finite(self.free, self.finite_dof)}"
        return f"mechanism {_finite(self.free, self.finite_mechanism_dof, False)}"

    def __str__(self) -> str:
        """The block ``pinmob analyze --finite`` prints."""
        free = self.free
        many = len(free.branches) > 1
        origin = self.conf.platform_origin if self.platform else None
        length = self.conf.mechanism.length_scale
        conditions = "no higher-order conditions (see below)"
        if free.tolerance is not None:
            conditions = f"higher-order conditions up to order {self.order} (tolerance {free.tolerance:.2e})"
        lines = [
            f"finite mobility: {conditions}, "
            f"each motion traced, {free.samples.samples} closed samples within {free.samples.radius:g} of q"
        ]
        if self.platform:
            lines.append(
                f"platform: {_finite(free, free.finite_dof)} (instantaneous: {free.dof} DoF, {free.motion_type})"
            )
            lines += [m.line(many, origin, length) for m in free.motions]
        internal = "; internal motions (the platform still to first order):" if free.internal and self.platform else ""
        internal = internal or (":" if free.internal else "")
        lines.append(
            f"mechanism: {_finite(free, free.finite_mechanism_dof, False)} (instantaneous: {free.mechanism_dof}){internal}"
        )
        lines += [m.line(many) for m in free.internal]
        lines += _branch_lines(free)
        lines += [f"  note: {n}" for n in free.notes]
        lines += _evidence_lines(free, self.order)
        if self.locked is not None:
            lk = self.locked
            what, inst = ("platform", lk.dof) if self.platform else ("mechanism", lk.mechanism_dof)
            lines.append(
                f"actuators held ({', '.join(lk.held)}): {what} {_finite(lk, self.finite_dof_locked, False)} "
                f"(instantaneous: {inst})"
            )
            lines += [m.line(len(lk.branches) > 1, origin, length) for m in lk.motions]
            lines += [f"  note: {n}" for n in lk.notes]
            lines += _evidence_lines(lk, self.order)
        if self.unheld:
            lines.append(
                f"actuators held: actuator(s) {', '.join(self.unheld)} not held (on a site without a reference site "
                "or on a free joint: MuJoCo gives such an actuator no length, a force or torque with nothing to "
                "hold at finite amplitude)"
            )
        return "\n".join(lines)


def _finite(side: Side, dof: int | None, types: bool = True) -> str:
    """``1 DoF finite, 1T`` (with ``types``: the motion types of the branches giving the platform that many DoF)."""
    if dof is None:
        return "cannot decide the finite DoF"
    kinds = (
        [] if not types else list(dict.fromkeys(b.motion_type for b in side.branches if b.dof == dof and b.motion_type))
    )
    return f"{dof} DoF finite" + (f", {' or '.join(kinds)}" if kinds and dof else "")


def _evidence_lines(side: Side, order: int) -> list[str]:
    """The line saying what decided where the conditions up to the order bound did not (none when they did)."""
    if side.unwritten:
        return [
            f"  decided by {side.evidence or 'nothing'} alone: the order conditions were not used "
            f"({unwritten_words(side.unwritten)}: no higher derivatives written)"
        ]
    if not side.evidence:
        return []
    return [f"  the conditions up to order {order} do not decide; decided by {side.evidence}"]


def _branch_lines(side: Side) -> list[str]:
    """One line per motion branch through q (none for a rigid mechanism)."""
    if not side.branches:
        return ["branches through q: none (no closed configuration near q but q)"] if side.mechanism_dof else []
    name = branch_point_name(side.branches)
    lines = [f"branches through q: {len(side.branches)}" + (f" ({name})" if name else "")]
    for i, b in enumerate(side.branches):
        where = "" if b.where == "q" else " (at a nearby point of the branch: at q it moves less, to first order)"
        if b.test is None:
            where = " (at closed samples near q: its tangent cone at q is not a linear space)"
        plat = f"; the platform {b.dof} DoF, {b.motion_type}{where}" if b.dof is not None else ""
        lines.append(f"  branch {i + 1}: {b.dimension} DoF{plat}")
    return lines


def finite_mobility(
    conf: Configuration,
    rtol: float,
    order: int = ORDER,
    order_tol: float = ORDER_TOL,
    seed: int = 0,
    motions: tuple[Motion, ...] | None = None,
    locked_motions: tuple[Motion, ...] | None = None,
) -> FiniteMobility:
    """Finite and instantaneous mobility at ``conf``, free and with the declared actuators held.

    Args:
        conf: the closed configuration.
        rtol: relative tolerance of the first-order rank decisions.
        order: the highest order of the conditions checked (2..8).
        order_tol: relative tolerance of the conditions.
        seed: of the random directions (cone points, tracing directions, samples).
        motions: the instantaneous platform motions to judge (default: the closed chain's, classified
            here; :func:`pinmob.analyze` passes its platform mobility's, so the labels are its own).
        locked_motions: likewise with the actuators held (the report passes its singularity block's
            uncontrolled motions).

    Raises:
        ConfigurationError: a bad order bound, or a joint type the conditions cannot treat.
    """
    order = check_order(order)

    def side(c: Configuration, held: tuple[int, ...], given: tuple[Motion, ...] | None) -> Side:
        blind = unwritten(c.mechanism.all_closures)  # no higher derivatives: the closed samples alone decide
        if blind:
            return sampled_side(c, rtol, held, blind, seed, given)
        return analyse_side(c, rtol, order, order_tol, held, seed, given)

    def compute() -> FiniteMobility:
        mech = conf.mechanism
        free = side(conf, (), motions)
        locked = None
        tendons, held_tendons, others = hold_tendons(conf)  # tendon actuators held as tendon equalities
        if mech.actuated or held_tendons:
            held = tuple(int(i) for i in joint_velocity_indices(mech, list(mech.actuated)))
            locked = side(tendons, held, locked_motions)
            locked = replace(locked, held=locked.held + held_tendons)
            if off := moments_off_lengths(conf):
                note = (
                    f"the moment arms MuJoCo gives actuator(s) {', '.join(off)} at q (which the first-order actuation "
                    "holds) are not the derivatives of their lengths (held here): the first-order counts may differ"
                )
                locked = replace(locked, notes=(*locked.notes, note))
        unheld = tuple(t.name for t in others)
        return FiniteMobility(mech.name, conf.name, order, free.tolerance, free, locked, mech.platform, conf, unheld)

    key = tuple(
        None if ms is None else tuple((m.label, m.twist.tobytes()) for m in ms) for ms in (motions, locked_motions)
    )
    return conf.memo(("finite", rtol, order, order_tol, seed, key), compute)
