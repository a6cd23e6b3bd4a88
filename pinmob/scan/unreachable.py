"""The verdict columns of a platform scan's rows, and the rows of samples that did not assemble, and why."""

from __future__ import annotations

from typing import Any

from pinmob.assembly import POSE_COORDS, SHOWN, pose_vector, worst_first
from pinmob.exceptions import ClosureError, PinmobError
from pinmob.model import CLOSURE_TOL, Mechanism

#: The singular-value columns of a platform scan's rows: the constraint's, then the actuation's.
SV_COLUMNS = [f"sv{i}" for i in range(1, 7)] + [f"av{i}" for i in range(1, 7)]

#: The verdict columns of a platform scan's rows, after the pose coordinates and before the singular values, in
#: order (every engine writes them in this order: :func:`pinmob.scan.sample.evaluate`,
#: :func:`pinmob.scan.batch_rows.analyse`, :func:`unreachable_row`).
VERDICT_COLUMNS = ("reachable", "dof", "motion_type", "constraint_rank", "locked_dof", "singularity", "near_singular",
                   "closest", "singular_limbs", "dependent_limbs", "uncontrolled", "distance")  # fmt: skip

#: The verdict of a sample that did not assemble, by column.
UNREACHABLE_VERDICT = dict(reachable=False, dof=-1, motion_type="unreachable", constraint_rank=-1, locked_dof=-1,
                           singularity="", near_singular=False, closest="", singular_limbs="", dependent_limbs="",
                           uncontrolled="", distance=float("nan"))  # fmt: skip


def unreachable_reason(exc: PinmobError, mech: Mechanism, tol: float = CLOSURE_TOL) -> str:
    """Why a sample did not assemble, on one line: the largest misses of the closest configuration found.

    A pose coordinate missed (``x off by ...``) is out of the mechanism's reach from the warm start; a
    limb or closure left open (``limb A open by ...``) cannot reach (its stroke, or its geometry).
    """
    res = exc.residuals if isinstance(exc, ClosureError) else {}
    if not res:
        return str(exc)
    length = mech.length_scale
    worst = [(k, (p, r)) for k, (p, r) in worst_first(res, length) if max(p / length, r) > tol][:SHOWN]
    limbs = {b.name for b in mech.limbs}
    parts = []
    for k, (p, r) in worst:
        off = " and ".join([f"{p:.2e} m"] * (p / length > tol) + [f"{r:.2e} rad"] * (r > tol))
        if k.startswith("coordinate "):
            parts.append(f"{k[11:]} off by {off}")
        elif k == "pose":
            parts.append(f"platform pose off by {off}")
        else:
            parts.append(f"{'limb' if k in limbs else 'closure'} {k} open by {off}")
    return "no convergence from the warm start (out of reach?); closest found: " + ", ".join(parts)


def unreachable_row(target: tuple[str, Any], reason: str) -> dict[str, Any]:
    """The row of a sample that did not assemble: the pose coordinates it asked for (NaN: followed), the reason."""
    kind, value = target
    row: dict[str, Any] = dict.fromkeys(POSE_COORDS, float("nan"))
    if kind == "pose":
        row.update(zip(POSE_COORDS, pose_vector(value).tolist()))
    elif kind == "coords":
        row.update(value[0])
    row.update((k, UNREACHABLE_VERDICT[k]) for k in VERDICT_COLUMNS)
    row["reason"] = reason
    row.update(dict.fromkeys(SV_COLUMNS, float("nan")))
    return row
