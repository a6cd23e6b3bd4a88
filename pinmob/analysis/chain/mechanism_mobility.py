"""Whole-mechanism mobility: mechanism DoF, redundant constraints, idle motions, actuation, frame motions.

With the dimensionless closure Jacobian ``K`` (rows, nv) of
:mod:`pinmob.analysis.chain.closed_chain`:

- mechanism DoF ``m = nv - rank K``: the closed chain's joint velocities are ``null K``;
- redundant (over-constraining) equations ``rows - rank K``; per closure c,
  independent of the order of declaration: ``essential_c = rank K - rank K_-c``
  (``K_-c``: K without c's rows), the constraint directions only c provides
  (removing c frees that many motions; 0 = c is not needed), and
  ``redundant_c = rows_c - essential_c``, its equations implied by the rest
  (its own other rows and the other closures). Two closures that repeat each
  other both count theirs, so these add up to at least ``rows - rank K``;
- Grubler-Kutzbach count ``sum f_joints - sum rows_closures = nv - rows``
  (``6 (n - 1 - j) + sum f`` with each closure as a joint of 6 - rows
  freedoms); it equals ``m`` only when no equation is redundant. Where the
  closures' own rows are dependent (``sum_c rank K_c < rows``), e.g. a planar
  mechanism, whose joint screws span a motion subgroup of dimension 3
  (:func:`pinmob.screw.subgroup.motion_subgroup`), where a weld's six spatial
  equations hold three, the count by the closures' own ranks
  ``nv - sum_c rank K_c`` is given beside the spatial one;
- internal motions: closed-chain motions that leave the output frame still,
  ``m`` minus the output's DoF (one output only);
- idle motions: the internal motions that move no actuated joint, no output
  frame (the platform, else the tree's leaf bodies that carry no closure
  frame; frames named only to be reported are not outputs), no joint centre
  and no closure point; e.g. a rod spinning about the line through its two
  ball joints;
- actuation (:mod:`pinmob.analysis.chain.actuation`);
- the motion of any frame: the image of ``null K`` by its Jacobian, classified
  like the platform's (:func:`pinmob.screw.classify.classify_twists`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from pinmob.analysis.chain.actuation import Actuation, actuation, default_end_frames, held_indices
from pinmob.analysis.chain.closed_chain import closed_chain, frame_rows, moving_joints, rates_of
from pinmob.analysis.chain.locking import lock_motions
from pinmob.analysis.chain.redundancy import REDUNDANCY_RULE, ClosureRank, closure_ranks
from pinmob.analysis.configuration import Configuration, as_configuration
from pinmob.analysis.motion import Motion, classified_motions, columns
from pinmob.assembly import CLOSURE_TOL
from pinmob.blas import one_blas_thread
from pinmob.frozen import ReadOnlyArrays
from pinmob.model import Mechanism, frame_id, frame_name, tendon_rows
from pinmob.screw import (
    RTOL,
    Array,
    MotionSubgroup,
    check_rtol,
    decide_rank,
    motion_subgroup,
    motion_type,
    shift_twists,
    twist_scaling,
)


@dataclass(frozen=True)
class FrameMobility(ReadOnlyArrays):
    """How one frame can move on the closed chain: ``dof`` = rank of ``J_frame null(K)``."""

    frame: str
    dof: int
    motion_type: str
    motions: tuple[Motion, ...]
    free_twists: Array = field(repr=False)
    origin: Array = field(default_factory=lambda: np.zeros(3), repr=False)
    length_scale: float = 1.0

    def to_dict(self) -> dict[str, Any]:
        """``{frame, dof, motion_type, motions}`` (each motion with its ``world_point``)."""
        return {
            "frame": self.frame,
            "dof": self.dof,
            "motion_type": self.motion_type,
            "motions": [m.to_dict(self.origin, self.length_scale) for m in self.motions],
        }


@dataclass(frozen=True)
class MechanismMobility(ReadOnlyArrays):
    """Mobility of the whole closed chain at one configuration (see the module docstring).

    ``end_frames`` are the output frames that idle motions leave at rest and
    that the actuation must control; ``frames`` the reported frame motions
    (the outputs first, then the frames named to be reported).
    """

    mechanism: str
    configuration: str | None
    nv: int
    rows: int
    rank: int
    mechanism_dof: int
    grubler: int
    closures: tuple[ClosureRank, ...]
    idle_dof: int
    idle_joints: tuple[str, ...]
    actuation: Actuation
    frames: tuple[FrameMobility, ...]
    end_frames: tuple[str, ...]
    singular_values: Array = field(repr=False)
    tolerance: float = 0.0
    length_scale: float = 1.0
    motions: Array = field(default_factory=lambda: np.zeros((0, 0)), repr=False)
    subgroup: MotionSubgroup | None = None
    ignored: tuple[str, ...] = ()

    @property
    def grubler_by_own_rank(self) -> int:
        """Grubler-Kutzbach with each closure counted by the rank of its own rows: ``nv - sum_c rank K_c``."""
        return self.nv - sum(c.rank for c in self.closures)

    @property
    def redundant_constraints(self) -> int:
        """Closure equations implied by the others: ``rows - rank K``."""
        return self.rows - self.rank

    @property
    def internal_dof(self) -> int | None:
        """Closed-chain motions with the output frame still: mechanism DoF minus its DoF (None unless one output)."""
        if len(self.end_frames) != 1 or not self.frames or self.frames[0].frame != self.end_frames[0]:
            return None
        return self.mechanism_dof - self.frames[0].dof

    @property
    def redundant_by_closure(self) -> dict[str, int]:
        """Per closure, its equations implied by the rest (:attr:`ClosureRank.redundant`); order-independent."""
        return {c.name: c.redundant for c in self.closures}

    def to_dict(self) -> dict[str, Any]:
        """The whole-mechanism document (plain JSON)."""
        return {
            "mechanism": self.mechanism,
            "configuration": self.configuration,
            "nv": self.nv,
            "closure_rows": self.rows,
            "closure_rank": self.rank,
            "mechanism_dof": self.mechanism_dof,
            "internal_dof": self.internal_dof,
            "idle_dof": self.idle_dof,
            "idle_joints": list(self.idle_joints),
            "redundant_constraints": self.redundant_constraints,
            "redundant_by_closure": self.redundant_by_closure,
            "grubler": self.grubler,
            "grubler_by_own_rank": self.grubler_by_own_rank,
            "motion_subgroup": None if self.subgroup is None else asdict(self.subgroup),
            "actuation": self.actuation.to_dict(),
            "redundant_by_closure_rule": REDUNDANCY_RULE,
            "closures": [c.to_dict() for c in self.closures],
            "end_frames": list(self.end_frames),
            "frames": [f.to_dict() for f in self.frames],
            "singular_values": self.singular_values.tolist(),
            "tolerance": self.tolerance,
            "length_scale": self.length_scale,
            "ignored": list(self.ignored),
        }

    def __str__(self) -> str:
        """Multi-line report of the whole closed chain: DoF, redundancy, idle motions, actuation, frames."""
        where = f" at {self.configuration!r}" if self.configuration else ""
        act = self.actuation
        lines = [
            f"{self.mechanism}{where}: mechanism DoF {self.mechanism_dof} (nv {self.nv} - closure rank {self.rank}), "
            f"Grubler-Kutzbach {self.grubler} (nv {self.nv} - {self.rows} closure equations)"
            + (f", ignoring what pinmob does not read: {'; '.join(self.ignored)}" if self.ignored else ""),
        ]
        own = sum(c.rank for c in self.closures)
        if own < self.rows:
            group = self.subgroup
            lines.append(
                f"  the spatial count: the closures' own equations have rank {own} of {self.rows} here"
                + (
                    f" (every joint screw lies in a {group.name} motion subgroup of dimension {group.dimension})"
                    if group is not None
                    else ""
                )
                + f"; counted by those ranks, nv {self.nv} - {own} = {self.grubler_by_own_rank}"
            )
        internal = self.internal_dof
        if internal:
            out = self.frames[0]
            lines.append(
                f"  = {out.dof} DoF of frame {out.frame!r} + {internal} internal motion(s): joints moving while "
                f"{out.frame!r} stays still ({self.idle_dof} of them idle)"
            )
        per_closure = ", ".join(f"{k}: {v}" for k, v in self.redundant_by_closure.items() if v)
        redundant = (
            f" (equations implied by the rest, per closure: {per_closure})" if self.redundant_constraints else ""
        )
        lines.append(f"redundant closure equations: {self.redundant_constraints}{redundant}")
        unneeded = [c.name for c in self.closures if not c.needed]
        if unneeded:
            lines.append(f"closures that add no constraint (removing one changes nothing): {', '.join(unneeded)}")
        lines.append(
            f"idle motions: {self.idle_dof}"
            + (f" (joints {', '.join(self.idle_joints)})" if self.idle_dof else "")
            + f"; outputs: {', '.join(self.end_frames) or 'none'} (and every joint centre and closure point)"
        )
        verdict = "valid" if act.valid else "NOT valid"
        lines.append(
            f"actuation {verdict}{act.base_note}: {act.count_text}; locked, {act.locked_dof} motion(s) remain "
            f"({act.idle_dof} idle)"
            + (f"; {act.redundant_actuators} actuator(s) over-determine the chain" if act.redundant_actuators else "")
        )
        for rates in act.remaining:
            lines.append(
                "  remaining motion: "
                + ", ".join(f"{k} {v:+.3g}" for k, v in list(rates.items())[:8])
                + (" ..." if len(rates) > 8 else "")
            )
        for f in self.frames:
            rigid = act.frame_dof.get(f.frame)
            lines.append(
                f"frame {f.frame!r}: {f.dof} DoF, {f.motion_type}"
                + (f"; {rigid} DoF with the actuators locked" if rigid is not None else "")
                + " (axis points in world coordinates)"
            )
            lines.extend(m.line(f.origin, f.length_scale) for m in f.motions)
        lines.append(f"closure rank tolerance {self.tolerance:.2e}, L = {self.length_scale:.4g} m")
        return "\n".join(lines)


def frame_mobility(
    mech: Mechanism | Configuration,
    q: ArrayLike | str | Configuration | None,
    frame: str,
    *,
    rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL,
) -> FrameMobility:
    """Free motions of ``frame`` at ``q``: :func:`frame_mobility_at`, ``rtol`` raised as :func:`pinmob.analyze` raises it."""
    conf = as_configuration(mech, q, closure_tol=closure_tol)
    return frame_mobility_at(conf, frame, conf.rank_rtol(check_rtol(rtol)))


@one_blas_thread
def frame_mobility_at(conf: Configuration, frame: str, rtol: float) -> FrameMobility:
    """Free motions of ``frame`` at ``conf`` with the rank tolerance ``rtol`` as given (cached per frame and tolerance).

    The image ``J_frame null(K)`` of every closed-chain motion (all closures,
    limb tips welded to the platform included), classified like the
    platform's (:func:`pinmob.screw.classify.classify_twists`). Cached on the
    configuration: where the limb-wise method does not apply, the platform
    mobility and the whole-mechanism analysis share the platform's.

    Raises:
        FrameError: no such frame (the message lists them).
    """
    mech = conf.mechanism
    fid = frame_id(mech.model, frame)

    def compute() -> FrameMobility:
        length = mech.length_scale
        image = frame_rows(conf, frame) @ closed_chain(conf, rtol).null
        dec = decide_rank(image.T, rtol, 6, at_least=1.0)
        basis = dec.row_space.T  # (6, rank): the image's orthonormal column span
        system, motions = classified_motions(conf, basis, rtol)
        origin = np.array(conf.frame_placement(fid).translation)
        return FrameMobility(
            frame, basis.shape[1], motion_type(system), motions, columns([mo.twist for mo in motions]), origin, length
        )

    return conf.memo(("frame_mobility", frame, rtol), compute)


@one_blas_thread
def mechanism_mobility(
    conf: Configuration,
    rtol: float,
    *,
    actuated: Sequence[str] | None = None,
    frames: Sequence[str] | None = None,
    outputs: Sequence[str] | None = None,
) -> MechanismMobility:
    """Mobility of the whole closed chain at a closed configuration.

    Args:
        conf: the closed configuration.
        rtol: relative tolerance of every rank decision.
        actuated: actuated joints (default: the mechanism's declared ones, and its tendon actuators;
            joints given: those alone).
        frames: frames whose motion is reported besides the outputs; naming
            them changes no count or verdict.
        outputs: frames that idle motions must leave at rest and that the
            actuation must control (default :func:`default_end_frames`: the
            platform, else the tree's free leaf bodies).

    Raises:
        FrameError: a frame does not exist (frame names are matched ignoring case where unambiguous).
    """
    mech = conf.mechanism
    acts = tuple(mech.actuated if actuated is None else actuated)
    tendons, names = (mech.actuated_tendons, mech.joint_actuators) if actuated is None else ((), ())  # joints named
    outs = tuple(default_end_frames(mech) if outputs is None else (frame_name(mech.model, f) for f in outputs))
    named = (frame_name(mech.model, f) for f in frames or ())
    reported = outs + tuple(f for f in dict.fromkeys(named) if f not in outs)
    chain = closed_chain(conf, rtol)
    dec, null = chain.decision, chain.null
    held = rates_of(null, held_indices(mech, acts))
    if tendons:
        held = np.vstack([held, tendon_rows(mech.model, tendons, conf.q, chain.col) @ null])
    split = lock_motions(conf, null, held, outs, rtol)
    rows = int(chain.k_hat.shape[0])
    top = max(1.0, float(dec.singular_values[0]) if dec.singular_values.size else 0.0)  # the rank rule's reference
    return MechanismMobility(
        mechanism=mech.name,
        configuration=conf.name,
        nv=mech.model.nv,
        rows=rows,
        rank=dec.rank,
        mechanism_dof=mech.model.nv - dec.rank,
        grubler=mech.model.nv - rows,
        closures=closure_ranks(mech, chain.k_hat, rtol, top, chain.left_null, dec.margin),
        idle_dof=split.idle.shape[1],
        idle_joints=moving_joints(mech, null @ split.idle),
        actuation=actuation(conf, chain, acts, split, reported, rtol, tendons, names),
        frames=tuple(frame_mobility_at(conf, f, rtol) for f in reported),
        end_frames=outs,
        singular_values=dec.singular_values,
        tolerance=dec.tolerance,
        length_scale=mech.length_scale,
        motions=chain.col[:, None] * null,
        subgroup=joint_subgroup(conf, rtol),
        ignored=mech.ignored,
    )


def joint_subgroup(conf: Configuration, rtol: float) -> MotionSubgroup | None:
    """The motion subgroup every joint screw of the tree lies in at ``conf`` (None: all of SE(3), or not a group).

    The screws are taken at the centroid of the joints (so that where the mechanism stands does not matter) and made
    dimensionless with its length scale.
    """
    mech = conf.mechanism
    centre = np.mean([m.translation for m in conf.data.oMi[1:]], axis=0) if mech.model.njoints > 1 else np.zeros(3)
    screws = shift_twists(conf.world_jacobian, centre)
    return motion_subgroup(twist_scaling(mech.length_scale)[:, None] * screws, rtol)
