"""Scans: mobility and singularities along a path or over a workspace slice.

What is scanned, in which order, is a :class:`pinmob.scan.spec.ScanSpec`. Each
target is assembled warm-started (the previous sample's configuration seeds
the closure solver of the next). One coarse walk (:func:`chunk_seeds`, in this
process) goes from the reference configuration through every ``STRIDE``-th
sample of each line (a grid row by row, in a serpentine) and gives each chunk
its seed; every chunk then runs from its seed, in this process or in a
worker, so ``workers=N`` gives the rows of ``workers=1``, and each sample costs
``1 + 1/STRIDE`` assemblies plus two per chunk (its neighbours on the line, for
the refinement). Each sample is analysed from one kinematics computation
(:func:`pinmob.analysis.singularity_analysis.singularity`).

Refinement (:mod:`pinmob.scan.refine`): a singularity between samples is looked for
where, along a line, a distance to singularity has a local minimum above
``rtol`` (each question on its own: constraint, actuation, each limb) that is
below the near-singular band or that the V through the three samples puts
below half its value, and where a sample borders one that cannot be assembled
(the edge of the reachable set, where a limb's inverse kinematics is singular).
A sample that is already singular is not refined. The line parameter is refined
(re-assembling warm-started at each trial, up to ``REFINE_ITER`` solver
iterations) and the best point is reported as an extra row (``refined`` True,
``index`` the sample before it) when its distance is below the near-singular
band ``NEAR_FACTOR * rtol``; it may then be singular or only near-singular.

Rows are yielded one at a time, in order of the line parameter (memory flat in
the number of samples); targets that cannot be assembled give a row with
``reachable = False``.
"""

from __future__ import annotations

import multiprocessing as mp
from collections.abc import Iterator
from multiprocessing.context import BaseContext
from typing import Any

import numpy as np

import pinmob.scan.chunk as chunk
from pinmob.exceptions import ConfigurationError, PinmobError
from pinmob.model.mechanism import Mechanism
from pinmob.scan.chunk import SV_COLUMNS, run_chunk
from pinmob.scan.spec import POSE_COORDS, ScanSpec
from pinmob.screw.algebra import Array


def chunk_seeds(mech: Mechanism, spec: ScanSpec) -> Iterator[tuple[int, int, Array]]:
    """``(start, stop, seed)`` of every chunk, in order, from one coarse walk (:meth:`ScanSpec.waypoints`).

    The seed is the walk's configuration at the chunk's first sample (or, when
    that does not assemble, at the last waypoint that did).
    """
    stops = dict(spec.chunks())
    order = list(stops)
    found: dict[int, Array] = {}
    q = np.array(spec.q_ref, float)
    for target, k in spec.waypoints():
        try:
            q = chunk.assemble_target(mech, target, q)
        except PinmobError:
            pass
        if k in stops:
            found[k] = q
        while order and order[0] in found:
            start = order.pop(0)
            yield start, stops[start], found.pop(start)


# --------------------------------------------------------------------------- rows


# --------------------------------------------------------------------------- running

_WORKER: dict[str, Any] = {}


def _init_worker(mech: Mechanism | str, spec: ScanSpec) -> None:
    """Worker set-up: the mechanism (forked workers) or the file to load it from (spawned workers)."""
    if isinstance(mech, str):
        from pinmob.io.loader import load

        mech = load(mech)
    _WORKER.update(mech=mech, spec=spec)


def _work(job: tuple[int, int, Array]) -> list[dict[str, Any]]:
    return run_chunk(_WORKER["mech"], _WORKER["spec"], *job)


def scan(mech: Mechanism, spec: ScanSpec, workers: int = 1, progress: bool | None = None) -> Iterator[dict[str, Any]]:
    """Rows of the scan (samples and refined points), in order of the line parameter, one at a time.

    Args:
        mech: the mechanism.
        spec: what to scan (:mod:`pinmob.scan.spec`).
        workers: local processes (1 = in this process); the rows do not depend on it.
        progress: show a tqdm bar on stderr (None: only for scans of 50 samples or more on a terminal).
    """
    from tqdm import tqdm

    if workers < 1:
        raise ConfigurationError(f"--workers must be at least 1, got {workers}")
    jobs = chunk_seeds(mech, spec)
    disable = (None if spec.size >= 50 else True) if progress is None else not progress
    bar = tqdm(total=spec.size, disable=disable, unit="sample", desc=f"scan {mech.name}", leave=False)
    try:
        if workers == 1 or len(spec.chunks()) == 1:
            for job in jobs:
                rows = run_chunk(mech, spec, *job)
                bar.update(job[1] - job[0])
                yield from rows
            return
        init: tuple[Mechanism | str, ScanSpec]
        if "fork" in mp.get_all_start_methods():
            ctx: BaseContext = mp.get_context("fork")
            init = (mech, spec)
        else:
            if mech.source is None:
                raise ConfigurationError("--workers > 1 needs a mechanism loaded from a file on this platform")
            ctx, init = mp.get_context("spawn"), (str(mech.source), spec)
        with ctx.Pool(min(workers, len(spec.chunks())), initializer=_init_worker, initargs=init) as pool:
            for rows in pool.imap(_work, jobs):
                bar.update(sum(not r["refined"] for r in rows))
                yield from rows
    finally:
        bar.close()


def columns(spec: ScanSpec) -> list[str]:
    """CSV columns of a scan's rows, in order."""
    params = list(spec.params(0))
    return ["index", *params, "refined", *POSE_COORDS, "reachable", "dof", "motion_type", "constraint_rank",
            "locked_dof", "singularity", "near_singular", "closest", "singular_limbs", "dependent_limbs",
            "uncontrolled", "distance", *SV_COLUMNS]  # fmt: skip
