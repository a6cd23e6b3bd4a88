"""One design, one record: its mechanism built, analysed at the reference configuration, its workspace scanned.

A design that cannot be built, closed or scanned is a record with ``status``
``failed`` and the one-line reason; an unexpected error inside pinmob is one
too (its type and message), never a crash of the sweep.
"""

from __future__ import annotations

import math
import tempfile
import warnings
from pathlib import Path
from typing import Any

from pinmob.analysis.entry_point import analyze
from pinmob.exceptions import PinmobError
from pinmob.scan.chunk import run_chunk
from pinmob.scan.run import chunk_seeds
from pinmob.sweeps.fields import MIN_AT
from pinmob.sweeps.spec import SweepSpec


def empty_record(spec: SweepSpec, index: int, values: dict[str, float]) -> dict[str, Any]:
    """The record of design ``index`` with its parameters and every other field None."""
    record: dict[str, Any] = dict.fromkeys(name for name, _ in spec.fields())
    record.update(design=index, **{p: values[p] for p in spec.parameters})
    return record


def failed(record: dict[str, Any], reason: str) -> dict[str, Any]:
    """The record marked failed, with its reason on one line."""
    record.update(status="failed", reason=" ".join(reason.split()))
    return record


def evaluate_design(spec: SweepSpec, item: tuple[int, dict[str, float]]) -> dict[str, Any]:
    """The record of one design ``item = (index, parameter values)`` (a Dask task, or run in process)."""
    index, values = item
    record = empty_record(spec, index, values)
    try:
        with warnings.catch_warnings(), tempfile.TemporaryDirectory(prefix="pinmob-design-") as folder:
            warnings.simplefilter("ignore")  # e.g. a template's meshes, not copied: kinematics only
            return _evaluate(spec, record, values, Path(folder))
    except PinmobError as exc:
        return failed(record, str(exc))
    except Exception as exc:  # noqa: BLE001  (a record says so; the sweep goes on)
        return failed(record, f"internal error {type(exc).__name__}: {exc}")


def _evaluate(spec: SweepSpec, record: dict[str, Any], values: dict[str, float], folder: Path) -> dict[str, Any]:
    mech = spec.source.mechanism(values, folder)
    scan = spec.scan.spec(mech)
    report = analyze(mech, scan.q_ref, rtol=scan.rtol, generic_rank=scan.generic_rank)
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
    samples = reachable = free = refined = 0
    types: set[str] = set()
    best: dict[str, Any] | None = None
    params = spec.scan.parameters()
    for job in chunk_seeds(mech, scan):
        for row in run_chunk(mech, scan, *job):
            if row["reachable"] and (best is None or row["distance"] < best["distance"]):
                best = row
            if row["refined"]:
                refined += bool(row["reachable"])
                continue
            samples += 1
            if row["reachable"]:
                reachable += 1
                free += row["singularity"] == "none"
                types.add(row["motion_type"])
    record.update(
        samples=samples,
        assembled=reachable / samples if samples else None,
        singularity_free=free / reachable if reachable else None,
        refined_points=refined,
        motion_types=";".join(sorted(types)),
    )
    if best is not None and math.isfinite(best["distance"]):
        record.update(min_distance=float(best["distance"]), min_distance_class=best["closest"])
        record.update({MIN_AT + p: float(best[p]) for p in params})
    return record
