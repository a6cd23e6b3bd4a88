"""Scans: mobility and singularities along a path or over a workspace slice, with refinement, files and plots.

:mod:`~pinmob.scan.scan_spec` (what to scan: paths and grids), :mod:`~pinmob.scan.scan_run`
(the scan itself: warm-started assembly, analysis, refinement, workers),
:mod:`~pinmob.scan.sample` (one sample on its own), :mod:`~pinmob.scan.lockstep` and
:mod:`~pinmob.scan.batch_rows` (the batched engine: chunks assembled in
lockstep, samples analysed in one batch), :mod:`~pinmob.scan.chain_scan` (a mechanism without a platform: the whole
closed chain along a joint path),
:mod:`~pinmob.scan.refine` (singular points between samples), and the subpackage :mod:`pinmob.scan.results`:
the rows as columns (``table``), streamed CSV/JSON/Parquet (``output``), :class:`ScanReport` (what :func:`scan`
returns, ``scan_report``), and PNG plots (``scan_plot``, ``workspace_map``).
"""

from pinmob.assembly import pose_vector
from pinmob.scan.chain_scan import check_actuated, value_joints
from pinmob.scan.chunk import run_chunk
from pinmob.scan.coordinates import check_coordinates, coordinate_unit
from pinmob.scan.results.scan_report import ScanReport, describe
from pinmob.scan.results.table import ScanTable
from pinmob.scan.sample import evaluate
from pinmob.scan.scan_run import ScanRun, columns, scan, scan_table, scan_tables
from pinmob.scan.scan_spec import (
    CHUNK,
    KINDS,
    LINE_CHUNK,
    POSE_COORDS,
    STRIDE,
    ScanSpec,
    grid_spec,
    parse_grid_axis,
    path_spec,
    platform_pose,
    pose_from_vector,
    resolve_pose,
    with_finite,
)
from pinmob.scan.seeding_walk import chunk_seeds

__all__ = [
    "CHUNK",
    "LINE_CHUNK",
    "KINDS",
    "POSE_COORDS",
    "STRIDE",
    "ScanReport",
    "ScanRun",
    "ScanSpec",
    "ScanTable",
    "check_actuated",
    "check_coordinates",
    "chunk_seeds",
    "columns",
    "coordinate_unit",
    "describe",
    "evaluate",
    "grid_spec",
    "parse_grid_axis",
    "path_spec",
    "platform_pose",
    "pose_from_vector",
    "pose_vector",
    "resolve_pose",
    "run_chunk",
    "scan",
    "scan_table",
    "scan_tables",
    "value_joints",
    "with_finite",
]
