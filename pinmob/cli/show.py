"""``pinmob show``: the free motions, animated in meshcat, or exported as one HTML file."""

from __future__ import annotations

import argparse
import math
import warnings

from pinmob import viewer
from pinmob.analysis import asked_configuration
from pinmob.assembly import CLOSURE_TOL, RESTARTS
from pinmob.cli.common import joint_values_of, load_for, signals_interrupt, with_elsewhere
from pinmob.exceptions import ConfigurationError


def run(args: argparse.Namespace) -> int:
    """``pinmob show``: the mechanism and its free motions, animated, in meshcat (or a self-contained HTML file)."""
    warnings.filterwarnings("ignore", category=ResourceWarning)  # meshcat's client leaves a socket to the GC
    mech = load_for(args)
    with with_elsewhere(mech):
        named = None if args.joints is None else f"--joints {args.joints}"
        state, _ = asked_configuration(  # checks --closure-tol; a file without a configuration: one found
            mech,
            args.config,
            joint_values_of(args),
            closure_tol=CLOSURE_TOL if args.closure_tol is None else args.closure_tol,
            restarts=RESTARTS,
            relax=False,
            name=named,
        )
    if state.name is None:
        state = state.with_name("found closed configuration")
    config = str(state.name)
    if args.html is None and args.force:
        raise ConfigurationError("--force only applies to --html FILE")
    if args.html is not None and (args.zmq_url or args.port is not None or args.detach):
        raise ConfigurationError("--html writes a file and uses no server: drop --zmq-url, --port and --detach")
    options = {"motion": args.motion, "wrenches": args.wrenches, "amplitude": args.amplitude, "steps": args.steps}
    if args.html is not None:
        with signals_interrupt():  # SIGTERM/SIGHUP as Ctrl-C: the temporary file is removed, the old file kept
            scene = viewer.export_html(mech, state, args.html, overwrite=args.force, **options)
        print_scene(mech.name, config, scene)
        return 0
    # SIGTERM and SIGHUP act as Ctrl-C (KeyboardInterrupt) from before the server starts until it is stopped:
    # while the scene is sent, the report printed and the server serves (a signal in a gap between separate
    # handlers, e.g. right after the "serving" line, killed pinmob and left the server running). Stopped while
    # serving: status 0; interrupted before: the server pinmob started is stopped, status 130 (main).
    with signals_interrupt():
        server, serving = None, False
        try:
            scene = viewer.show(  # stops it if interrupted; tied: a SIGKILL of pinmob stops it too
                mech, state, zmq_url=args.zmq_url, port=args.port, tied=not args.detach, **options
            )
            server = scene.server
            print_scene(mech.name, config, scene)
            print(f"open {scene.url}")
            if server is None:
                return 0
            if args.detach:
                print(f"the meshcat server keeps running (pid {server.pid}); stop it with: kill {server.pid}")
                return 0
            serving = True  # before the line: whoever reads it and sends a signal gets status 0
            print(f"serving (meshcat server pid {server.pid}); press Ctrl-C to stop the server", flush=True)
            server.process.wait()  # until the server ends, or Ctrl-C, SIGTERM or SIGHUP
        except KeyboardInterrupt:
            if not serving:
                raise
        finally:
            if server is not None and not args.detach:
                server.stop()
    return 0


def print_scene(name: str, config: str, scene: viewer.Scene) -> None:
    """The report of ``pinmob show``: the mobility, each clip's reach and measured displacement, the notes."""
    mob = scene.mobility
    if scene.shown_frame:
        print(f"note: {scene.shown_frame}")
    print(f"{name} at {config!r}: {mob.dof} DoF, {mob.motion_type}")
    for label in scene.clips:
        path = scene.paths[label]
        unit = "m" if label.startswith("T") else "rad"
        state = "" if path.complete else "  (stopped early, see below)"
        print(
            f"  clip {label!r}: +{path.reached[0]:.3g} / -{path.reached[1]:.3g} {unit} of {path.amplitude:.3g}{state}"
        )
        moved = " / ".join(
            f"{sign}: {d.translation:.3g} m, {d.rotation:.2g} rad ({math.degrees(d.deviation):.2g} deg off the motion)"
            for sign, d in zip("+-", path.displacement, strict=True)
        )
        print(f"    {'output frame' if scene.shown_frame else 'platform'} moved {moved}")
        if path.verdict:
            only = "" if path.finite is not False else "; the motion exists only to first order"
            print(f"    finite analysis: {path.verdict}{only}")
    for note in scene.notes:
        print(f"note: {note}")
    if scene.generated_geometry:
        print("drawn as a generated stick figure (the URDF has no visuals)")
    if not scene.panel_shown:
        print(
            f"note: the meshcat server at {scene.zmq_url} is not pinmob's: its page shows the scene without pinmob's "
            "panel (motions, clips, labels, legend); leave out --zmq-url for pinmob's own server"
        )
    if scene.html is not None:
        print(f"wrote {scene.html} (open it in a browser; no server needed)")
