"""Command line: ``pinmob models``, ``pinmob analyze``, ``pinmob show``.

Errors are printed as one line on stderr (``pinmob: error: ...``) with exit
status 2, never with a traceback.
"""

from __future__ import annotations

import argparse
import json
import sys
import tomllib
import warnings
from collections.abc import Callable, Sequence
from typing import TYPE_CHECKING, Any

from .exceptions import PinmobError, choices

if TYPE_CHECKING:
    from .mechanism import Mechanism

COMMANDS: dict[str, Callable[[argparse.Namespace], int]] = {}


def command(name: str) -> Callable[[Callable[[argparse.Namespace], int]], Callable[[argparse.Namespace], int]]:
    def deco(fn: Callable[[argparse.Namespace], int]) -> Callable[[argparse.Namespace], int]:
        COMMANDS[name] = fn
        return fn

    return deco


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="pinmob", description="Platform mobility of parallel and closed-chain robots."
    )
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("models", help="list the built-in mechanisms")
    p.add_argument("--json", action="store_true", help="print JSON")

    p = sub.add_parser("analyze", help="mobility of the platform at a configuration")
    p.add_argument("mechanism", help="built-in model name or path to a mechanism file")
    p.add_argument("--config", "-c", help="named configuration (default: the first one in the file)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument(
        "--paper-view",
        action="store_true",
        help="also show the seed paper's view: generic limb wrenches carried to the configuration",
    )
    p.add_argument("--rtol", type=float, default=None, help="relative tolerance of rank decisions (default 1e-6)")

    p = sub.add_parser("show", help="show the mechanism and its free motions, animated, in meshcat")
    p.add_argument("mechanism", help="built-in model name or path to a mechanism file")
    p.add_argument("--config", "-c", help="named configuration (default: the first one in the file)")
    p.add_argument("--html", metavar="FILE", help="write a self-contained HTML file instead of using a server")
    p.add_argument("--force", action="store_true", help="with --html: overwrite FILE if it exists")
    p.add_argument(
        "--zmq-url", help="send to a running meshcat server (e.g. tcp://127.0.0.1:6000) instead of starting one"
    )
    p.add_argument("--port", type=int, help="web port of the server pinmob starts (default: first free from 7000)")
    p.add_argument(
        "--detach", action="store_true", help="leave the started server running in the background and return"
    )
    p.add_argument("--motion", help="free motion shown first, by label (e.g. 'T1 x'; default: the first)")
    p.add_argument("--wrenches", action="store_true", help="show the constraint wrenches")
    p.add_argument(
        "--amplitude", type=float, help="distance of each motion: m for translations, rad for rotations/screws"
    )
    p.add_argument("--steps", type=int, default=12, help="continuation steps per direction (default 12)")
    return parser


@command("models")
def _models(args: argparse.Namespace) -> int:
    from .mechanism_file import builtin_models, load

    rows: list[dict[str, Any]] = []
    for name in builtin_models():
        mech = load(name)
        rows.append(
            {
                "name": name,
                "limbs": [{"name": b.name, "joints": list(b.joints)} for b in mech.limbs],
                "configurations": {
                    c: {
                        "expected": (
                            {"dof": mech.expected[c].dof, "motion_type": mech.expected[c].motion_type}
                            if c in mech.expected
                            else None
                        )
                    }
                    for c in mech.configurations
                },
                "description": mech.description,
            }
        )
    if args.json:
        print(json.dumps(rows, indent=2))
        return 0
    for row in rows:
        limbs = ", ".join(f"{b['name']} ({len(b['joints'])} joints)" for b in row["limbs"])
        print(f"{row['name']}: limbs {limbs}")
        for c, info in row["configurations"].items():
            exp = info["expected"]
            print(f"    {c}" + (f": expected {exp['dof']} DoF {exp['motion_type']}" if exp else ""))
    return 0


@command("analyze")
def _analyze(args: argparse.Namespace) -> int:
    from .exceptions import ConfigurationError
    from .mechanism_file import load
    from .mobility import analyze, paper_view
    from .report import format_expectation
    from .screw import RTOL

    mech = load(args.mechanism)
    config = _pick_configuration(mech, args.config)
    rtol = RTOL if args.rtol is None else args.rtol
    if not 0 < rtol < 1:
        raise ConfigurationError(f"--rtol must be in (0, 1), got {rtol}")
    q = mech.configuration(config)
    mob = analyze(mech, q, configuration=config, rtol=rtol)
    paper = paper_view(mech, config, rtol=rtol) if args.paper_view else None
    if args.json:
        out = mob.to_dict()
        if config in mech.expected:
            exp = mech.expected[config]
            out["expected"] = {
                "dof": exp.dof,
                "motion_type": exp.motion_type,
                "source": exp.source,
                "agrees": exp.dof == mob.dof and exp.motion_type == mob.motion_type,
            }
        if paper is not None:
            out["paper_view"] = paper.to_dict()
        print(json.dumps(out, indent=2, allow_nan=False))
        return 0
    print(mob)
    if config in mech.expected:
        print(format_expectation(mob, mech.expected[config]))
    if paper is not None:
        print()
        print(paper)
        if (paper.dof, paper.motion_type) != (mob.dof, mob.motion_type):
            print(
                f"difference: the paper's view gives {paper.motion_type} ({paper.dof} DoF), the wrenches at the "
                f"configuration give {mob.motion_type} ({mob.dof} DoF); serially singular limbs: "
                f"{', '.join(mob.serially_singular_limbs) or 'none'}"
            )
    return 0


def _pick_configuration(mech: Mechanism, config: str | None) -> str:
    """The named configuration to use: the one asked for, else the file's first."""
    from .exceptions import ConfigurationError

    if config is None:
        if not mech.configurations:
            raise ConfigurationError(f"{mech.name!r} declares no configuration; name one in the mechanism file")
        return next(iter(mech.configurations))
    if config not in mech.configurations:
        raise ConfigurationError(
            f"no configuration {config!r} in {mech.name!r}; valid: {choices(mech.configurations)}" + _elsewhere(config)
        )
    return config


def _elsewhere(config: str) -> str:
    """Hint naming the built-in models that do have a configuration called ``config``."""
    from .mechanism_file import builtin_models

    owners = []
    for name, path in builtin_models().items():
        with path.open("rb") as fh:
            if config in tomllib.load(fh).get("configurations", {}):
                owners.append(name)
    return f"; built-in model(s) with a configuration {config!r}: {choices(owners)}" if owners else ""


@command("show")
def _show(args: argparse.Namespace) -> int:
    from .exceptions import ConfigurationError
    from .mechanism_file import load

    warnings.filterwarnings("ignore", category=ResourceWarning)  # meshcat's client leaves a socket to the GC
    mech = load(args.mechanism)
    config = _pick_configuration(mech, args.config)
    if args.html is None and args.force:
        raise ConfigurationError("--force only applies to --html FILE")
    if args.html is not None and (args.zmq_url or args.port is not None or args.detach):
        raise ConfigurationError("--html writes a file and uses no server: drop --zmq-url, --port and --detach")
    options = {"motion": args.motion, "wrenches": args.wrenches, "amplitude": args.amplitude, "steps": args.steps}
    from . import viewer

    if args.html is not None:
        scene = viewer.export_html(mech, config, args.html, overwrite=args.force, **options)
    else:
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
    for note in scene.notes:
        print(f"note: {note}")
    if scene.generated_geometry:
        print("drawn as a generated stick figure (the URDF has no visuals)")
    if scene.html is not None:
        print(f"wrote {scene.html} (open it in a browser; no server needed)")
        return 0
    print(f"open {scene.url}")
    if scene.server is None:
        return 0
    if args.detach:
        print(f"the meshcat server keeps running (pid {scene.server.pid}); stop it with: kill {scene.server.pid}")
        return 0
    print("serving; press Ctrl-C to stop the server")
    try:
        scene.server.process.wait()
    except KeyboardInterrupt:
        pass
    finally:
        scene.server.stop()
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``pinmob`` console script."""
    args = build_parser().parse_args(argv)
    warnings.simplefilter("ignore" if getattr(args, "json", False) else "default")
    warnings.formatwarning = lambda msg, cat, *a, **k: f"pinmob: warning: {msg}\n"  # type: ignore[assignment]
    try:
        return COMMANDS[args.command](args)
    except PinmobError as exc:
        print(f"pinmob: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print("pinmob: interrupted", file=sys.stderr)
        return 130
