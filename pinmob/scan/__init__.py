"""Scans: mobility and singularities along a path or over a workspace slice, with refinement, files and plots.

:mod:`~pinmob.scan.scan_spec` (what to scan: paths and grids), :mod:`~pinmob.scan.scan_run`
(the scan itself: warm-started assembly, analysis, refinement, workers),
:mod:`~pinmob.scan.sample` (one sample on its own), :mod:`~pinmob.scan.lockstep` and
:mod:`~pinmob.scan.batch_rows` (the batched engine: chunks assembled in
lockstep, samples analysed in one batch), :mod:`~pinmob.scan.chain_scan` (a mechanism without a platform: the whole
closed chain along a joint path),
:mod:`~pinmob.scan.refine` (singular points between samples),
:mod:`~pinmob.scan.output` (streamed CSV/JSON), :mod:`~pinmob.scan.scan_plot` and
:mod:`~pinmob.scan.workspace_map` (PNG maps of grids).
"""

from pinmob.assembly.reach import pose_vector
from pinmob.scan.chunk import run_chunk
from pinmob.scan.sample import evaluate
from pinmob.scan.scan_run import chunk_seeds, columns, scan
from pinmob.scan.scan_spec import (
    CHUNK,
    KINDS,
    POSE_COORDS,
    STRIDE,
    ScanSpec,
    grid_spec,
    path_spec,
    platform_pose,
    pose_from_vector,
    resolve_pose,
    with_finite,
)

__all__ = [
    "CHUNK",
    "KINDS",
    "POSE_COORDS",
    "STRIDE",
    "ScanSpec",
    "chunk_seeds",
    "columns",
    "evaluate",
    "grid_spec",
    "path_spec",
    "platform_pose",
    "pose_from_vector",
    "pose_vector",
    "resolve_pose",
    "run_chunk",
    "scan",
    "with_finite",
]
