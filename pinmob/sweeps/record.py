"""One design, one record: its mechanism built, analysed at the reference configuration, its workspace scanned.

A design that cannot be built, closed or scanned is a record with ``status``
``failed`` and the one-line reason; an unexpected error inside pinmob is one
too (its type and message), never a crash of the sweep. With the spec's
``finite = true`` the record adds the finite-mobility analysis at the reference
configuration (:data:`pinmob.sweeps.fields.FINITE_FIELDS`); a mechanism it cannot
treat (a joint type of no constant motion subspace) leaves those fields null and
says why in ``finite_motions``.
"""

from __future__ import annotations

import math
import tempfile
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from pinmob.analysis import ORDER, FiniteMobility, MotionVerdict, Verdict, analyze
from pinmob.exceptions import ConfigurationError, PinmobError
from pinmob.scan import ScanTable, scan_table
from pinmob.sweeps.fields import MIN_AT
from pinmob.sweeps.sweep_spec import DesignJob


def empty_record(job: DesignJob, index: int, values: dict[str, float]) -> dict[str, Any]:
    """The record of design ``index`` with its parameters and every other field None."""
    record: dict[str, Any] = dict.fromkeys(name for name, _ in job.fields)
    record.update(design=index, **{p: values[p] for p in job.parameters})
    return record


def failed(record: dict[str, Any], reason: str) -> dict[str, Any]:
    """The record marked failed, with its reason on one line."""
    record.update(status="failed", reason=" ".join(reason.split()))
    return record


def evaluate_design(job: DesignJob, item: tuple[int, dict[str, float]]) -> dict[str, Any]:
    """The record of one design ``item = (index, parameter values)`` (a Dask task, or run in process)."""
    index, values = item
    record = empty_record(job, index, values)
    try:
        with warnings.catch_warnings(), tempfile.TemporaryDirectory(prefix="pinmob-design-") as folder:
            warnings.simplefilter("ignore")  # e.g. a template's meshes, not copied: kinematics only
            return _evaluate(job, record, values, Path(folder))
    except PinmobError as exc:
        return failed(record, str(exc))
    except Exception as exc:  # noqa: BLE001  (a record says so; the sweep goes on)
        return failed(record, f"internal error {type(exc).__name__}: {exc}")


def evaluate_designs(job: DesignJob, items: list[tuple[int, dict[str, float]]]) -> list[dict[str, Any]]:
    """The records of several designs (one Dask task, :class:`pinmob.sweeps.sweep_run.SweepRun`), in order."""
    return [evaluate_design(job, item) for item in items]


def _evaluate(job: DesignJob, record: dict[str, Any], values: dict[str, float], folder: Path) -> dict[str, Any]:
    mech = job.source.mechanism(values, folder)
    scan = job.scan.spec(mech)
    finite = job.finite_order is not None
    report = analyze(mech, scan.q_ref, rtol=scan.rtol, generic_rank=scan.generic_rank, finite=finite,
                     finite_order=job.finite_order or ORDER)  # fmt: skip
    whole = report.mechanism_mobility
    record.update(
        status="ok",
        reason="",
        dof=report.dof,
        motion_type=report.motion_type,
        constraint_rank=report.constraint_rank,
        generic_rank=scan.generic_rank,
        mechanism_dof=whole.mechanism_dof,
        redundant_constraints=whole.redundant_constraints,
        actuation_valid=whole.actuation.valid,
    )
    table = scan_table(mech, scan)
    refined, reachable = table["refined"], table["reachable"]
    samples = int((~refined).sum())
    assembled = reachable & ~refined
    record.update(
        samples=samples,
        assembled=int(assembled.sum()) / samples if samples else None,
        singularity_free=float(np.mean(table["singularity"][assembled] == "none")) if assembled.any() else None,
        refined_points=int((refined & reachable).sum()),
        motion_types=";".join(sorted(set(table["motion_type"][assembled].tolist()))),
    )
    best = closest_row(table)
    if best is not None:
        record.update(min_distance=float(table["distance"][best]), min_distance_class=table["closest"][best])
        record.update({MIN_AT + p: float(table[p][best]) for p in job.scan.parameters()})
    if finite:
        try:
            fm = report.finite
        except ConfigurationError as exc:  # e.g. a joint type the higher-order conditions cannot treat
            record["finite_motions"] = "not analysed: " + " ".join(str(exc).split())
        else:
            assert fm is not None  # asked for
            record.update(finite_fields(fm))
    return record


def closest_row(table: ScanTable) -> int | None:
    """The row of the smallest finite distance to singularity among the assembled rows (the first of equals).

    None when no row assembled, when the first assembled row's distance is NaN, or when no distance is finite.
    """
    reach = np.flatnonzero(table["reachable"])
    if not len(reach) or np.isnan(table["distance"][reach[0]]):
        return None
    best = int(reach[np.nanargmin(table["distance"][reach])])
    return best if math.isfinite(table["distance"][best]) else None


def finite_fields(fm: FiniteMobility) -> dict[str, Any]:
    """The record's finite-mobility fields (:data:`pinmob.sweeps.fields.FINITE_FIELDS`) from the analysis."""
    return {
        "finite_dof": fm.finite_dof,
        "finite_mechanism_dof": fm.finite_mechanism_dof,
        "finite_dof_locked": fm.finite_dof_locked,
        "finite_motions": "; ".join(f"{v.label}: {short_verdict(v)}" for v in fm.motions),
    }


def short_verdict(v: MotionVerdict) -> str:
    """``finite``, ``blocked at order k``, ``branch point`` or ``cannot decide`` (the note left out)."""
    return f"blocked at order {v.order}" if v.verdict is Verdict.BLOCKED else v.verdict.value
