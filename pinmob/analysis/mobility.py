"""Platform mobility at a closed configuration (the seed paper's method, done right).

For each limb i with joint screws ``T_i`` (6, n_i) -- the columns of its tip
frame's ``LOCAL_WORLD_ALIGNED`` Jacobian, carried to the platform origin
(:func:`pinmob.analysis.limbs.limb_twists`) -- the constraint wrenches are a
basis ``W_i`` of ``{w : w^T T_i = 0}``. Stacking them,
``C = [W_1 ... W_k]^T``, an SVD gives the constraint space (rank d) and the
free twists ``{t : C t = 0}`` (dimension 6 - d). All on dimensionless matrices
(:mod:`pinmob.screw`), so the answer does not depend on units.

When a closure couples two or more limbs (its loop involves the joints of
several limbs), or the mechanism has no limbs, no limb has wrenches of its
own: the platform's free twists are then the image of the whole closed
chain's motions, ``J_platform null(K)``
(:func:`pinmob.analysis.chain.mechanism_mobility.frame_mobility_at`), its constraint wrenches
their reciprocal, and the result says so (``method``, ``method_note``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pinmob.analysis.chain.mechanism_mobility import frame_mobility_at
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.generic import generic_twist_ranks
from pinmob.analysis.limbs import LimbMobility, limb_wrenches, limbwise_obstacle
from pinmob.analysis.motion import (
    Constraint,
    Method,
    Motion,
    View,
    classified_motions,
    columns,
    constraints_of,
    numbers,
    point_scale,
    vector,
)
from pinmob.blas import one_blas_thread
from pinmob.exceptions import ConfigurationError
from pinmob.frozen import ReadOnlyArrays
from pinmob.screw import (
    Array,
    MotionKind,
    classify_wrenches,
    clean,
    motion_type,
    reciprocal_twists,
    reciprocal_wrenches,
    wrench_scaling,
)


@dataclass(frozen=True)
class Mobility(ReadOnlyArrays):
    """Mobility of the platform at one configuration.

    Attributes:
        mechanism, configuration: names (configuration may be None).
        dof: number of independent free motions, ``6 - constraint_rank``.
        motion_type: label such as ``3T``, ``3T1R``, ``1T1R1H`` or ``rigid``.
        motions: canonical free motions (translations, rotations, screws by pitch).
        free_twists: (6, dof) the motions' unit twists as columns (read-only).
        constraints: canonical constraint wrenches.
        constraint_wrenches: (6, d) their wrenches ``[f; tau]`` as columns (read-only).
        constraint_rank: d.
        singular_values: (6,) of the stacked dimensionless limb wrenches (zero-padded);
            with the closure-Jacobian method, of an orthonormal basis of the
            constraint space (ones, then zeros).
        tolerance: absolute threshold applied to ``singular_values``.
        length_scale: L [m].
        platform: the platform frame's name.
        platform_origin: (3,) world position of the platform frame [m].
        limbs: per-limb details.
        view: :class:`View`: wrenches at q, or the paper's generic limb wrenches carried to q.
        method: :class:`Method` used; ``closure Jacobian`` when a closure couples
            limbs or there is no limb (``limbs`` is then empty).
        method_note: why that method was used (empty for the limb-wise method).
    """

    mechanism: str
    configuration: str | None
    dof: int
    motion_type: str
    motions: tuple[Motion, ...]
    free_twists: Array = field(repr=False)
    constraints: tuple[Constraint, ...] = field(repr=False)
    constraint_wrenches: Array = field(repr=False)
    constraint_rank: int = 0
    singular_values: Array = field(default_factory=lambda: np.zeros(6), repr=False)
    tolerance: float = 0.0
    length_scale: float = 1.0
    platform: str = ""
    platform_origin: Array = field(default_factory=lambda: np.zeros(3), repr=False)
    limbs: tuple[LimbMobility, ...] = field(default=(), repr=False)
    view: View = View.CONFIGURATION
    method: Method = Method.LIMB_WISE
    method_note: str = ""

    @property
    def translations(self) -> int:
        """Number of free translations."""
        return sum(m.kind is MotionKind.TRANSLATION for m in self.motions)

    @property
    def rotations(self) -> int:
        """Number of free rotations (zero-pitch screws)."""
        return sum(m.kind is MotionKind.ROTATION for m in self.motions)

    @property
    def screws(self) -> int:
        """Number of free screws (finite non-zero pitch)."""
        return sum(m.kind is MotionKind.SCREW for m in self.motions)

    @property
    def serially_singular_limbs(self) -> tuple[str, ...]:
        """Names of the limbs at a serial singularity."""
        return tuple(limb.name for limb in self.limbs if limb.serially_singular)

    @property
    def rotation_centre(self) -> Array | None:
        """(3,) the world point [m] where every rotation axis meets, when there are two or more and they do.

        The least-squares point of the axes (lines ``p_i + t d_i``); None when it lies farther than
        ``1e-9 L`` from any of them, or there are fewer than two rotations. Coordinates that are round-off
        print as 0 (:func:`~pinmob.analysis.motion.point_scale`).
        """
        rotations = [m for m in self.motions if m.kind is MotionKind.ROTATION and m.point is not None]
        if len(rotations) < 2:
            return None
        points = [self.platform_origin + m.point for m in rotations if m.point is not None]
        projectors = [np.eye(3) - np.outer(m.direction, m.direction) for m in rotations]
        rhs = np.concatenate([p @ a for p, a in zip(projectors, points)])
        point = np.linalg.lstsq(np.vstack(projectors), rhs)[0]
        off = max(float(np.linalg.norm(p @ (point - a))) for p, a in zip(projectors, points))
        return (
            clean(point, point_scale(self.length_scale, self.platform_origin))
            if off <= 1e-9 * self.length_scale
            else None
        )

    @property
    def frame(self) -> str:
        """A sentence naming the frame twists and wrenches are expressed in."""
        p = ", ".join(f"{x:.6g}" for x in clean(self.platform_origin, self.length_scale))
        return (
            f"twists [v; w] and wrenches [f; tau] at the origin of frame {self.platform!r} "
            f"(world position [{p}] m), world-aligned axes (pin.LOCAL_WORLD_ALIGNED); axis points in world coordinates"
        )

    def to_dict(self) -> dict[str, Any]:
        """Plain-JSON dictionary (no NaN), keys as documented in docs/usage.md#json-pinmob-analyze---json-mobilityto_dict."""
        return {
            "mechanism": self.mechanism,
            "configuration": self.configuration,
            "view": self.view.value,
            "method": self.method.value,
            "method_note": self.method_note,
            "dof": self.dof,
            "motion_type": self.motion_type,
            "translations": self.translations,
            "rotations": self.rotations,
            "screws": self.screws,
            "motions": [m.to_dict(self.platform_origin, self.length_scale) for m in self.motions],
            "free_twists": self.free_twists.T.tolist(),
            "constraints": [c.to_dict(self.platform_origin, self.length_scale) for c in self.constraints],
            "constraint_wrenches": self.constraint_wrenches.T.tolist(),
            "constraint_rank": self.constraint_rank,
            "singular_values": vector(self.singular_values),
            "tolerance": self.tolerance,
            "length_scale": self.length_scale,
            "frame": self.frame,
            "limbs": [limb.to_dict() for limb in self.limbs],
        }

    def __str__(self) -> str:
        """Multi-line report: DoF and type, each motion, the constraints, limbs and numbers."""
        where = f" at {self.configuration!r}" if self.configuration else ""
        view = " (paper's view: generic limb wrenches carried here)" if self.view is View.PAPER else ""
        lines = [f"{self.mechanism}{where}{view}: {self.dof} DoF, {self.motion_type}"]
        origin, length = self.platform_origin, self.length_scale
        lines.extend(m.line(origin, length) for m in self.motions)
        centre = self.rotation_centre
        if centre is not None:
            lines.append(f"  the {self.rotations} rotation axes meet at {numbers(centre)} m (world)")
        lines.append(f"constraint rank {self.constraint_rank}:")
        lines.extend(c.line(origin, length) for c in self.constraints)
        if self.method_note:
            lines.append(f"method: {self.method.value} ({self.method_note})")
        lines.append("limbs:" if self.limbs else "limbs: none used")
        lines.extend(limb.line() for limb in self.limbs)
        singular = self.serially_singular_limbs
        if singular and self.view is View.CONFIGURATION:
            lines.append(
                f"note: limb(s) {', '.join(singular)} are at a serial singularity: their joint screws are dependent "
                "here, so each has more constraint wrenches than at generic configurations. A method that carries "
                "the generic limb wrenches to this configuration (as the seed paper does) misses them: see `paper=True`."
            )
        lines.append(
            f"singular values {numbers(self.singular_values, 3)}, tolerance {self.tolerance:.2e}, "
            f"L = {self.length_scale:.4g} m"
        )
        lines.append(f"frame: {self.frame}")
        return "\n".join(lines)


def mobility_from_wrenches(
    conf: Configuration,
    limb_rows: list[tuple[Array, int]],
    rtol: float,
    view: View = View.CONFIGURATION,
    *,
    method: Method = Method.LIMB_WISE,
    note: str = "",
    wrenches: Array | None = None,
) -> Mobility:
    """Stack limb wrenches (or take ``wrenches``, (6, d)), decide the constraint rank and classify both spaces.

    Args:
        conf: the closed configuration.
        limb_rows: per limb, its wrenches (6, m_i) and twist rank (empty with ``wrenches``).
        rtol: relative tolerance of every rank decision.
        view: which wrenches these are (at q, or the paper's).
        method: how they were obtained.
        note: why that method.
        wrenches: (6, d) the constraint wrenches, when not stacked from limbs.
    """
    mech = conf.mechanism
    length = mech.length_scale
    if wrenches is None:
        blocks = [w for w, _ in limb_rows]
        stacked = np.hstack(blocks) if blocks else np.zeros((6, 0))
    else:
        stacked = wrenches
    _, dec = reciprocal_twists(stacked, length, rtol)
    constraint_basis = dec.row_space.T / wrench_scaling(length)[:, None]
    keep = view is View.CONFIGURATION  # the platform frame's motion on the closed chain is the same space
    system, motions = classified_motions(conf, dec.null_space.T, rtol, keep=keep)  # the free twists' span
    cons = constraints_of(classify_wrenches(constraint_basis, length, rtol))
    sv = np.zeros(6)
    sv[: min(6, dec.singular_values.size)] = dec.singular_values[:6]
    ranks = generic_twist_ranks(mech) if limb_rows else ()
    limbs = tuple(
        LimbMobility(limb.name, limb.joints, rank, generic, w, limb.closures, limb.loop_joints)
        for limb, (w, rank), generic in zip(mech.limbs, limb_rows, ranks)
    )
    return Mobility(
        mechanism=mech.name,
        configuration=conf.name,
        dof=6 - dec.rank,
        motion_type=motion_type(system),
        motions=motions,
        free_twists=columns([m.twist for m in motions]),
        constraints=cons,
        constraint_wrenches=columns([c.wrench for c in cons]),
        constraint_rank=dec.rank,
        singular_values=sv,
        tolerance=dec.tolerance,
        length_scale=length,
        platform=mech.platform,
        platform_origin=conf.platform_origin,
        limbs=limbs,
        view=view,
        method=method,
        method_note=note,
    )


@one_blas_thread
def platform_mobility(conf: Configuration, rtol: float) -> Mobility:
    """Mobility of the platform at a closed configuration: limb-wise, or by the closure Jacobian where it must.

    Raises:
        ConfigurationError: the mechanism has no platform frame.
    """
    mech = conf.mechanism
    if not mech.has_platform:
        raise ConfigurationError(
            f"{mech.name!r} has no platform frame: the whole-mechanism analysis (report.mechanism_mobility, "
            "for the frames `frames` names) gives the motion of any frame"
        ).naming("frames")
    obstacle = limbwise_obstacle(mech)
    if not obstacle:
        return mobility_from_wrenches(conf, limb_wrenches(conf, rtol), rtol)
    free = frame_mobility_at(conf, mech.platform, rtol).free_twists
    wrenches, _ = reciprocal_wrenches(free, mech.length_scale, rtol)
    note = (
        f"{obstacle}: the limb-wise method does not apply; the platform's motion is the image of the "
        "closed chain's motions (closure Jacobian of the whole mechanism)"
    )
    return mobility_from_wrenches(
        conf, [], rtol, View.CONFIGURATION, method=Method.CLOSURE_JACOBIAN, note=note, wrenches=wrenches
    )
