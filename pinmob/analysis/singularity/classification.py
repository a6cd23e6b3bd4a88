"""The singularity classes at a configuration, computed from the limbs' joint screws (see :mod:`pinmob.analysis.singularity.result`)."""

from __future__ import annotations

import numpy as np

from pinmob.analysis.configuration import Configuration
from pinmob.analysis.generic import dependent_limbs, generic_constraint_rank, generic_twist_ranks
from pinmob.analysis.limbs import column_joints, limb_decisions, limb_twists, unit_columns, wrench_blocks
from pinmob.analysis.motion import Motion, columns, motions_of
from pinmob.analysis.singularity.result import Singularity, distance_of, generic_locked_dof, padded
from pinmob.blas import one_blas_thread
from pinmob.exceptions import ConfigurationError
from pinmob.model import Mechanism
from pinmob.screw import (
    RTOL,
    Array,
    RankDecision,
    classify_twists,
    decide_rank,
    decide_ranks,
    twist_scaling,
    wrench_scaling,
)


def require_platform(
    mech: Mechanism,
    what: str = "a singularity report",
    analysis: str = "pinmob.analyze",
    path_scan: str = "a joint path scan (pinmob.scan.path_spec)",
) -> None:
    """Raise unless the mechanism has limbs meeting at a platform frame.

    ``what`` needs the platform; the message advises ``analysis`` and ``path_scan`` instead (the command line
    names its commands).

    Raises:
        ConfigurationError: no limbs or no platform frame (Extended URDF, MJCF, closures only), or a
            closure couples limbs (limb-wise classes do not apply).
    """
    if mech.coupling_closures:
        coupled = "; ".join(f"{c!r} couples limbs {', '.join(limbs)}" for c, limbs in mech.coupling_closures.items())
        raise ConfigurationError(
            f"{what} uses limb-wise singularity classes, which do not apply to {mech.name!r}: closure {coupled} "
            f"(no limb has wrenches of its own); {analysis} reports its mobility from the closure Jacobian"
        )
    if not mech.limbs or not mech.has_platform:
        raise ConfigurationError(
            f"{what} needs limbs meeting at a platform frame; {mech.name!r} is described by loop closures only "
            "(Extended URDF, MJCF or a TOML file without limbs), so it has no platform to scan or classify: "
            f"{analysis} reports its mobility and {path_scan} scans the whole closed chain along a path in its "
            "actuated joints; a platform scan needs a TOML mechanism file naming its limbs and platform"
        )


def _participants(unit: Array, names: list[str], rtol: float) -> tuple[str, ...]:
    """Names of the columns with a coefficient above ``sqrt(rtol)`` in a unit vector of ``null(unit)``."""
    null = decide_rank(unit, rtol).null_space  # (n - rank, n), orthonormal rows
    weight = np.max(np.abs(null), axis=0, initial=0.0)
    return tuple(dict.fromkeys(n for n, w in zip(names, weight) if w > np.sqrt(rtol)))


def singularity_from_twists(
    mech: Mechanism,
    twists: tuple[Array, ...] | list[Array],
    locked_twists: tuple[Array, ...] | list[Array],
    decisions: list[RankDecision],
    generic_rank: int,
    *,
    configuration: str | None = None,
    rtol: float = RTOL,
) -> Singularity:
    """The report from the limbs' joint screws and :func:`limb_decisions`.

    Args:
        mech: the mechanism.
        twists: each limb's screws, :func:`pinmob.analysis.limbs.limb_twists`.
        locked_twists: the same with the actuated joints still
            (``limb_twists(..., lock_actuated=True)``; loops inside a limb stay closed).
        decisions: :func:`pinmob.analysis.limbs.limb_decisions` of ``twists``.
        generic_rank: the generic constraint rank.
        configuration: name reported with the result.
        rtol: relative tolerance of every rank decision.
    """
    g = int(generic_rank)
    length = mech.length_scale
    st, sw = twist_scaling(length)[:, None], wrench_scaling(length)[:, None]
    blocks = wrench_blocks(decisions)
    generic_ranks = generic_twist_ranks(mech)
    distances: dict[str, float] = {}
    limb_joints, limb_ranks = {}, {}
    for limb, generic, t, dec in zip(mech.limbs, generic_ranks, twists, decisions):
        limb_ranks[limb.name] = dec.rank
        distances[f"limb {limb.name}"] = distance_of(dec.singular_values, generic)
        if dec.rank < generic:
            limb_joints[limb.name] = (
                _participants(unit_columns(st * t), column_joints(mech, limb), rtol)
                if not limb.closures
                else limb.joints + limb.loop_joints  # columns are loop-closing rate combinations, not joints
            )
    # actuated limbs: the wrenches reciprocal to the unactuated screws, and those outside the limb's constraint space
    acting = [i for i, limb in enumerate(mech.limbs) if mech.limb_actuators(limb)]
    locked_decisions = decide_ranks([(st * locked_twists[i]).T for i in acting], rtol, n=6)
    locked_blocks = list(blocks)
    extras = []
    for i, ldec in zip(acting, locked_decisions):
        locked = locked_blocks[i] = ldec.null_space.T
        extras.append(locked - blocks[i] @ (blocks[i].T @ locked))  # actuation wrenches: outside the limb's own
    act_wrenches = [
        dec.row_space.T / sw if extra.size else np.zeros((6, 0))
        for extra, dec in zip(extras, decide_ranks([e.T for e in extras], rtol, n=6, at_least=1.0))
    ]

    cdec = decide_rank(np.concatenate(blocks, axis=1).T, rtol, n=6)
    constraint = cdec.rank < g
    if g > 0:
        distances["constraint"] = distance_of(cdec.singular_values, g)
    g_locked = generic_locked_dof(mech, g)
    ldec = decide_rank(np.concatenate(locked_blocks, axis=1).T, rtol, n=6)
    locked_dof = 6 - ldec.rank
    actuation: bool | None = None
    motions: tuple[Motion, ...] = ()
    if mech.actuated:
        actuation = locked_dof > g_locked
        distances["actuation"] = distance_of(ldec.singular_values, 6 - g_locked)
        if locked_dof:
            motions = motions_of(classify_twists(ldec.null_space.T / st, length, rtol))
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
        uncontrolled_twists=columns([m.twist for m in motions]),
        actuation_wrenches=np.concatenate(act_wrenches, axis=1) if act_wrenches else np.zeros((6, 0)),
        distance=min(distances.values(), default=1.0),
        distances=distances,
        limb_ranks=limb_ranks,
        generic_limb_ranks={limb.name: g for limb, g in zip(mech.limbs, generic_ranks)},
        constraint_singular_values=padded(cdec.singular_values),
        actuation_singular_values=padded(ldec.singular_values),
        rtol=rtol,
    )


@one_blas_thread
def singularity(conf: Configuration, rtol: float, generic_rank: int | None = None) -> Singularity:
    """Singularity classes, uncontrolled motions and distances at a closed configuration (cached per tolerance).

    Args:
        conf: the closed configuration.
        rtol: relative tolerance of every rank decision.
        generic_rank: generic constraint rank; default :func:`generic_constraint_rank`
            (estimated once per mechanism from random closed configurations, unless declared).

    Raises:
        ConfigurationError: the mechanism has no limbs or no platform frame, or a closure couples limbs.
    """
    mech = conf.mechanism
    require_platform(mech)

    def compute() -> Singularity:
        g = generic_constraint_rank(mech, rtol=rtol) if generic_rank is None else int(generic_rank)
        twists, locked = limb_twists(conf, rtol), limb_twists(conf, rtol, lock_actuated=True)
        return singularity_from_twists(
            mech, twists, locked, limb_decisions(mech, twists, rtol), g, configuration=conf.name, rtol=rtol
        )

    return conf.memo(("singularity", rtol, generic_rank), compute)
