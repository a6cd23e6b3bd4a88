"""Singularities at a configuration, in the classes of Zlatanov, Bonev and Gosselin (2002).

With ``T_i`` (6, n_i) the joint screws of limb i at the platform origin and
``W_i`` (6, 6 - rank T_i) the wrenches reciprocal to them (see
:mod:`pinmob.mobility`), three questions are asked, each on dimensionless
matrices (``[v / L; w]`` for twists, ``[f L; tau]`` for wrenches):

* **limb (Type I, serial) singularity**: ``rank U_i`` is below the limb's
  generic twist rank, ``U_i`` being the dimensionless joint screws with each
  column scaled to unit length (so that neither the unit of length nor the
  unit of a joint's rate, rad/s or m/s or mm/s, matters). The joints taking
  part are those with a coefficient above ``sqrt(rtol)`` in a unit vector of
  ``null(U_i)``.
* **constraint singularity**: ``d = rank [W_1 ... W_k]`` is below the
  mechanism's generic constraint rank ``g`` (declared as ``generic_rank`` in
  the mechanism file, else estimated from random closed configurations): the
  platform gains freedom. The *dependent limbs* are the limbs of the minimal
  sets S of limbs whose own stacked wrenches lost rank: ``rank [W_i, i in S]``
  below its value at generic configurations (:func:`dependent_limbs`).
* **actuation (Type II, parallel) singularity**: with the actuated joints
  locked, limb i keeps the screws ``T_i^u`` of its unactuated joints and is
  reciprocal to ``W_i^u = null((T_i^u)^T)``, which holds ``W_i`` plus one
  actuation wrench per actuated joint. The platform keeps
  ``locked_dof = 6 - rank [W_1^u ... W_k^u]`` free motions, the *uncontrolled*
  twists. A configuration is actuation-singular when ``locked_dof`` exceeds its
  generic value ``max(0, 6 - g - n_actuated)``. Without any actuated joint the
  question does not apply (``actuation`` None, no uncontrolled motion).

Distance to singularity (dimensionless, in [0, 1], unit-invariant): for each
question, ``sigma_r / sigma_1`` of the very matrix whose rank is decided, ``r``
being its generic rank: the stacked limb wrenches (r = g), the stacked
locked-limb wrenches (r = 6 - generic locked dof) and each limb's ``U_i`` (its
generic twist rank). Ranks count the singular values above ``rtol * sigma_1``,
so each class is present exactly when its distance is at most ``rtol``. A
configuration with no class present but a distance below ``NEAR_FACTOR * rtol``
is *near-singular*.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike, NDArray

from .closure import CLOSURE_TOL, closed_kinematics
from .exceptions import ConfigurationError
from .generic import (
    dependent_limbs,
    generic_constraint_rank,
    limb_decisions,
    unit_columns,
    wrench_blocks,
)
from .mechanism import Limb, Mechanism
from .mobility import Mobility, Motion, _assemble, _motions, limb_twists
from .screw import (
    RTOL,
    Array,
    RankDecision,
    classify_twists,
    decide_rank,
    reciprocal_wrenches,
    twist_scaling,
    wrench_scaling,
)

#: Near-singular band: no class present but ``distance < NEAR_FACTOR * rtol``.
NEAR_FACTOR = 1e3


@dataclass(frozen=True)
class Singularity:
    """Singularity classes and distances at one closed configuration.

    Attributes:
        mechanism, configuration: names (configuration may be None).
        constraint: constraint singularity (constraint rank below ``generic_rank``).
        actuation: actuation (Type II) singularity; None when no joint is actuated.
        limbs: names of the serially singular (Type I) limbs.
        limb_joints: per serially singular limb, the joints taking part.
        dependent_limbs: limbs of the minimal limb sets whose wrenches lost rank (constraint singularity only).
        constraint_rank, generic_rank: d here and at generic configurations.
        locked_dof: platform DoF with the actuated joints locked (the DoF when none is actuated).
        generic_locked_dof: its generic value ``max(0, 6 - generic_rank - n_actuated)``.
        uncontrolled: canonical uncontrolled motions (free motions with actuators locked; empty without actuators).
        uncontrolled_twists: (6, len(uncontrolled)) their unit twists ``[v; w]``.
        actuation_wrenches: (6, m) the actuation wrenches ``[f; tau]`` [N, N m per unit] found.
        distance: smallest of ``distances`` (dimensionless, [0, 1]).
        distances: per question (``constraint``, ``actuation``, ``limb <name>``), ``sigma_r / sigma_1``.
        limb_ranks, generic_limb_ranks: twist rank of each limb here and at generic configurations.
        constraint_singular_values: (6,) of the stacked dimensionless limb wrenches (NaN where absent).
        actuation_singular_values: (6,) of the stacked dimensionless locked-limb wrenches (NaN where absent).
        rtol: relative tolerance of the rank decisions.
    """

    mechanism: str
    configuration: str | None
    constraint: bool
    actuation: bool | None
    limbs: tuple[str, ...]
    limb_joints: dict[str, tuple[str, ...]]
    dependent_limbs: tuple[str, ...]
    constraint_rank: int
    generic_rank: int
    locked_dof: int
    generic_locked_dof: int
    uncontrolled: tuple[Motion, ...]
    uncontrolled_twists: Array = field(repr=False)
    actuation_wrenches: Array = field(repr=False)
    distance: float = 1.0
    distances: dict[str, float] = field(default_factory=dict)
    limb_ranks: dict[str, int] = field(default_factory=dict)
    generic_limb_ranks: dict[str, int] = field(default_factory=dict)
    constraint_singular_values: Array = field(default_factory=lambda: np.full(6, np.nan), repr=False)
    actuation_singular_values: Array = field(default_factory=lambda: np.full(6, np.nan), repr=False)
    rtol: float = RTOL

    @property
    def classes(self) -> tuple[str, ...]:
        """Names of the singularity classes present: ``constraint``, ``actuation``, ``limb``."""
        out = ["constraint"] if self.constraint else []
        out += ["actuation"] if self.actuation else []
        out += ["limb"] if self.limbs else []
        return tuple(out)

    @property
    def label(self) -> str:
        """``none`` or the classes joined by ``+``, e.g. ``actuation+limb``."""
        return "+".join(self.classes) or "none"

    @property
    def near_singular(self) -> bool:
        """No class present, but ``distance < NEAR_FACTOR * rtol``."""
        return not self.classes and self.distance < NEAR_FACTOR * self.rtol

    @property
    def closest(self) -> str:
        """The question with the smallest distance (``constraint``, ``actuation`` or ``limb <name>``)."""
        return min(self.distances, key=self.distances.__getitem__) if self.distances else ""

    @property
    def rank_gap(self) -> dict[str, int]:
        """Rank lost per question (``constraint``, ``actuation``, ``limb <name>``): generic minus here, at least 0."""
        gap = {
            "constraint": max(0, self.generic_rank - self.constraint_rank),
            "actuation": max(0, self.locked_dof - self.generic_locked_dof),
        }
        for name, rank in self.limb_ranks.items():
            gap[f"limb {name}"] = max(0, self.generic_limb_ranks[name] - rank)
        return gap

    def to_dict(self) -> dict[str, Any]:
        """The ``singularity`` entry of ``pinmob analyze --json``."""
        return {
            "constraint": self.constraint,
            "actuation": self.actuation,
            "limbs": list(self.limbs),
            "locked_dof": self.locked_dof,
            "uncontrolled": [m.to_dict() for m in self.uncontrolled],
            "distance": self.distance,
            "generic_rank": self.generic_rank,
            "classes": list(self.classes),
            "near_singular": self.near_singular,
            "limb_joints": {k: list(v) for k, v in self.limb_joints.items()},
            "dependent_limbs": list(self.dependent_limbs),
            "rank_gap": self.rank_gap,
            "distances": dict(self.distances),
        }


# --------------------------------------------------------------------------- helpers


def ratio(singular_values: NDArray[np.floating], rank: int) -> Array:
    """``sigma_rank / sigma_1`` (1-based) of each row of (N, m) singular values; 1 when rank is 0, 0 when m < rank."""
    s = np.atleast_2d(np.asarray(singular_values, float))
    if rank <= 0:
        return np.ones(s.shape[0])
    if s.shape[1] < rank:
        return np.zeros(s.shape[0])
    top = s[:, 0]
    return np.where(top > 0, s[:, rank - 1] / np.where(top > 0, top, 1.0), 0.0)


def _distance(singular_values: ArrayLike, rank: int) -> float:
    return float(ratio(np.asarray(singular_values, float)[None, :], rank)[0])


def _padded(values: Array) -> Array:
    out = np.full(6, np.nan)
    out[: min(6, values.size)] = values[:6]
    return out


def column_joints(mech: Mechanism, limb: Limb) -> list[str]:
    """Joint name of every velocity column of the limb."""
    out: list[str] = []
    for name in limb.joints:
        out += [name] * mech.model.joints[mech.model.getJointId(name)].nv
    return out


def require_platform(mech: Mechanism, what: str = "a singularity report") -> None:
    """Raise unless the mechanism has limbs meeting at a platform frame.

    Raises:
        ConfigurationError: no limbs or no platform frame (Extended URDF, MJCF, closures only), or a
            closure couples limbs (limb-wise classes do not apply).
    """
    if mech.coupling_closures:
        coupled = "; ".join(f"{c!r} couples limbs {', '.join(limbs)}" for c, limbs in mech.coupling_closures.items())
        raise ConfigurationError(
            f"{what} uses limb-wise singularity classes, which do not apply to {mech.name!r}: closure {coupled} "
            "(no limb has wrenches of its own); `pinmob analyze` reports its mobility from the closure Jacobian"
        )
    if not mech.limbs or not mech.has_platform:
        raise ConfigurationError(
            f"{what} needs limbs meeting at a platform frame; {mech.name!r} is described by loop closures only "
            "(Extended URDF, MJCF or a TOML file without limbs), so it has no platform to scan or classify: "
            "`pinmob analyze` reports its mobility; to scan it, write a TOML mechanism file naming its limbs and platform"
        )


def generic_locked_dof(mech: Mechanism, generic_rank: int) -> int:
    """Platform DoF with the actuators locked at a generic configuration: ``max(0, 6 - g - n_actuated)``."""
    return max(0, 6 - generic_rank - len(mech.actuated))


def _participants(unit: Array, names: list[str], rtol: float) -> tuple[str, ...]:
    """Names of the columns with a coefficient above ``sqrt(rtol)`` in a unit vector of ``null(unit)``."""
    null = decide_rank(unit, rtol).null_space  # (n - rank, n), orthonormal rows
    weight = np.max(np.abs(null), axis=0, initial=0.0)
    return tuple(dict.fromkeys(n for n, w in zip(names, weight) if w > np.sqrt(rtol)))


# --------------------------------------------------------------------------- analysis


def singularity_from_twists(
    mech: Mechanism,
    twists: list[Array],
    locked_twists: list[Array],
    decisions: list[RankDecision],
    generic_rank: int,
    *,
    configuration: str | None = None,
    rtol: float = RTOL,
) -> Singularity:
    """The report from the limbs' joint screws and :func:`limb_decisions`.

    Args:
        twists: each limb's screws, :func:`pinmob.mobility.limb_twists`.
        locked_twists: the same with the actuated joints still
            (``limb_twists(..., lock_actuated=True)``; loops inside a limb stay closed).
    """
    g = int(generic_rank)
    length = mech.length_scale
    st, sw = twist_scaling(length)[:, None], wrench_scaling(length)[:, None]
    blocks = wrench_blocks(decisions)
    distances: dict[str, float] = {}
    locked_blocks, act_wrenches = [], []
    limb_joints, limb_ranks = {}, {}
    for limb, t, t_locked, dec, w_hat in zip(mech.limbs, twists, locked_twists, decisions, blocks):
        limb_ranks[limb.name] = dec.rank
        distances[f"limb {limb.name}"] = _distance(dec.singular_values, limb.generic_twist_rank)
        if dec.rank < limb.generic_twist_rank:
            limb_joints[limb.name] = (
                _participants(unit_columns(st * t), column_joints(mech, limb), rtol)
                if not limb.closures
                else limb.joints + limb.loop_joints  # columns are loop-closing rate combinations, not joints
            )
        if limb.actuated:
            locked = decide_rank((st * t_locked).T, rtol, n=6).null_space.T
            extra = locked - w_hat @ (w_hat.T @ locked)  # actuation wrenches: outside the limb's constraint space
            basis = decide_rank(extra.T, rtol, n=6).row_space.T if extra.size else np.zeros((6, 0))
            act_wrenches.append(basis / sw)
            locked_blocks.append(locked)
        else:
            locked_blocks.append(w_hat)

    cdec = decide_rank(np.hstack(blocks).T, rtol, n=6)
    constraint = cdec.rank < g
    if g > 0:
        distances["constraint"] = _distance(cdec.singular_values, g)
    g_locked = generic_locked_dof(mech, g)
    ldec = decide_rank(np.hstack(locked_blocks).T, rtol, n=6)
    locked_dof = 6 - ldec.rank
    actuation: bool | None = None
    motions: tuple[Motion, ...] = ()
    if mech.actuated:
        actuation = locked_dof > g_locked
        distances["actuation"] = _distance(ldec.singular_values, 6 - g_locked)
        if locked_dof:
            motions = _motions(classify_twists(ldec.null_space.T / st, length, rtol))
    return Singularity(
        mechanism=mech.name,
        configuration=configuration,
        constraint=bool(constraint),
        actuation=actuation,
        limbs=tuple(limb_joints),
        limb_joints=limb_joints,
        dependent_limbs=dependent_limbs(mech, blocks, rtol, g) if constraint else (),
        constraint_rank=cdec.rank,
        generic_rank=g,
        locked_dof=locked_dof,
        generic_locked_dof=g_locked,
        uncontrolled=motions,
        uncontrolled_twists=np.column_stack([m.twist for m in motions]) if motions else np.zeros((6, 0)),
        actuation_wrenches=np.hstack(act_wrenches) if act_wrenches else np.zeros((6, 0)),
        distance=min(distances.values(), default=1.0),
        distances=distances,
        limb_ranks=limb_ranks,
        generic_limb_ranks={limb.name: limb.generic_twist_rank for limb in mech.limbs},
        constraint_singular_values=_padded(cdec.singular_values),
        actuation_singular_values=_padded(ldec.singular_values),
        rtol=rtol,
    )


def analyze_singularity(
    mech: Mechanism,
    q: Array | str,
    *,
    configuration: str | None = None,
    generic_rank: int | None = None,
    rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL,
) -> Singularity:
    """Singularity classes, uncontrolled motions and distances at a closed configuration.

    Args:
        mech: the mechanism.
        q: configuration (nq,), or the name of one of ``mech.configurations``.
        configuration: name reported with the result.
        generic_rank: generic constraint rank; default :func:`generic_constraint_rank`.
        rtol: relative tolerance of every rank decision.
        closure_tol: closure tolerance (position / L and rotation [rad]).

    Raises:
        ConfigurationError: the mechanism has no limbs or no platform frame.
        ClosureError: q does not close the loops.
    """
    require_platform(mech)
    q, configuration = mech.resolve(q, configuration)
    g = generic_constraint_rank(mech, rtol=rtol) if generic_rank is None else int(generic_rank)
    data = closed_kinematics(mech, q, closure_tol)
    twists, locked = limb_twists(mech, data, rtol), limb_twists(mech, data, rtol, lock_actuated=True)
    return singularity_from_twists(
        mech, twists, locked, limb_decisions(mech, twists, rtol), g, configuration=configuration, rtol=rtol
    )


def analyze_both(
    mech: Mechanism, data: pin.Data, generic_rank: int, *, rtol: float = RTOL, configuration: str | None = None
) -> tuple[Mobility, Singularity]:
    """Mobility (as :func:`pinmob.analyze`) and singularity report from one kinematics computation.

    Args:
        data: kinematics computed at a closed configuration (:func:`pinmob.closure.compute_kinematics`).
    """
    twists, locked = limb_twists(mech, data, rtol), limb_twists(mech, data, rtol, lock_actuated=True)
    rows = [reciprocal_wrenches(t, mech.length_scale, rtol) for t in twists]
    origin = data.oMf[mech.platform_id].translation
    mob = _assemble(mech, configuration, [(w, dec.rank) for w, dec in rows], origin, rtol, "configuration")
    decisions = limb_decisions(mech, twists, rtol)
    sing = singularity_from_twists(
        mech, twists, locked, decisions, generic_rank, configuration=configuration, rtol=rtol
    )
    return mob, sing


def format_singularity(sing: Singularity) -> str:
    """The singularity section of the text report."""
    near = f"; near-singular (below {NEAR_FACTOR * sing.rtol:.0e})" if sing.near_singular else ""
    lines = [f"singularity: {sing.label} (distance {sing.distance:.3g}; 0 = singular, 1 = best conditioned{near})"]
    gap = sing.rank_gap
    lines.append(
        f"  constraint: {'SINGULAR' if sing.constraint else 'no'} (rank {sing.constraint_rank}, generic {sing.generic_rank}"
        + (
            f", lost {gap['constraint']}; dependent limbs {', '.join(sing.dependent_limbs) or '-'}"
            if sing.constraint
            else ""
        )
        + ")"
    )
    if sing.actuation is None:
        lines.append("  actuation (Type II): not applicable (no actuated joint declared)")
    else:
        unc = ", ".join(m.label for m in sing.uncontrolled) or "none"
        lines.append(
            f"  actuation (Type II): {'SINGULAR' if sing.actuation else 'no'} (actuators locked: {sing.locked_dof} DoF "
            f"left, generic {sing.generic_locked_dof}; uncontrolled: {unc})"
        )
    if sing.limbs:
        for name in sing.limbs:
            lines.append(
                f"  limb (Type I): {name} SINGULAR (rank {sing.limb_ranks[name]}, generic "
                f"{sing.generic_limb_ranks[name]}; joints {', '.join(sing.limb_joints[name])})"
            )
    else:
        lines.append("  limb (Type I): no")
    lines.append("  distances: " + ", ".join(f"{k} {v:.3g}" for k, v in sing.distances.items()))
    return "\n".join(lines)
