"""``pinmob scan``: mobility and singularities along a path or over a workspace slice."""

from __future__ import annotations

import argparse
from pathlib import Path

from pinmob.analysis import require_platform
from pinmob.cli.common import check_outputs, load_for, signals_interrupt
from pinmob.cli.scan_view import check_view_options, view
from pinmob.exceptions import ConfigurationError
from pinmob.scan import (
    check_actuated,
    grid_spec,
    parse_grid_axis,
    path_spec,
    scan,
    with_finite,
)


def run(args: argparse.Namespace) -> int:
    """``pinmob scan``: mobility and singularities along a path or over a workspace slice.

    Parses the options into a scan (:mod:`pinmob.scan.scan_spec`), runs it (:func:`pinmob.scan.scan`, which writes the
    files) and prints its report, then draws the plot or the 3D view. SIGTERM and SIGHUP stop it as Ctrl-C does:
    the output files are left as they were (or not created).
    """
    with signals_interrupt():
        return _run(args)


def _run(args: argparse.Namespace) -> int:
    _check_scan_options(args)
    outputs = {"--csv": args.csv, "--json": args.json_out, "--parquet": args.parquet, "--plot": args.plot,
               "--html": args.html}  # fmt: skip
    check_outputs(outputs, args.force)
    if args.plot and Path(args.plot).suffix.lower() != ".png":
        raise ConfigurationError(f"--plot {args.plot!r}: the plot is a PNG image; give a file name ending in .png")
    mech = load_for(args)
    check_view_options(args, mech)
    tolerances = {k: v for k, v in (("rtol", args.rtol), ("closure_tol", args.closure_tol)) if v is not None}
    names = list(mech.configurations)
    if args.grid:
        require_platform(mech, "pinmob scan --grid", "`pinmob analyze`", "`pinmob scan --from A --to B`")
        axes = [parse_grid_axis(text, "--grid") for text in args.grid]
        if not names and not args.at:
            raise ConfigurationError(f"{mech.name!r} declares no configuration; give --at")
        spec = grid_spec(mech, args.at or names[0], axes, **tolerances)
        if args.plot and len(spec.axes) != 2:
            raise ConfigurationError(
                f"--plot maps a grid over two coordinates; this grid has {len(spec.axes)}: drop --plot or grid two"
            )
        reference = str(args.at or names[0])
    else:
        if args.joints or not mech.has_platform:
            check_actuated(mech)
        start = args.start or (names[0] if names else None)
        end = args.end or (names[1] if len(names) > 1 else None)
        if start is None or end is None:
            raise ConfigurationError(f"{mech.name!r} has fewer than two configurations; give --from and --to")
        samples = 21 if args.samples is None else args.samples
        spec = path_spec(mech, start, end, samples, joints=args.joints, **tolerances)
        reference = str(start)
    if args.finite or args.finite_order is not None:  # --finite-order K implies --finite
        spec = with_finite(mech, spec, args.finite_order)
    keep = bool(args.show or args.html or args.plot)  # the rows kept for the plot or the 3D view
    report = scan(mech, spec, args.workers, False if args.no_progress else None, args.scheduler, csv=args.csv,
                  json=args.json_out, parquet=args.parquet, overwrite=args.force, keep_rows=keep)  # fmt: skip
    print(report)
    if args.plot:
        report.plot(mech, args.plot)
        print(f"plot: {args.plot}")
    if args.show or args.html:
        view(args, mech, spec, list(report), report.what, reference)
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
