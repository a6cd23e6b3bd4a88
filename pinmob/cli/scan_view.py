"""``pinmob scan --show`` and ``--html FILE``: the scan's reachable set in 3D, beside the mechanism at one sample.

The viewer is imported when a view is drawn: a scan without one does not load it (20 ms of a fresh process).
"""

from __future__ import annotations

import argparse
import warnings
from typing import Any

from pinmob.analysis import Configuration
from pinmob.exceptions import ConfigurationError
from pinmob.model import Mechanism
from pinmob.scan import ScanSpec, coordinate_unit


def check_view_options(args: argparse.Namespace, mech: Mechanism) -> None:
    """Refuse, before the scan, a view the scan cannot give (both targets, ``--sample`` alone, no platform)."""
    if args.show and args.html:
        raise ConfigurationError("--show uses a meshcat server, --html writes a file: give one of them")
    if args.sample is not None and not (args.show or args.html):
        raise ConfigurationError(
            "--sample K chooses the sample the 3D view draws the mechanism at: add --show or --html "
            "(a path's number of samples is --samples N, or -n N)"
        )
    if (args.show or args.html) and not mech.has_platform:
        raise ConfigurationError(
            f"--show and --html draw the platform's reachable positions; {mech.name!r} has no platform"
        )


def axes_words(mech: Mechanism, spec: ScanSpec) -> tuple[str, ...]:
    """Each gridded coordinate with its unit and range (``grid x [m]: -0.03 to 0.03, 5 values``)."""
    return tuple(
        f"grid {name} [{coordinate_unit(mech, name)}]: {lo:g} to {hi:g}, {n} values" for name, lo, hi, n in spec.axes
    )


def view(
    args: argparse.Namespace, mech: Mechanism, spec: ScanSpec, rows: list[dict[str, Any]], what: str, reference: str
) -> None:
    """Draw the scan's reachable set beside the mechanism (at ``--sample K``, else at ``reference``)."""
    from pinmob import viewer  # here: a scan without a view does not load the viewer

    state: Any = reference
    if spec.cad:  # closed within the scan's closure tolerance only (CAD gaps)
        state = Configuration(mech, spec.q_ref, closure_tol=spec.closure_tol, name=reference)
    if args.sample is not None:
        state = viewer.sample_configuration(mech, rows, args.sample, spec.q_ref, spec.closure_tol)
    ws = viewer.workspace_cloud(
        rows, spec.reference_rtol(mech), args.sample, f"{mech.name}: {what}", axes_words(mech, spec)
    )
    at = f"sample #{args.sample}" if args.sample is not None else repr(reference)
    warnings.filterwarnings("ignore", category=ResourceWarning)  # meshcat's client leaves a socket to the GC
    if args.html:
        scene = viewer.export_html(mech, state, args.html, overwrite=args.force, workspace=ws)
        print(f"3D view: {len(ws.positions)} assembled samples beside the mechanism at {at}; wrote {scene.html}")
        return
    scene = viewer.show(mech, state, tied=True, workspace=ws)
    server = scene.server
    print(f"3D view: {len(ws.positions)} assembled samples beside the mechanism at {at}; open {scene.url}")
    if server is None:
        return
    print(f"serving (meshcat server pid {server.pid}); press Ctrl-C to stop the server", flush=True)
    try:
        server.process.wait()
    except KeyboardInterrupt:
        pass
    finally:
        server.stop()
