"""``pinmob scan``: mobility and singularities along a path or over a workspace slice."""

from __future__ import annotations

import argparse
import tempfile
import time
from collections import Counter
from pathlib import Path
from typing import Any

from pinmob.analysis.singularity.classification import require_platform
from pinmob.analysis.singularity.result import NEAR_FACTOR
from pinmob.assembly.residual import CLOSURE_TOL
from pinmob.cli.common import check_outputs, load_for, signals_interrupt
from pinmob.cli.scan_view import check_view_options, view
from pinmob.exceptions import ConfigurationError
from pinmob.scan import columns, grid_spec, path_spec, scan, with_finite
from pinmob.scan.chain_scan import check_actuated
from pinmob.scan.coordinates import coordinate_unit
from pinmob.scan.output import RowWriter
from pinmob.scan.scan_plot import plot_path, varied_joint
from pinmob.scan.scan_spec import ScanSpec, parse_grid_axis
from pinmob.scan.workspace_map import plot_map
from pinmob.screw.rank import RTOL


def run(args: argparse.Namespace) -> int:
    """``pinmob scan``: mobility and singularities along a path or over a workspace slice.

    SIGTERM and SIGHUP stop it as Ctrl-C does: the output files are left as they were (or not created).
    """
    with signals_interrupt():
        return _run(args)


def _run(args: argparse.Namespace) -> int:
    rtol = RTOL if args.rtol is None else args.rtol  # checked by the library (path_spec, grid_spec)
    _check_scan_options(args)
    check_outputs({"--csv": args.csv, "--json": args.json_out, "--plot": args.plot, "--html": args.html}, args.force)
    if args.plot and Path(args.plot).suffix.lower() != ".png":
        raise ConfigurationError(f"--plot {args.plot!r}: the plot is a PNG image; give a file name ending in .png")
    mech = load_for(args)
    check_view_options(args, mech)
    closure_tol = CLOSURE_TOL if args.closure_tol is None else args.closure_tol
    names = list(mech.configurations)
    if args.grid:
        require_platform(mech, "pinmob scan --grid", "`pinmob analyze`", "`pinmob scan --from A --to B`")
        axes = [parse_grid_axis(text, "--grid") for text in args.grid]
        if not names and not args.at:
            raise ConfigurationError(f"{mech.name!r} declares no configuration; give --at")
        spec = grid_spec(mech, args.at or names[0], axes, rtol, closure_tol)
        if args.plot and len(spec.axes) != 2:
            raise ConfigurationError(
                f"--plot maps a grid over two coordinates; this grid has {len(spec.axes)}: drop --plot or grid two"
            )
        what = f"grid {' x '.join(args.grid)} at {args.at or names[0]!r}" + _held_text(spec)
    else:
        if args.joints or not mech.has_platform:
            check_actuated(mech)
        start = args.start or (names[0] if names else None)
        end = args.end or (names[1] if len(names) > 1 else None)
        if start is None or end is None:
            raise ConfigurationError(f"{mech.name!r} has fewer than two configurations; give --from and --to")
        samples = 21 if args.samples is None else args.samples
        spec = path_spec(mech, start, end, samples, joints=args.joints, rtol=rtol, closure_tol=closure_tol)
        joints = "" if spec.platform else f" ({', '.join(spec.joints)})"  # a closed chain's actuated joints
        kind = {"joints": "actuated-joint", "coords": f"coordinate ({', '.join(spec.coords)})"}.get(spec.kind, "pose")
        what = f"{kind} path{joints} {start!r} -> {end!r}, {samples} samples" + _held_text(spec)
    rtol = spec.rtol  # as checked
    if args.finite or args.finite_order is not None:  # --finite-order K implies --finite
        spec = with_finite(mech, spec, args.finite_order)
        what += f", finite DoF per sample (order bound {spec.finite_order})"
    used = spec.reference_rtol(mech)  # rtol, or raised for the CAD gaps held (spec.cad)
    band = NEAR_FACTOR * used
    if spec.cad:  # loops closed to CAD accuracy (pinmob.assembly.cad_gaps)
        what += f", closure tolerance {spec.closure_tol:g} (CAD gaps of the reference held; rank tolerance {used:.2g})"
    generic = "generic constraint rank" if spec.platform else "generic closure rank"
    key = "generic_rank" if spec.platform else "generic_closure_rank"
    meta = {"mechanism": mech.name, "scan": what, key: spec.generic_rank, "rtol": rtol, "near_singular_band": band,
            "length_scale": mech.length_scale}  # fmt: skip
    if spec.cad:
        meta.update(closure_tol=spec.closure_tol, rank_rtol=used)
    counts: Counter[str] = Counter()
    tally: Counter[str] = Counter()
    finite: Counter[str] = Counter()
    listed: list[dict[str, Any]] = []
    kept: list[dict[str, Any]] = []  # every row, for --show or --html
    why = ""
    with tempfile.TemporaryDirectory() as tmp:
        csv_path = args.csv or (str(Path(tmp) / "scan.csv") if args.plot else None)
        t0 = time.perf_counter()
        rows = scan(mech, spec, args.workers, False if args.no_progress else None, args.scheduler)
        with RowWriter(columns(spec), meta, csv_path, args.json_out) as writer:
            for row in rows:
                writer.write(row)
                if args.show or args.html:
                    kept.append(row)
                kind = _row_kind(row)
                tally[kind] += 1
                if not row["refined"]:
                    counts[_count_key(row) if row["reachable"] else "unreachable"] += 1
                    if spec.finite_order is not None and row["reachable"]:
                        dof = row["finite_dof" if spec.platform else "finite_mechanism_dof"]
                        finite["cannot decide" if dof is None else f"{dof} DoF"] += 1
                if kind != "regular" and len(listed) < 20:
                    listed.append(row)
                if not row["reachable"] and row.get("reason") and not why:
                    why = f"#{row['index']} ({_params(row)}): {row['reason']}"
        elapsed = time.perf_counter() - t0
        n = spec.size
        print(f"{mech.name}: {what}")
        print(f"{n} samples in {elapsed:.2f} s ({n / elapsed:.1f} samples/s, {rows.where}); "
              f"{generic} {spec.generic_rank}")  # fmt: skip
        for key, k in sorted(counts.items()):
            print(f"  {k:5d} x {key}")
        if finite:
            print(f"finite DoF of the {'platform' if spec.platform else 'mechanism'} at the assembled samples: "
                  + ", ".join(f"{k} x {key}" for key, k in sorted(finite.items())))  # fmt: skip
        print(f"singular samples: {tally['singular']}; near-singular samples (distance < {band:.0e}): "
              f"{tally['near-singular']}; refined singular points: {tally['refined']}")  # fmt: skip
        total = tally["singular"] + tally["near-singular"] + tally["refined"]
        if why:
            print(f"first sample not assembled: {why}")
        for row in listed:
            print("  " + (_format_row(row, used, mech.actuated) if spec.platform else _format_chain_row(row, used)))
        if total > len(listed):
            print(f"  ... ({total - len(listed)} more in the output files)")
        for label, path in (("csv", args.csv), ("json", args.json_out)):
            if path:
                print(f"{label}: {path}")
        if args.plot and csv_path:
            title = f"{mech.name}: {what}"
            if args.grid:
                plot_map(
                    csv_path, args.plot, title, rtol=used, units={a[0]: coordinate_unit(mech, a[0]) for a in spec.axes}
                )
            else:
                plot_path(csv_path, args.plot, title, used, mech.length_scale, varied_joint(mech, spec), spec.platform)
            print(f"plot: {args.plot}")
    if args.show or args.html:
        view(args, mech, spec, kept, what, str(args.at or names[0] if args.grid else start))
    return 0


def _check_scan_options(args: argparse.Namespace) -> None:
    """A grid scan and a path scan take different options: refuse a mix."""
    path_options = {"--from": args.start, "--to": args.end, "--joints": args.joints or None, "-n": args.samples}
    if args.grid:
        given = [k for k, v in path_options.items() if v is not None]
        if given:
            raise ConfigurationError(
                f"--grid scans a workspace slice; {', '.join(given)} belong to a path scan: drop them or drop --grid"
            )
    elif args.at is not None:
        raise ConfigurationError("--at fixes the other coordinates of a --grid scan; a path scan uses --from and --to")


def _row_kind(row: dict[str, Any]) -> str:
    """``refined``, ``singular``, ``near-singular`` or ``regular`` (unreachable samples are regular)."""
    if row["refined"]:
        return "refined"
    if row["reachable"] and row["singularity"] != "none":
        return "singular"
    return "near-singular" if row["near_singular"] else "regular"


def _count_key(row: dict[str, Any]) -> str:
    """How the summary counts an assembled sample: the platform's DoF and type, or the closed chain's DoF and verdict."""
    if "motion_type" in row:
        return f"{row['dof']} DoF {row['motion_type']}"
    verdict = {True: "actuation valid", False: "actuation NOT valid"}.get(row["actuation_valid"], "no actuated joint")
    return f"mechanism DoF {row['dof']}, closure rank {row['closure_rank']}, {row['idle_dof']} idle, {verdict}"


def _distance(distance: float, rtol: float) -> str:
    """``distance 3.52e-04``, or ``distance <= 1e-06`` at a singularity (at most ``rtol``: the figure is round-off)."""
    return f"distance <= {rtol:g}" if distance <= rtol else f"distance {distance:.2e}"


def _format_chain_row(row: dict[str, Any], rtol: float) -> str:
    """One listed row of a closed chain's joint path: where, class, DoF, motions left with the actuators locked."""
    where = f"#{row['index']}+ refined" if row["refined"] else f"#{row['index']}"
    names = [k for k in row if k.startswith("q_")]
    values = ", ".join(f"{k[2:]} = {row[k]:.6g}" for k in names[:6]) + (", ..." if len(names) > 6 else "")
    label = row["singularity"] if row["singularity"] != "none" else f"near-singular ({row['closest']})"
    left = f", locked: {row['locked_dof']} motion(s) left ({row['uncontrolled']})" if row["uncontrolled"] else ""
    if "finite_mechanism_dof" in row:  # --finite
        dof = row["finite_mechanism_dof"]
        left += f", finite mechanism DoF {'cannot decide' if dof is None else dof}"
    return (f"{where} (s = {round(row['s'], 12):.6g}; {values}): {label}; mechanism DoF {row['dof']}, "
            f"closure rank {row['closure_rank']}{left}, {_distance(row['distance'], rtol)}")  # fmt: skip


def _params(row: dict[str, Any]) -> str:
    """Where a row is: ``s = 0.5``, or ``x = 0.01, y = -0.02`` (the grid's coordinates)."""
    return ", ".join(f"{k} = {round(row[k], 12):.6g}" for k in row if k == "s" or k.startswith("grid_"))


def _format_row(row: dict[str, Any], rtol: float, actuated: tuple[str, ...] = ()) -> str:
    """One listed row of ``pinmob scan``: where, class, limbs, uncontrolled motions, DoF, distance.

    A refined point also gives its actuated joints' values (those not on the grid).
    """
    params = _params(row)
    where = f"#{row['index']}+ refined" if row["refined"] else f"#{row['index']}"
    joints = [n for n in actuated if f"q_{n}" in row and n not in {k[5:] for k in row if k.startswith("grid_")}]
    if row["refined"] and joints:
        params += "; " + ", ".join(f"{n} = {row['q_' + n]:.6g}" for n in joints)
    label = row["singularity"] if row["singularity"] != "none" else f"near-singular ({row['closest']})"
    limbs = f", limbs {row['singular_limbs']}" if row["singular_limbs"] else ""
    dep = f", dependent limbs {row['dependent_limbs']}" if row["dependent_limbs"] else ""
    unc = f", uncontrolled {row['uncontrolled']}" if row["uncontrolled"] else ""
    fin = ""
    if "finite_dof" in row:  # --finite
        fin = f" (finite {'cannot decide' if row['finite_dof'] is None else row['finite_dof']})"
    return (f"{where} ({params}): {label}{limbs}{dep}{unc}; {row['dof']} DoF {row['motion_type']}{fin}, "
            f"{_distance(row['distance'], rtol)}")  # fmt: skip


def _held_text(spec: ScanSpec) -> str:
    """What a scan holds and what follows the mechanism, for its header line ('' when nothing is held)."""
    if spec.following:
        held = ", ".join(c for c, _ in spec.held) or "none"
        return f"; held: {held}; following the mechanism: {', '.join(spec.following)}"
    if spec.held and not spec.pose_grid:
        return f"; held: {', '.join(c for c, _ in spec.held)}"
    return ""
