"""``pinmob analyze``: the whole answer at a configuration, from :func:`pinmob.analyze` (text or JSON)."""

from __future__ import annotations

import argparse
import json
import sys
from typing import Any

from pinmob.analysis import REPORT_PARTS, Report, analyze
from pinmob.assembly import CLOSURE_TOL
from pinmob.cli.common import joint_values_of, load_for, with_elsewhere
from pinmob.cli.flags import worded_report
from pinmob.exceptions import ConfigurationError
from pinmob.name_matching import choices
from pinmob.screw import RTOL


def run(args: argparse.Namespace) -> int:
    """``pinmob analyze``: print the :class:`~pinmob.analysis.report.Report` (``--json``: its document).

    The command parses, calls :func:`pinmob.analyze` (which checks each argument and resolves the configuration
    by name or joint values) and formats.

    Returns:
        the exit status: 1 with ``--check`` when the analysis differs from the file's expectation, else 0.
    """
    mech = load_for(args)
    if args.check and not mech.expected:
        raise ConfigurationError(f"--check: {mech.name!r} has no expected table in any configuration")
    with with_elsewhere(mech):
        report = analyze(
            mech,
            args.config,
            configuration=None if args.joints is None else f"--joints {args.joints}",
            joints=joint_values_of(args),
            rtol=RTOL if args.rtol is None else args.rtol,
            closure_tol=CLOSURE_TOL if args.closure_tol is None else args.closure_tol,
            frames=args.frame,
            restarts=args.restarts,
            relax=args.relax,
            **part_arguments(args),
        )
    if args.check and report.expectation is None:
        raise ConfigurationError(
            f"--check: configuration {report.configuration!r} of {mech.name!r} has no expected table; "
            f"configurations with one: {choices(mech.expected)}"
        )
    if args.json:
        print(json.dumps(report.to_dict(), indent=2, allow_nan=False))
    else:
        print(worded_report(report.brief() if args.brief else str(report)))  # the parameters it names as options
    return check_status(args, report)


def part_arguments(args: argparse.Namespace) -> dict[str, Any]:
    """The keywords of :func:`pinmob.analyze` the registered report parts' options give (those given only).

    An option given also sets the switch it implies (``--finite-order K``: ``finite=True``).
    """
    given: dict[str, Any] = {}
    for part in REPORT_PARTS.values():
        for o in part.options:
            value = getattr(args, o.keyword, None) if o.option is not None else None
            if value is None or value is False:
                continue
            given[o.keyword] = value
            if o.implies is not None:
                given[o.implies] = True
    return given


def check_status(args: argparse.Namespace, report: Report) -> int:
    """Exit status of ``analyze``: 1 with ``--check`` when the result differs from the file's expectation."""
    exp = report.expectation
    if not args.check or exp is None or exp.agrees:
        return 0
    found = report.mobility if report.has_limbs else report.platform_frame
    what = "no platform frame" if found is None else f"{found.dof} DoF {found.motion_type}"
    print(
        f"pinmob: check failed: {report.mechanism} at {report.configuration!r}: analysis gives {what}, "
        f"the file expects {exp.dof} DoF {exp.motion_type}",
        file=sys.stderr,
    )
    return 1
