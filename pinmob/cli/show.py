"""``pinmob show``: the free motions, animated in meshcat, or exported as one HTML file."""

from __future__ import annotations

import argparse
import math
import warnings

from pinmob import viewer
from pinmob.cli.common import pick_configuration, serve_until_stopped, signals_interrupt
from pinmob.exceptions import ConfigurationError
from pinmob.io.loader import load


def run(args: argparse.Namespace) -> int:
    """``pinmob show``: the mechanism and its free motions, animated, in meshcat (or a self-contained HTML file)."""
    warnings.filterwarnings("ignore", category=ResourceWarning)  # meshcat's client leaves a socket to the GC
    mech = load(args.mechanism)
    config = pick_configuration(mech, args.config)
    if args.html is None and args.force:
        raise ConfigurationError("--force only applies to --html FILE")
    if args.html is not None and (args.zmq_url or args.port is not None or args.detach):
        raise ConfigurationError("--html writes a file and uses no server: drop --zmq-url, --port and --detach")
    options = {"motion": args.motion, "wrenches": args.wrenches, "amplitude": args.amplitude, "steps": args.steps}
    if args.html is not None:
        scene = viewer.export_html(mech, config, args.html, overwrite=args.force, **options)
    else:
        with signals_interrupt():  # a SIGTERM while the server starts or the scene is sent stops the server too
            scene = viewer.show(mech, config, zmq_url=args.zmq_url, port=args.port, **options)
    mob = scene.mobility
    print(f"{mech.name} at {config!r}: {mob.dof} DoF, {mob.motion_type}")
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
        print(f"    platform moved {moved}")
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
        return 0
    print(f"open {scene.url}")
    if scene.server is None:
        return 0
    if args.detach:
        print(f"the meshcat server keeps running (pid {scene.server.pid}); stop it with: kill {scene.server.pid}")
        return 0
    print(f"serving (meshcat server pid {scene.server.pid}); press Ctrl-C to stop the server", flush=True)
    serve_until_stopped(scene.server)
    return 0
