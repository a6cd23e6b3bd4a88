"""Readable text reports of mobility results."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from .screw import MotionKind, WrenchKind

if TYPE_CHECKING:
    from .constraints import MechanismMobility
    from .mechanism import Expectation
    from .mobility import Mobility, Motion

KIND_WORDS = {"T": "translation", "R": "rotation", "H": "screw"}


def _v(a: np.ndarray, digits: int = 4) -> str:
    return "[" + ", ".join(f"{x: .{digits}g}" for x in np.asarray(a) + 0.0) + "]"


def _motion_line(m: Motion) -> str:
    """``  T1 x     translation direction [...]`` (+ ``through [...] m``, ``pitch ... m/rad``)."""
    text = f"  {m.label:<8} {KIND_WORDS[m.kind.value]:<11} direction {_v(m.direction)}"
    if m.point is not None:
        text += f" through {_v(m.point)} m"
    if m.kind is MotionKind.SCREW:
        text += f", pitch {m.pitch:.4g} m/rad"
    return text


def format_mobility(mob: Mobility) -> str:
    """Multi-line report: DoF and type, each motion, the constraints, limbs and numbers."""
    where = f" at {mob.configuration!r}" if mob.configuration else ""
    view = " (paper's view: generic limb wrenches carried here)" if mob.view == "paper" else ""
    lines = [f"{mob.mechanism}{where}{view}: {mob.dof} DoF, {mob.motion_type}"]
    lines.extend(_motion_line(m) for m in mob.motions)
    lines.append(f"constraint rank {mob.constraint_rank}:")
    for c in mob.constraints:
        text = f"  {c.kind.value:<7} direction {_v(c.direction)}"
        if c.point is not None:
            text += f" through {_v(c.point)} m"
        if c.kind is WrenchKind.WRENCH:
            text += f", pitch {c.pitch:.4g} m/rad"
        lines.append(text)
    if mob.method_note:
        lines.append(f"method: {mob.method.value} ({mob.method_note})")
    lines.append("limbs:" if mob.limbs else "limbs: none used")
    for limb in mob.limbs:
        flag = "  <- serial singularity" if limb.serially_singular else ""
        loops = (
            f" + {len(limb.loop_joints)} loop joint(s), closed by {', '.join(limb.closures)}" if limb.closures else ""
        )
        lines.append(
            f"  {limb.name}: {len(limb.joints)} joints{loops}, twist rank {limb.twist_rank} "
            f"(generic {limb.generic_twist_rank}), {limb.wrench_count} constraint wrench(es){flag}"
        )
    singular = mob.serially_singular_limbs
    if singular and mob.view == "configuration":
        lines.append(
            f"note: limb(s) {', '.join(singular)} are at a serial singularity: their joint screws are dependent "
            "here, so each has more constraint wrenches than at generic configurations. A method that carries "
            "the generic limb wrenches to this configuration (as the seed paper does) misses them: see --paper-view."
        )
    lines.append(
        f"singular values {_v(mob.singular_values, 3)}, tolerance {mob.tolerance:.2e}, L = {mob.length_scale:.4g} m"
    )
    lines.append(f"frame: {mob.frame}")
    return "\n".join(lines)


def format_expectation(mob: Mobility, expected: Expectation) -> str:
    """One line comparing a result with the mechanism file's expectation."""
    ok = mob.dof == expected.dof and mob.motion_type == expected.motion_type
    verdict = "agrees with" if ok else "DIFFERS from"
    src = f" ({expected.source})" if expected.source else ""
    return f"expected {expected.dof} DoF {expected.motion_type}{src}: analysis {verdict} it"


def format_mechanism(mm: MechanismMobility) -> str:
    """Multi-line report of the whole closed chain: DoF, redundancy, idle motions, actuation, frames."""
    where = f" at {mm.configuration!r}" if mm.configuration else ""
    act = mm.actuation
    lines = [
        f"{mm.mechanism}{where}: mechanism DoF {mm.mechanism_dof} (nv {mm.nv} - closure rank {mm.rank}), "
        f"Grubler-Kutzbach {mm.grubler} (nv {mm.nv} - {mm.rows} closure equations)",
        f"redundant closure equations: {mm.redundant_constraints}"
        + (
            " (equations implied by the rest, per closure: "
            + ", ".join(f"{k}: {v}" for k, v in mm.redundant_by_closure.items() if v)
            + ")"
            if mm.redundant_constraints
            else ""
        ),
    ]
    unneeded = [c.name for c in mm.closures if not c.needed]
    if unneeded:
        lines.append(f"closures that add no constraint (removing one changes nothing): {', '.join(unneeded)}")
    lines.append(
        f"idle motions: {mm.idle_dof}"
        + (f" (joints {', '.join(mm.idle_joints)})" if mm.idle_dof else "")
        + f"; outputs: {', '.join(mm.end_frames) or 'none'} (and every joint centre and closure point)"
    )
    verdict = "valid" if act.valid else "NOT valid"
    lines.append(
        f"actuation {verdict}: {len(act.actuated)} actuated joint(s); locked, {act.locked_dof} motion(s) remain "
        f"({act.idle_dof} idle)"
        + (f"; {act.redundant_actuators} actuator(s) over-determine the chain" if act.redundant_actuators else "")
    )
    for rates in act.remaining:
        lines.append(
            "  remaining motion: "
            + ", ".join(f"{k} {v:+.3g}" for k, v in list(rates.items())[:8])
            + (" ..." if len(rates) > 8 else "")
        )
    for f in mm.frames:
        rigid = act.frame_dof.get(f.frame)
        lines.append(
            f"frame {f.frame!r}: {f.dof} DoF, {f.motion_type}"
            + (f"; {rigid} DoF with the actuators locked" if rigid is not None else "")
            + " (axis points relative to its origin, world axes)"
        )
        lines.extend(_motion_line(m) for m in f.motions)
    lines.append(f"closure rank tolerance {mm.tolerance:.2e}, L = {mm.length_scale:.4g} m")
    return "\n".join(lines)
