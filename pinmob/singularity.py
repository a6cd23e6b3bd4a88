"""Singularities at a configuration, in the classes of Zlatanov, Bonev and Gosselin (2002).

With ``T_i`` (6, n_i) the joint screws of limb i at the platform origin and
``W_i`` (6, 6 - rank T_i) the wrenches reciprocal to them (see
:mod:`pinmob.mobility`), three questions are asked, each on dimensionless
matrices (``[v / L; w]`` for twists, ``[f L; tau]`` for wrenches):

* **limb (Type I, serial) singularity**: ``rank T_i`` is below the limb's
  generic twist rank. The joints taking part are those with a non-zero
  coefficient in ``null(T_i)`` (columns normalised).
* **constraint singularity**: ``d = rank [W_1 ... W_k]`` is below the
  mechanism's generic constraint rank ``g`` (declared as ``generic_rank`` in
  the mechanism file, else estimated from random closed configurations): the
  platform gains freedom. The limbs whose wrenches became dependent are those
  with a non-zero block in ``null([W_1 ... W_k])``.
* **actuation (Type II, parallel) singularity**: with the actuated joints
  locked, limb i keeps the screws ``T_i^u`` of its unactuated joints and is
  reciprocal to ``W_i^u = null((T_i^u)^T)``, which holds ``W_i`` plus one
  actuation wrench per actuated joint (the wrench reciprocal to every other
  joint screw of the limb but not to the actuated one). The platform keeps
  ``locked_dof = 6 - rank [W_1^u ... W_k^u]`` free motions, the *uncontrolled*
  twists. A configuration is actuation-singular when ``locked_dof`` exceeds its
  generic value ``max(0, 6 - g - n_actuated)``.

Distance to singularity (dimensionless, in [0, 1], unit-invariant): for each
question, the ratio ``sigma_r / sigma_1`` of the relevant matrix, ``r`` being
its generic rank: stacked limb wrenches (rank g), stacked locked-limb wrenches
(rank 6 - generic locked dof), and each limb's joint screws with columns
normalised to unit length (its generic twist rank). Wrench bases are
orthonormal per limb, so these values do not depend on the bases chosen. The
reported ``distance`` is the smallest of them; 0 means singular, 1 means the
matrix is as well conditioned as it can be.
"""

from __future__ import annotations

import weakref
from collections import Counter
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from .closure import CLOSURE_TOL, assemble_joints, closed_kinematics
from .exceptions import PinmobError
from .mechanism import Mechanism
from .mobility import Motion, _motions, analyze, limb_twists
from .screw import RTOL, Array, classify_twists, decide_rank, twist_scaling, wrench_scaling

#: Coefficient (relative to the largest) above which a joint or limb takes part in a dependency.
PARTICIPATION = 1e-6**0.5

_GENERIC: dict[int, tuple[weakref.ref, int]] = {}


@dataclass(frozen=True)
class Singularity:
    """Singularity classes and distances at one closed configuration.

    Attributes:
        mechanism, configuration: names (configuration may be None).
        constraint: constraint singularity (constraint rank below ``generic_rank``).
        actuation: actuation (Type II) singularity; None when no joint is actuated.
        limbs: names of the serially singular (Type I) limbs.
        limb_joints: per serially singular limb, the joints taking part.
        dependent_limbs: limbs whose wrenches became dependent (constraint singularity only).
        constraint_rank, generic_rank: d here and at generic configurations.
        locked_dof: platform DoF with the actuated joints locked.
        generic_locked_dof: its generic value ``max(0, 6 - generic_rank - n_actuated)``.
        uncontrolled: canonical uncontrolled motions (the free motions with actuators locked).
        uncontrolled_twists: (6, locked_dof) their unit twists ``[v; w]``.
        actuation_wrenches: (6, m) the actuation wrenches ``[f; tau]`` [N, N m per unit] found.
        distance: smallest of ``distances`` (dimensionless, [0, 1]).
        distances: per question (``constraint``, ``actuation``, ``limb <name>``), ``sigma_r / sigma_1``.
        constraint_singular_values: (6,) of the stacked dimensionless limb wrenches (zero-padded).
        actuation_singular_values: (6,) of the stacked dimensionless locked-limb wrenches.
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
    constraint_singular_values: Array = field(default_factory=lambda: np.zeros(6), repr=False)
    actuation_singular_values: Array = field(default_factory=lambda: np.zeros(6), repr=False)

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
    def rank_gap(self) -> dict[str, int]:
        """Rank lost per question: generic rank minus rank here (0 when not singular)."""
        return {
            "constraint": max(0, self.generic_rank - self.constraint_rank),
            "actuation": max(0, self.locked_dof - self.generic_locked_dof),
        }

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
            "limb_joints": {k: list(v) for k, v in self.limb_joints.items()},
            "dependent_limbs": list(self.dependent_limbs),
            "rank_gap": self.rank_gap,
            "distances": dict(self.distances),
        }


# --------------------------------------------------------------------------- helpers


def _padded(values: Array) -> Array:
    out = np.zeros(6)
    out[: min(6, values.size)] = values[:6]
    return out


def _ratio(singular_values: ArrayLike, rank: int) -> float:
    """``sigma_rank / sigma_1`` (1-based); 1 when rank is 0 (nothing to lose)."""
    if rank <= 0:
        return 1.0
    s = np.asarray(singular_values, float)
    if s.size < rank or s[0] <= 0:
        return 0.0
    return float(s[rank - 1] / s[0])


def _participants(matrix: Array, groups: list[tuple[str, slice]], rtol: float) -> tuple[str, ...]:
    """Groups of columns with a coefficient in the null space of ``matrix`` (columns normalised)."""
    if matrix.shape[1] == 0:
        return ()
    norms = np.linalg.norm(matrix, axis=0)
    scaled = matrix / np.where(norms > 0, norms, 1.0)
    null = decide_rank(scaled, rtol).null_space  # (n - rank, n)
    if null.shape[0] == 0:
        return ()
    weight = np.max(np.abs(null), axis=0)
    return tuple(name for name, cols in groups if np.max(weight[cols], initial=0.0) > PARTICIPATION)


def _column_names(mech: Mechanism, joints: tuple[str, ...]) -> list[str]:
    names = []
    for j in joints:
        names += [j] * mech.model.joints[mech.model.getJointId(j)].nv
    return names


def generic_locked_dof(mech: Mechanism, generic_rank: int) -> int:
    """Platform DoF with the actuators locked at a generic configuration: ``max(0, 6 - g - n_actuated)``."""
    return max(0, 6 - generic_rank - len(mech.actuated))


# --------------------------------------------------------------------------- generic rank


def generic_constraint_rank(mech: Mechanism, samples: int = 4, seed: int = 0, rtol: float = RTOL) -> int:
    """The mechanism's constraint rank at generic configurations.

    The declared ``generic_rank`` when the mechanism file has one; otherwise the
    most frequent constraint rank (ties: the larger) over random closed
    configurations near each named configuration: joints perturbed by
    ``N(0, 0.05)`` [rad, or L x 0.05 m for prismatic joints] and closed again
    by :func:`pinmob.closure.assemble_joints`. These ranks are decided with the
    looser tolerance ``sqrt(rtol)``: a mechanism whose whole workspace is
    singular (3-PUU-flat) closes a hair's breadth off its singular manifold
    (closure holds to second order there), and the tight tolerance would see
    the hair. Cached per mechanism object.

    Raises:
        PinmobError: no closed configuration could be built.
    """
    if mech.generic_rank is not None:
        return mech.generic_rank
    cached = _GENERIC.get(id(mech))
    if cached is not None and cached[0]() is mech:
        return cached[1]
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
    counts = Counter(analyze(mech, q, rtol=float(np.sqrt(rtol))).constraint_rank for q in closed)
    rank = max(counts, key=lambda r: (counts[r], r))
    _GENERIC[id(mech)] = (weakref.ref(mech), rank)
    return rank


# --------------------------------------------------------------------------- analysis


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
        ClosureError: q does not close the loops.
    """
    q, configuration = mech.resolve(q, configuration)
    g = generic_constraint_rank(mech, rtol=rtol) if generic_rank is None else int(generic_rank)
    length = mech.length_scale
    st, sw = twist_scaling(length)[:, None], wrench_scaling(length)[:, None]
    data = closed_kinematics(mech, q, closure_tol)
    twists = limb_twists(mech, data)
    locked_twists = limb_twists(mech, data, rtol, lock_actuated=True)

    distances: dict[str, float] = {}
    wrench_blocks, locked_blocks, groups, act_wrenches = [], [], [], []
    singular_limbs, limb_joints = [], {}
    col = 0
    for i, (limb, t) in enumerate(zip(mech.limbs, twists)):
        dec = decide_rank((st * t).T, rtol, n=6)
        w_hat = dec.null_space.T  # (6, 6 - r) dimensionless, orthonormal
        wrench_blocks.append(w_hat)
        groups.append((limb.name, slice(col, col + w_hat.shape[1])))
        col += w_hat.shape[1]
        unit_cols = st * t / np.where(np.linalg.norm(st * t, axis=0) > 0, np.linalg.norm(st * t, axis=0), 1.0)
        distances[f"limb {limb.name}"] = _ratio(np.linalg.svd(unit_cols, compute_uv=False), limb.generic_twist_rank)
        if dec.rank < limb.generic_twist_rank:
            singular_limbs.append(limb.name)
            names = _column_names(mech, limb.joints)
            limb_joints[limb.name] = (
                _participants(st * t, [(n, slice(k, k + 1)) for k, n in enumerate(names)], rtol)
                if not limb.closures
                else limb.joints + limb.loop_joints  # columns are loop-closing rate combinations, not joints
            )
        if limb.actuated:
            locked = decide_rank((st * locked_twists[i]).T, rtol, n=6).null_space.T
            extra = locked - w_hat @ (w_hat.T @ locked)  # actuation wrenches: outside the limb's constraint space
            basis = decide_rank(extra.T, rtol, n=6).row_space.T if extra.size else np.zeros((6, 0))
            act_wrenches.append(basis / sw)
            locked_blocks.append(locked)
        else:
            locked_blocks.append(w_hat)

    stacked = np.hstack(wrench_blocks)
    cdec = decide_rank(stacked.T, rtol, n=6)
    constraint = cdec.rank < g
    if g > 0:
        distances["constraint"] = _ratio(cdec.singular_values, g)
    dependent = _participants(stacked, groups, rtol) if constraint else ()

    g_locked = generic_locked_dof(mech, g)
    ldec = decide_rank(np.hstack(locked_blocks).T, rtol, n=6)
    locked_dof = 6 - ldec.rank
    actuation: bool | None = None
    if mech.actuated:
        actuation = locked_dof > g_locked
        distances["actuation"] = _ratio(ldec.singular_values, 6 - g_locked)
    free = ldec.null_space.T / st
    motions = _motions(classify_twists(free, length, rtol)) if locked_dof else ()
    return Singularity(
        mechanism=mech.name,
        configuration=configuration,
        constraint=bool(constraint),
        actuation=actuation,
        limbs=tuple(singular_limbs),
        limb_joints=limb_joints,
        dependent_limbs=dependent,
        constraint_rank=cdec.rank,
        generic_rank=g,
        locked_dof=locked_dof,
        generic_locked_dof=g_locked,
        uncontrolled=motions,
        uncontrolled_twists=np.column_stack([m.twist for m in motions]) if motions else np.zeros((6, 0)),
        actuation_wrenches=np.hstack(act_wrenches) if act_wrenches else np.zeros((6, 0)),
        distance=min(distances.values(), default=1.0),
        distances=distances,
        constraint_singular_values=_padded(cdec.singular_values),
        actuation_singular_values=_padded(ldec.singular_values),
    )


def format_singularity(sing: Singularity) -> str:
    """The singularity section of the text report."""
    lines = [f"singularity: {sing.label} (distance {sing.distance:.3g}; 0 = singular, 1 = best conditioned)"]
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
        lines.append("  actuation (Type II): no actuated joint declared")
    else:
        unc = ", ".join(m.label for m in sing.uncontrolled) or "none"
        lines.append(
            f"  actuation (Type II): {'SINGULAR' if sing.actuation else 'no'} (actuators locked: {sing.locked_dof} DoF "
            f"left, generic {sing.generic_locked_dof}; uncontrolled: {unc})"
        )
    if sing.limbs:
        for name in sing.limbs:
            lines.append(f"  limb (Type I): {name} SINGULAR (joints {', '.join(sing.limb_joints[name])})")
    else:
        lines.append("  limb (Type I): no")
    lines.append("  distances: " + ", ".join(f"{k} {v:.3g}" for k, v in sing.distances.items()))
    return "\n".join(lines)
