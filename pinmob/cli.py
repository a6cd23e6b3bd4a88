"""Command line: ``pinmob models``, ``pinmob analyze``, ``pinmob show``, ``pinmob scan``.

Errors are printed as one line on stderr (``pinmob: error: ...``) with exit
status 2, never with a traceback.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import re
import sys
import tomllib
import warnings
from collections.abc import Callable, Iterator, Sequence
from typing import TYPE_CHECKING, Any, NoReturn

from .exceptions import ConfigurationError, PinmobError, choices

if TYPE_CHECKING:
    from .mechanism import Mechanism
    from .screw import Array

COMMANDS: dict[str, Callable[[argparse.Namespace], int]] = {}


def command(name: str) -> Callable[[Callable[[argparse.Namespace], int]], Callable[[argparse.Namespace], int]]:
    def deco(fn: Callable[[argparse.Namespace], int]) -> Callable[[argparse.Namespace], int]:
        COMMANDS[name] = fn
        return fn

    return deco


class Parser(argparse.ArgumentParser):
    """argparse with usage errors on one line, ``pinmob: error: ...``, exit status 2 (``--help`` unchanged).

    The line ends with the help of the (sub)command that has the bad argument: ``see 'pinmob analyze --help'``.
    """

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"pinmob: error: {' '.join(message.split())}; see '{self.prog} --help'\n")

    def parse_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> argparse.Namespace:
        """As argparse, but an unrecognised argument after a command points to that command's help
        (argparse reports it on the top-level parser, whose help does not list the command's options)."""
        parsed, extra = self.parse_known_args(args, namespace)
        if extra:
            command = getattr(parsed, "command", None)
            prog = f"{self.prog} {command}" if command else self.prog
            self.exit(2, f"pinmob: error: unrecognized arguments: {' '.join(extra)}; see '{prog} --help'\n")
        return parsed


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(prog="pinmob", description="Platform mobility of parallel and closed-chain robots.")
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
    p.add_argument(
        "--check",
        action="store_true",
        help="exit 1 (one line on stderr) when the analysis differs from the file's expected table (for CI)",
    )
    p.add_argument(
        "--frame",
        action="append",
        default=None,
        help="frame whose motion is also reported (repeatable); the outputs that define idle motions and "
        "actuation validity stay the platform, else the tree's free leaf bodies",
    )
    p.add_argument(
        "--relax",
        action="store_true",
        help="if the loops cannot be closed as declared, relax the over-constraining closures to 3d and say which",
    )
    p.add_argument(
        "--restarts", type=int, default=20, help="random restarts when searching a closed configuration (default 20)"
    )
    p.add_argument(
        "--search-actuators",
        type=int,
        default=None,
        metavar="K",
        help="also list every valid set of K actuated joints (exhaustive)",
    )

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
    p = sub.add_parser("scan", help="mobility and singularities along a path or over a workspace slice")
    p.add_argument("mechanism", help="built-in model name or path to a mechanism file")
    p.add_argument(
        "--from",
        dest="start",
        help="path start: configuration name or pose x,y,z,roll,pitch,yaw [m, rad] (default: first configuration)",
    )
    p.add_argument("--to", dest="end", help="path end: configuration name or pose (default: second configuration)")
    p.add_argument(
        "--joints",
        action="store_true",
        help="interpolate the actuated joint values from --from to --to (forward kinematics) instead of platform poses",
    )
    p.add_argument("--samples", "-n", type=int, default=None, help="samples along a path (default 21)")
    p.add_argument(
        "--grid",
        nargs=2,
        metavar="COORD:LO:HI:N",
        help="scan a workspace slice: two pose coordinates (x, y, z [m], roll, pitch, yaw [rad]) instead of a path",
    )
    p.add_argument(
        "--at",
        help="grid: configuration whose platform pose fixes the other coordinates (default: first configuration)",
    )
    p.add_argument("--csv", help="write the samples to this CSV file")
    p.add_argument("--json", dest="json_out", help="write the samples to this JSON file")
    p.add_argument(
        "--plot", help="write a PNG plot here (path: singular values; grid: maps of motion type and distance)"
    )
    p.add_argument("--force", action="store_true", help="overwrite the --csv, --json and --plot files if they exist")
    p.add_argument("--workers", type=int, default=1, help="local processes (results identical to 1)")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--rtol", type=float, default=None, help="relative tolerance of rank decisions (default 1e-6)")
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
                "limbs": [{"name": b.name, "joints": list(b.joints), "actuated": list(b.actuated)} for b in mech.limbs],
                "closures": [{"name": c.name, "frames": [c.frame_a, c.frame_b], "type": c.type} for c in mech.closures],
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
        closures = ", ".join(f"{c['name']} ({c['type']})" for c in row["closures"])
        print(f"{row['name']}: {len(row['limbs'])} limbs" + (f", closures {closures}" if closures else ""))
        for b in row["limbs"]:
            prefix = f"{b['name']}_"
            short = [j.removeprefix(prefix) + ("*" if j in b["actuated"] else "") for j in b["joints"]]
            print(f"    limb {b['name']}: {' '.join(short)}")
        for c, info in row["configurations"].items():
            exp = info["expected"]
            print(f"    {c}" + (f": expected {exp['dof']} DoF {exp['motion_type']}" if exp else ""))
    print("(* actuated; joint names without the limb prefix)")
    return 0


@command("analyze")
def _analyze(args: argparse.Namespace) -> int:
    from .constraints import analyze_mechanism
    from .mechanism_file import load
    from .mobility import analyze, check_rtol, paper_view
    from .report import format_expectation
    from .screw import RTOL

    mech = load(args.mechanism)
    config = args.config
    rtol = RTOL if args.rtol is None else check_rtol(args.rtol, "--rtol")
    if args.check and not mech.expected:
        raise ConfigurationError(f"--check: {mech.name!r} has no expected table in any configuration")
    if config is None and not mech.configurations:
        return _analyze_closed_chain(args, mech, rtol)
    config = _pick_configuration(mech, config)
    if args.check and config not in mech.expected:
        raise ConfigurationError(
            f"--check: configuration {config!r} of {mech.name!r} has no expected table; configurations with one: "
            f"{choices(mech.expected)}"
        )
    q = mech.configuration(config)
    if not mech.limbs:
        return _analyze_closed_chain(args, mech, rtol, q, config)
    mob = analyze(mech, q, configuration=config, rtol=rtol)
    mm = analyze_mechanism(mech, q, configuration=config, frames=args.frame, rtol=rtol)
    paper = paper_view(mech, config, rtol=rtol) if args.paper_view else None
    from .singularity import analyze_singularity, format_singularity

    # the singularity classes are limb-wise: not defined when a closure couples limbs
    sing = analyze_singularity(mech, q, configuration=config, rtol=rtol) if not mob.method_note else None
    sets = _actuator_sets(args, mech, q, rtol)
    if args.json:
        out = mob.to_dict()
        out.update({k: v for k, v in mm.to_dict().items() if k in MECHANISM_KEYS})
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
        out["singularity"] = sing.to_dict() if sing is not None else None
        if sets is not None:
            out["valid_actuator_sets"] = [list(x) for x in sets]
        print(json.dumps(out, indent=2, allow_nan=False))
        return _check_exit(args, mech, config, mob)
    print(mob)
    print(format_singularity(sing) if sing is not None else "singularity: not analysed (limb-wise classes)")
    if config in mech.expected:
        print(format_expectation(mob, mech.expected[config]))
    print()
    print(mm)
    _print_actuator_sets(args, sets)
    if paper is not None:
        print()
        print(paper)
        if (paper.dof, paper.motion_type) != (mob.dof, mob.motion_type):
            print(
                f"difference: the paper's view gives {paper.motion_type} ({paper.dof} DoF), the wrenches at the "
                f"configuration give {mob.motion_type} ({mob.dof} DoF); serially singular limbs: "
                f"{', '.join(mob.serially_singular_limbs) or 'none'}"
            )
    return _check_exit(args, mech, config, mob)


def _check_exit(args: argparse.Namespace, mech: Mechanism, config: str | None, mob: Any) -> int:
    """Exit status of ``analyze``: 1 with ``--check`` when the result differs from the file's expectation.

    ``mob`` is the limb-wise result, or the platform frame's motion for a mechanism without limbs.
    """
    if args.check and (config is None or config not in mech.expected):
        raise ConfigurationError(f"--check: {mech.name!r} has no expected table for configuration {config!r}")
    exp = mech.expected.get(config) if config is not None else None
    if not args.check or exp is None or (mob is not None and (exp.dof, exp.motion_type) == (mob.dof, mob.motion_type)):
        return 0
    found = "no platform frame" if mob is None else f"{mob.dof} DoF {mob.motion_type}"
    print(
        f"pinmob: check failed: {mech.name} at {config!r}: analysis gives {found}, "
        f"the file expects {exp.dof} DoF {exp.motion_type}",
        file=sys.stderr,
    )
    return 1


def _pick_configuration(mech: Mechanism, config: str | None) -> str:
    """The named configuration to use: the one asked for, else the file's first."""

    if config is None:
        if not mech.configurations:
            raise ConfigurationError(f"{mech.name!r} declares no configuration; name one in the mechanism file")
        return next(iter(mech.configurations))
    if config not in mech.configurations:
        raise ConfigurationError(
            f"no configuration {config!r} in {mech.name!r}; valid: {choices(mech.configurations)}"
            + _elsewhere(config, mech)
        )
    return config


def _elsewhere(config: str, mech: Mechanism | None = None) -> str:
    """Hint naming the built-in models that do have a configuration called ``config``, and why not ``mech``.

    The why is the sentence of ``mech``'s description that names one of those models, if any (e.g. the
    3-PUU's links are too long for beta = 0, which needs the geometry of 3-PUU-flat).
    """
    from .mechanism_file import builtin_models

    owners = []
    for name, path in builtin_models().items():
        with path.open("rb") as fh:
            if config in tomllib.load(fh).get("configurations", {}):
                owners.append(name)
    if not owners:
        return ""
    why = ""
    if mech is not None:
        sentences = re.split(r"(?<=[.!?])\s+", mech.description)
        others = [o for o in owners if o not in mech.name]  # '3-PUU' in "3-PUU-flat" is the family, not a pointer
        named = [t for t in sentences if any(re.search(rf"(?<![\w-]){re.escape(o)}(?![\w-])", t) for o in others)]
        why = f". Why not in {mech.name!r}: {named[0]}" if named else ""
    return f"; built-in model(s) with a configuration {config!r}: {choices(owners)}{why}"


@command("show")
def _show(args: argparse.Namespace) -> int:

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
        _print_scene(mech.name, config, scene)
        return 0
    # SIGTERM and SIGHUP act as Ctrl-C (KeyboardInterrupt) from before the server starts until it is stopped:
    # while the scene is sent, the report printed and the server serves (a signal in a gap between separate
    # handlers, e.g. right after the "serving" line, killed pinmob and left the server running). Stopped while
    # serving: status 0; interrupted before: the server pinmob started is stopped, status 130 (main).
    with _signals_interrupt():
        server, serving = None, False
        try:
            scene = viewer.show(
                mech, config, zmq_url=args.zmq_url, port=args.port, **options
            )  # stops it if interrupted
            server = scene.server
            _print_scene(mech.name, config, scene)
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


def _print_scene(name: str, config: str, scene: Any) -> None:
    """The report of ``pinmob show``: the mobility, each clip's reach and measured displacement, the notes."""
    import math

    mob = scene.mobility
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
        print(f"    platform moved {moved}")
    for note in scene.notes:
        print(f"note: {note}")
    if scene.generated_geometry:
        print("drawn as a generated stick figure (the URDF has no visuals)")
    if scene.html is not None:
        print(f"wrote {scene.html} (open it in a browser; no server needed)")


@contextlib.contextmanager
def _signals_interrupt() -> Iterator[None]:
    """Within the block, SIGTERM and SIGHUP raise KeyboardInterrupt, as Ctrl-C does, so cleanups run."""
    import signal

    def interrupt(signum: int, frame: object) -> None:
        raise KeyboardInterrupt

    wanted = [signal.SIGTERM] + ([signal.SIGHUP] if hasattr(signal, "SIGHUP") else [])
    previous = {sig: signal.signal(sig, interrupt) for sig in wanted}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)


@command("scan")
def _scan(args: argparse.Namespace) -> int:
    import tempfile
    import time
    from collections import Counter
    from pathlib import Path

    from .mechanism_file import load
    from .mobility import check_rtol
    from .plot import plot_map, plot_path
    from .scan import columns, grid_spec, path_spec, scan
    from .scan_file import RowWriter
    from .screw import RTOL
    from .singularity import NEAR_FACTOR, require_platform

    rtol = RTOL if args.rtol is None else check_rtol(args.rtol, "--rtol")
    _check_scan_options(args)
    mech = load(args.mechanism)
    require_platform(mech, "pinmob scan")
    names = list(mech.configurations)
    if args.grid:
        axes = [_grid_axis(text) for text in args.grid]
        if not names and not args.at:
            raise ConfigurationError(f"{mech.name!r} declares no configuration; give --at")
        spec = grid_spec(mech, args.at or names[0], axes, rtol)
        what = f"grid {args.grid[0]} x {args.grid[1]} at {args.at or names[0]!r}"
    else:
        start = args.start or (names[0] if names else None)
        end = args.end or (names[1] if len(names) > 1 else None)
        if start is None or end is None:
            raise ConfigurationError(f"{mech.name!r} has fewer than two configurations; give --from and --to")
        samples = 21 if args.samples is None else args.samples
        spec = path_spec(mech, start, end, samples, joints=args.joints, rtol=rtol)
        what = f"{'actuated-joint' if args.joints else 'pose'} path {start!r} -> {end!r}, {samples} samples"
    _check_outputs({"--csv": args.csv, "--json": args.json_out, "--plot": args.plot}, args.force)
    if args.plot and Path(args.plot).suffix.lower() != ".png":
        raise ConfigurationError(f"--plot {args.plot!r}: the plot is a PNG image; give a file name ending in .png")
    band = NEAR_FACTOR * rtol
    meta = {"mechanism": mech.name, "scan": what, "generic_rank": spec.generic_rank, "rtol": rtol,
            "near_singular_band": band, "length_scale": mech.length_scale}  # fmt: skip
    counts: Counter[str] = Counter()
    tally: Counter[str] = Counter()
    listed: list[dict[str, Any]] = []
    with tempfile.TemporaryDirectory() as tmp:
        csv_path = args.csv or (str(Path(tmp) / "scan.csv") if args.plot else None)
        t0 = time.perf_counter()
        with RowWriter(columns(spec), meta, csv_path, args.json_out) as writer:
            for row in scan(mech, spec, workers=args.workers, progress=False if args.no_progress else None):
                writer.write(row)
                kind = _row_kind(row)
                tally[kind] += 1
                if not row["refined"]:
                    counts[f"{row['dof']} DoF {row['motion_type']}" if row["reachable"] else "unreachable"] += 1
                if kind != "regular" and len(listed) < 20:
                    listed.append(row)
        elapsed = time.perf_counter() - t0
        n = spec.size
        print(f"{mech.name}: {what}")
        print(f"{n} samples in {elapsed:.2f} s ({n / elapsed:.1f} samples/s, {args.workers} worker(s)); "
              f"generic constraint rank {spec.generic_rank}")  # fmt: skip
        for key, k in sorted(counts.items()):
            print(f"  {k:5d} x {key}")
        print(f"singular samples: {tally['singular']}; near-singular samples (distance < {band:.0e}): "
              f"{tally['near-singular']}; refined singular points: {tally['refined']}")  # fmt: skip
        total = tally["singular"] + tally["near-singular"] + tally["refined"]
        for row in listed:
            print("  " + _format_row(row))
        if total > len(listed):
            print(f"  ... ({total - len(listed)} more in the output files)")
        for label, path in (("csv", args.csv), ("json", args.json_out)):
            if path:
                print(f"{label}: {path}")
        if args.plot and csv_path:
            (plot_map if args.grid else plot_path)(csv_path, args.plot, f"{mech.name}: {what}", rtol=rtol)
            print(f"plot: {args.plot}")
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


def _grid_axis(text: str) -> tuple[str, float, float, int]:
    """``COORD:LO:HI:N`` -> (coordinate, low, high, count)."""

    parts = text.split(":")
    try:
        if len(parts) != 4:
            raise ValueError
        return parts[0], float(parts[1]), float(parts[2]), int(parts[3])
    except ValueError:
        raise ConfigurationError(
            f"--grid {text!r}: expected COORD:LO:HI:N (four fields separated by ':'), e.g. x:-0.1:0.1:21"
        ) from None


def _row_kind(row: dict[str, Any]) -> str:
    """``refined``, ``singular``, ``near-singular`` or ``regular`` (unreachable samples are regular)."""
    if row["refined"]:
        return "refined"
    if row["reachable"] and row["singularity"] != "none":
        return "singular"
    return "near-singular" if row["near_singular"] else "regular"


def _format_row(row: dict[str, Any]) -> str:
    """One listed row of ``pinmob scan``: where, class, limbs, uncontrolled motions, DoF, distance."""
    params = ", ".join(f"{k} = {round(row[k], 12):.6g}" for k in row if k == "s" or k.startswith("grid_"))
    where = f"#{row['index']}+ refined" if row["refined"] else f"#{row['index']}"
    label = row["singularity"] if row["singularity"] != "none" else f"near-singular ({row['closest']})"
    limbs = f", limbs {row['singular_limbs']}" if row["singular_limbs"] else ""
    dep = f", dependent limbs {row['dependent_limbs']}" if row["dependent_limbs"] else ""
    unc = f", uncontrolled {row['uncontrolled']}" if row["uncontrolled"] else ""
    return f"{where} ({params}): {label}{limbs}{dep}{unc}; {row['dof']} DoF {row['motion_type']}, distance {row['distance']:.2e}"


def _check_outputs(paths: dict[str, str | None], force: bool) -> None:
    """Refuse, before any work, output files that exist (unless ``force``), are folders, or lie in no folder."""
    from pathlib import Path

    given = {option: Path(path).expanduser() for option, path in paths.items() if path}
    if len({p.resolve() for p in given.values()}) < len(given):
        raise ConfigurationError(
            f"{', '.join(given)} must name different files, got {choices(map(str, given.values()))}"
        )
    for option, target in given.items():
        if target.is_dir():
            raise ConfigurationError(f"{option} {str(target)!r} is a folder; give a file name")
        if target.exists() and not force:
            raise ConfigurationError(
                f"{option} {str(target)!r} exists already; choose another file name or allow overwriting (--force)"
            )
        parent = target.parent if str(target.parent) else Path(".")
        if not parent.is_dir():
            raise ConfigurationError(f"cannot write {option} {str(target)!r}: folder {str(parent)!r} does not exist")


#: keys of the whole-mechanism result added to the JSON of a limb-and-platform analysis
MECHANISM_KEYS = (
    "nv",
    "closure_rows",
    "closure_rank",
    "mechanism_dof",
    "idle_dof",
    "idle_joints",
    "redundant_constraints",
    "redundant_by_closure",
    "redundant_by_closure_rule",
    "grubler",
    "actuation",
    "closures",
    "end_frames",
    "frames",
)


def _analyze_closed_chain(
    args: argparse.Namespace, mech: Mechanism, rtol: float, q: Array | None = None, config: str | None = None
) -> int:
    """``pinmob analyze`` for a mechanism without limbs (Extended URDF, MJCF, TOML closures only)."""
    from .closure import ClosureError, check_closed, find_closed, find_closed_relaxed, unclosable, worst_residual
    from .constraints import analyze_mechanism

    relaxed: tuple[str, ...] = ()
    method = f"named configuration {config!r}"
    if q is None:
        if args.relax:
            mech, found, relaxed = find_closed_relaxed(mech, restarts=args.restarts)
        else:
            try:
                found = find_closed(mech, restarts=args.restarts)
            except ClosureError as exc:
                bad = unclosable(mech)
                hint = f"closures that cannot close even on their own: {', '.join(bad)}. " if bad else ""
                raise ClosureError(
                    f"{mech.name!r} (as declared) could not be closed from the neutral configuration nor {args.restarts} random restarts. "
                    f"{hint}Rerun with --relax to turn the over-constraining closures into 3d (ball) closures. Largest residual "
                    f"of the best attempt: {worst_residual(exc.residuals, mech.length_scale):.2e} (m / L or rad)",
                    exc.residuals,
                ) from None
        q, method = found.q, found.method
        residual = found.residual
    else:
        residual = worst_residual(check_closed(mech, q), mech.length_scale)
    mm = analyze_mechanism(mech, q, configuration=config, frames=args.frame, rtol=rtol)
    sets = _actuator_sets(args, mech, q, rtol)
    if args.json:
        out = mm.to_dict()
        out["closed_configuration"] = {
            "method": method,
            "residual": residual,
            "relaxed_closures": list(relaxed),
            "q": [float(x) for x in q],
        }
        if mech.has_platform and mm.frames:
            out["platform"] = mm.frames[0].to_dict()
        if sets is not None:
            out["valid_actuator_sets"] = [list(x) for x in sets]
        print(json.dumps(out, indent=2, allow_nan=False))
        return _check_exit(args, mech, config, _platform_frame(mech, mm))
    print(f"closed configuration: {method} (largest residual {residual:.1e})")
    if relaxed:
        print(f"relaxed to 3d (the file's closures cannot all close as declared): {', '.join(relaxed)}")
    print(mm)
    _print_actuator_sets(args, sets)
    return _check_exit(args, mech, config, _platform_frame(mech, mm))


def _platform_frame(mech: Mechanism, mm: Any) -> Any:
    """The platform frame's entry of a whole-mechanism result, or None."""
    return next((f for f in mm.frames if f.frame == mech.platform), None) if mech.has_platform else None


def _actuator_sets(args: argparse.Namespace, mech: Mechanism, q: Array, rtol: float) -> list[tuple[str, ...]] | None:
    """``--search-actuators K``: every valid set of K actuated joints, or None when not asked.

    The outputs are the default ones (the platform, else the free leaf bodies): ``--frame`` only reports.
    """
    from .constraints import actuator_sets

    if args.search_actuators is None:
        return None
    return actuator_sets(mech, q, args.search_actuators, rtol=rtol)


def _print_actuator_sets(args: argparse.Namespace, sets: list[tuple[str, ...]] | None) -> None:
    if sets is None:
        return
    print(f"valid sets of {args.search_actuators} actuated joints: {len(sets)}")
    for x in sets[:50]:
        print("  " + ", ".join(x))
    if len(sets) > 50:
        print(f"  ... ({len(sets) - 50} more)")


def _format_warning(
    message: Warning | str, category: type[Warning], filename: str, lineno: int, line: str | None = None
) -> str:
    return f"pinmob: warning: {message}\n"


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``pinmob`` console script."""
    args = build_parser().parse_args(argv)
    warnings.simplefilter("ignore" if getattr(args, "json", False) else "default")
    warnings.formatwarning = _format_warning
    try:
        status = COMMANDS[args.command](args)
        sys.stdout.flush()  # a closed pipe shows here, not at interpreter exit
        return status
    except PinmobError as exc:
        print(f"pinmob: error: {' '.join(str(exc).split())}", file=sys.stderr)
        return 2
    except BrokenPipeError:
        # the reader went away (``pinmob ... | head -1``): stop quietly, as Unix tools do on SIGPIPE
        try:
            devnull = os.open(os.devnull, os.O_WRONLY)
            os.dup2(devnull, sys.stdout.fileno())  # nothing left to flush at exit
            os.close(devnull)
        except (OSError, ValueError):  # stdout is not a file (e.g. captured in tests)
            pass
        return 128 + 13
    except KeyboardInterrupt:
        print("pinmob: interrupted", file=sys.stderr)
        return 130
