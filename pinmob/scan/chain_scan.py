"""Scans of a mechanism without a platform: a path in its actuated joints, the whole closed chain per sample.

A *joint path* runs from a start to an end configuration, each a named
configuration or joint values ``name=value,...`` (the others solved to close the
loops, :func:`pinmob.assembly.named_assembly.close_joint_values`). The actuated joints
are interpolated, ``a(s) = (1 - s) a_A + s a_B``, and the other joints re-closed
at each sample from the previous one (forward kinematics,
:func:`pinmob.assembly.assemble.assemble_joints`), as for a platform
mechanism's joint path. Each row is the whole-mechanism answer
(:func:`pinmob.analysis.chain.mechanism_mobility.mechanism_mobility`): mechanism DoF
``m = nv - rank K``, closure rank, redundant closure equations, idle motions,
and the actuation verdict.

Classes and distances (dimensionless, in [0, 1], unit-invariant), each from the
matrix whose rank the analysis decides:

* ``closure``: the closure rank is below its generic value ``g``
  (:func:`generic_closure_rank`): the mechanism gains DoF. Distance
  ``sigma_g / sigma_1`` of the dimensionless closure Jacobian ``K_hat``;
* ``actuation``: with the actuated joints locked, motions that are not idle
  remain (``locked_dof > idle_dof``). Distance ``sigma_r / max(1, sigma_1)``,
  ``r = m - idle_dof``, of ``S N``: the held joints' rates (rows) on an
  orthonormal basis ``N`` of the closed chain's dimensionless motions; its
  rank is decided against ``rtol * max(1, sigma_1)``, and the remaining
  motions are not all idle exactly when that rank is below ``r`` (0 when fewer
  joints are held than ``r``).

The CSV's ``sv1..sv6`` are the six largest singular values of ``K_hat``,
``av1..av6`` those of ``S N`` (NaN where absent).
"""

from __future__ import annotations

import functools
import warnings
from collections import Counter
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.analysis import (
    NEAR_FACTOR,
    Configuration,
    closed_chain,
    distance_of,
    generic_configurations,
    generic_constraint_rank,
    mechanism_mobility,
    padded,
)
from pinmob.assembly import close_joint_values, closed_configuration, named_vector
from pinmob.exceptions import ClosureError, ConfigurationError, PinmobError
from pinmob.model import CLOSURE_TOL, Mechanism, has_joint, joint_value, parse_joint_values
from pinmob.name_matching import choices
from pinmob.screw import RTOL, Array

SV_COLUMNS = [f"sv{i}" for i in range(1, 7)] + [f"av{i}" for i in range(1, 7)]
#: The whole-mechanism columns of a joint path's rows, after ``index``, ``s``, ``refined`` and the joint values.
CHAIN_COLUMNS = ["reachable", "reason", "dof", "closure_rank", "closure_rows", "redundant_constraints", "idle_dof",
                 "locked_dof", "redundant_actuators", "actuation_valid", "singularity", "near_singular", "closest",
                 "uncontrolled", "distance", *SV_COLUMNS]  # fmt: skip


def value_columns(joints: tuple[str, ...] | list[str]) -> list[str]:
    """The columns of joint values [rad or m, MuJoCo's ``qpos`` for MJCF files]: ``q_<name>``."""
    return [f"q_{name}" for name in joints]


def value_joints(mech: Mechanism) -> tuple[str, ...]:
    """The joints whose values a closed chain's rows give.

    The actuated ones, then every other one-degree joint (prismatic, revolute, continuous).
    """
    model = mech.model
    single = [model.names[j] for j in range(1, model.njoints) if model.joints[j].nv == 1]
    return tuple(mech.actuated) + tuple(n for n in single if n not in mech.actuated)


def joint_row(
    mech: Mechanism, joints: tuple[str, ...], q: Array | None, targets: dict[str, float] | None = None
) -> dict[str, float]:
    """``{q_<name>: value}`` of one-degree joints at q [m or rad] (NaN: not assembled).

    A continuous joint's angle is in (-pi, pi], or the turn nearest its value in ``targets`` (the values a
    joint path asked for: its rows then read them, not their angles).
    """
    columns, where = joint_coordinates(mech.model, tuple(joints), mech.model.nq)
    if q is None:
        return dict.fromkeys(columns, float("nan"))
    if where is not None:  # one coordinate each: its value (joint_value's rule for them), read at once
        return dict(zip(columns, np.asarray(q, float)[list(where)].tolist()))
    near = targets or {}
    return {f"q_{n}": joint_value(mech.model, q, n, near.get(n)) for n in joints}


@functools.lru_cache(maxsize=64)
def joint_coordinates(
    model: pin.Model, joints: tuple[str, ...], nq: int
) -> tuple[tuple[str, ...], tuple[int, ...] | None]:
    """The joints' columns, and the coordinate in q of each joint when each has exactly one (None: not so).

    Cached per model, joints and size.
    """
    columns, out = tuple(value_columns(joints)), []
    for name in joints:
        if not has_joint(model, name) or model.joints[model.getJointId(name)].nq != 1:
            return columns, None
        out.append(int(model.joints[model.getJointId(name)].idx_q))
    return columns, tuple(out)


def end_values(mech: Mechanism, joints: tuple[str, ...], text: str, q: Array) -> Array:
    """The values of ``joints`` at a path end [m or rad], the ends of a joint path's interpolation.

    Those the end gives (``name=value,...``), as given, else read from its closed configuration q
    (:func:`~pinmob.model.joint_values.joint_value`: a continuous joint's angle, not its stored cosine); a
    continuous joint given 4 rad is interpolated towards 4, not -2.28.
    """
    given = parse_joint_values(text, "path end") if "=" in text else {}
    return np.array([given[n] if n in given else joint_value(mech.model, q, n) for n in joints], float)


def check_actuated(mech: Mechanism) -> tuple[str, ...]:
    """The actuated joints a joint path interpolates.

    Raises:
        ConfigurationError: none is declared (one line saying how to give them).
    """
    if not mech.actuated:
        tendons = [t.name for t in mech.actuated_tendons]
        kinds = ", ".join(sorted({t.kind for t in mech.actuated_tendons}))
        why = f" (its actuator(s) {', '.join(tendons)} drive {kinds}, not joints)" if tendons else ""
        raise ConfigurationError(
            f"{mech.name!r} declares no actuated joint{why}, and a joint path interpolates the actuated joints: "
            "name them with `actuated=a,b,...` (pinmob.model.actuated_joints.with_actuated in Python)"
        ).naming("actuated")
    return mech.actuated


def path_end(mech: Mechanism, text: str, seed: Array | None = None, closure_tol: float = CLOSURE_TOL) -> Array:
    """A closed configuration at a path end: a configuration name, or joint values ``name=value,...``.

    Joint values keep the other joints of ``seed`` (else of the first named configuration, else neutral) and,
    when that does not close, solve them with the given ones held.

    Raises:
        ConfigurationError: neither a configuration name nor joint values (the message lists the names).
        FrameError: a joint that does not exist (the message lists them).
        ClosureError: the configuration or the values do not close.
    """
    if "=" not in text:
        if not any(text.casefold() == n.casefold() for n in mech.configurations):
            names = choices(mech.configurations) if mech.configurations else "it has none"
            pose = "" if mech.has_platform else f" (a platform pose needs a platform frame; {mech.name!r} has none)"
            raise ConfigurationError(
                f"{text!r} is neither a configuration of {mech.name!r} ({names}) "
                f"nor joint values name=value,... [rad or m] of a joint path{pose}"
            )
        return closed_configuration(mech, text, closure_tol)
    values = parse_joint_values(text, "path end")
    if seed is None and mech.configurations:
        seed = named_vector(mech, next(iter(mech.configurations)), closure_tol)[0]
    try:
        return close_joint_values(mech, values, seed, closure_tol)[0]
    except ClosureError as exc:
        raise ClosureError(
            f"path end {text!r}: these joint values do not close the loops: {exc}", exc.residuals
        ) from None


def joint_path_ends(
    mech: Mechanism, start: str, end: str, rtol: float = RTOL, closure_tol: float = CLOSURE_TOL
) -> tuple[tuple[str, ...], Array, Array, int]:
    """A joint path's actuated joints, closed ends (:func:`path_end`; the end seeded at the start) and generic rank.

    A warning names the actuators on tendons and sites: the path moves the actuated joints, not what they drive.

    The generic rank is the platform's generic constraint rank, or for a mechanism without a platform the
    generic closure rank (:func:`generic_closure_rank`).

    Raises:
        PinmobError: no actuated joint, an end that is neither a configuration nor joint values, or that does not close.
    """
    acts = check_actuated(mech)
    if mech.actuated_tendons:
        kinds = "/".join(sorted({t.kind for t in mech.actuated_tendons}))
        warnings.warn(
            f"{mech.name!r}: a joint path interpolates the actuated joints only; {kinds} actuator(s) "
            f"{', '.join(t.name for t in mech.actuated_tendons)} are not held along it (each sample's verdict holds them)",
            stacklevel=2,
        )
    qa = path_end(mech, start, None, closure_tol)
    qb = path_end(mech, end, qa, closure_tol)
    if mech.has_platform:
        return acts, qa, qb, generic_constraint_rank(mech, rtol=rtol)
    return acts, qa, qb, generic_closure_rank(mech, (qa, qb), rtol, closure_tol)


def generic_closure_rank(
    mech: Mechanism, ends: tuple[Array, ...], rtol: float = RTOL, closure_tol: float = CLOSURE_TOL
) -> int:
    """The closure rank at generic configurations.

    The most frequent rank (ties: the larger) of ``K_hat`` over the random closed configurations near the named
    ones (:func:`pinmob.analysis.generic.generic_configurations`, the same the platform's generic ranks use),
    decided with the looser tolerance ``sqrt(rtol)`` as there; when none can be built, the larger rank at ``ends``
    (closed within ``closure_tol``).
    """
    loose = float(np.sqrt(rtol))
    try:
        qs = generic_configurations(mech)
    except PinmobError:
        return max(closed_chain(Configuration(mech, q, closure_tol=closure_tol), loose).decision.rank for q in ends)
    counts = Counter(closed_chain(Configuration(mech, q), loose).decision.rank for q in qs)
    return max(counts, key=lambda r: (counts[r], r))


def evaluate_chain(
    mech: Mechanism, q: Array, rtol: float, generic_rank: int, closure_tol: float = CLOSURE_TOL
) -> tuple[dict[str, Any], dict[str, float]]:
    """The whole-mechanism row at a closed configuration, and the distance of each question (module docstring).

    With ``closure_tol`` above the default, as :func:`pinmob.analyze` at that tolerance: the rank tolerance is at
    least 10 x q's closure residual, and the row adds ``residual`` and ``rank_rtol``.
    """
    conf = Configuration(mech, q, closure_tol=closure_tol)
    cad = closure_tol > CLOSURE_TOL
    rtol = conf.rank_rtol(rtol) if cad else rtol
    mm = mechanism_mobility(conf, rtol)
    act = mm.actuation
    free = mm.mechanism_dof - act.idle_dof
    distances = {"closure": distance_of(mm.singular_values, generic_rank)}
    actuated = bool(act.actuated or act.tendons)
    if actuated:
        distances["actuation"] = _actuation_distance(np.asarray(act.rate_singular_values, float), free)
    labels = [k for k, bad in (("closure", mm.rank < generic_rank), ("actuation", act.locked_dof > act.idle_dof))
              if bad and k in distances]  # fmt: skip
    distance = min(distances.values())
    row: dict[str, Any] = {
        "reachable": True,
        "reason": "",
        "dof": mm.mechanism_dof,
        "closure_rank": mm.rank,
        "closure_rows": mm.rows,
        "redundant_constraints": mm.redundant_constraints,
        "idle_dof": mm.idle_dof,
        "locked_dof": act.locked_dof if actuated else -1,
        "redundant_actuators": act.redundant_actuators,
        "actuation_valid": act.valid if actuated else "",
        "singularity": ", ".join(labels) or "none",
        "near_singular": not labels and distance < NEAR_FACTOR * rtol,
        "closest": min(distances, key=lambda k: distances[k]),
        "uncontrolled": ";".join(" ".join(f"{j}:{v:+.3g}" for j, v in m.items()) for m in act.remaining),
        "distance": distance,
    }
    sv = padded(np.asarray(mm.singular_values, float))
    av = padded(np.asarray(act.rate_singular_values, float))
    row.update(zip(SV_COLUMNS, [*sv.tolist(), *av.tolist()]))
    if cad:
        row.update(residual=conf.residual, rank_rtol=rtol)
    return row, distances


def _actuation_distance(rates: Array, r: int) -> float:
    """``sigma_r / max(1, sigma_1)`` of the held rates' singular values: 1 when r is 0, 0 when fewer than r."""
    if r <= 0:
        return 1.0
    if rates.size < r:
        return 0.0
    return float(rates[r - 1]) / max(1.0, float(rates[0]))


def unreachable_chain(reason: str) -> dict[str, Any]:
    """The row of a sample whose loops could not be closed, with the reason."""
    row: dict[str, Any] = dict.fromkeys(CHAIN_COLUMNS, "")
    row.update(reachable=False, reason=reason, near_singular=False, distance=float("nan"))
    row.update({k: -1 for k in ("dof", "closure_rank", "closure_rows", "redundant_constraints", "idle_dof",
                                "locked_dof", "redundant_actuators")})  # fmt: skip
    row.update(dict.fromkeys(SV_COLUMNS, float("nan")))
    return row
