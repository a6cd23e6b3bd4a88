"""The command line's arguments: ``pinmob models|analyze|show|scan|sweep|glossary|fix`` and their options."""

from __future__ import annotations

import argparse
import functools
from collections.abc import Callable, Sequence
from typing import NoReturn

from pinmob import __version__
from pinmob.analysis import FOLLOW_STEPS, ORDER, ORDERS, REPORT_PARTS
from pinmob.assembly import CLOSURE_TOL, CLOSURE_TOL_MAX, RESTARTS
from pinmob.screw import RTOL

#: where every term the reports use is explained (shown by every ``--help``)
GLOSSARY = (
    "Terms used in the reports (DoF, T/R/H, pitch, axis point, constraint wrench and rank, generic, twist rank, "
    "Type I/II, distance to singularity, L, rtol, pin.LOCAL_WORLD_ALIGNED, closure rank, Grubler-Kutzbach, "
    "internal and idle motions, ...) are explained by 'pinmob glossary' (all of them) and 'pinmob glossary TERM' "
    "(the entries of one, e.g. 'pinmob glossary \"twist rank\"')."
)


class Parser(argparse.ArgumentParser):
    """argparse with usage errors on one line, ``pinmob: error: ...``, exit status 2 (``--help`` unchanged).

    The line ends with the help of the (sub)command that has the bad argument: ``see 'pinmob analyze --help'``.
    """

    def error(self, message: str) -> NoReturn:
        """Print the usage error on one line and exit with status 2."""
        self.exit(2, f"pinmob: error: {' '.join(message.split())}; see '{self.prog} --help'\n")

    def parse_args(  # type: ignore[override]
        self, args: Sequence[str] | None = None, namespace: argparse.Namespace | None = None
    ) -> argparse.Namespace:
        """As argparse, but an unrecognised argument after a command points to that command's help.

        argparse reports it on the top-level parser, whose help does not list the command's options.
        """
        parsed, extra = self.parse_known_args(args, namespace)
        if extra:
            command = getattr(parsed, "command", None)
            prog = f"{self.prog} {command}" if command else self.prog
            self.exit(2, f"pinmob: error: unrecognized arguments: {' '.join(extra)}; see '{prog} --help'\n")
        return parsed


def add_model_options(p: argparse.ArgumentParser, joints: bool = True) -> None:
    """The options of ``analyze`` and ``show`` (``scan``: without ``--joints``): which configuration, actuation, tolerance."""
    if joints:
        p.add_argument(
            "--joints",
            metavar="NAME=VALUE,...",
            help="analyse at these joint values [rad or m] (the others from the first named configuration, else "
            "neutral); analyze --json prints a configuration's values as joint_values",
        )
    p.add_argument(
        "--actuated", metavar="A,B,...", help="the actuated joints (replacing the file's actuators, tendon ones too)"
    )
    p.add_argument(
        "--xacro-arg",
        action="append",
        metavar="NAME:=VALUE",
        help="an argument of a .xacro file (repeatable), as xacro's NAME:=VALUE",
    )
    p.add_argument(
        "--package-path",
        action="append",
        metavar="FOLDER",
        help="a folder holding ROS packages, searched by a .xacro file's $(find pkg) (repeatable; then "
        "ROS_PACKAGE_PATH); includes and load_yaml read only there and beside the file",
    )
    p.add_argument(
        "--closure-tol",
        type=float,
        default=None,
        help=f"largest closure residual accepted, position / L and rotation [rad] (default {CLOSURE_TOL:.0e}, at most {CLOSURE_TOL_MAX:.0e}; a "
        "refusal of loops that close to CAD accuracy names the value that accepts them)",
    )


def add_part_options(p: argparse.ArgumentParser) -> None:
    """The options of the registered report parts (:class:`~pinmob.analysis.report.PartOption`), in their order.

    Each option's destination is its keyword of :func:`pinmob.analyze` (``--paper-view`` gives ``args.paper``); a
    switch is True when given, an option with a value None when not (the library's default then applies).
    """
    for part in REPORT_PARTS.values():
        for o in part.options:
            if o.option is None:
                continue
            implied = next((f"; implies --{i.option}" for i in part.options if i.keyword == o.implies), "")
            if o.metavar is None:
                p.add_argument(f"--{o.option}", dest=o.keyword, action="store_true", help=o.help + implied)
            else:
                p.add_argument(
                    f"--{o.option}", dest=o.keyword, type=o.type, default=None, metavar=o.metavar, help=o.help + implied
                )


#: Each command's one-line help (``pinmob --help`` lists them in this order).
COMMAND_HELP = {
    "models": "list the built-in mechanisms",
    "analyze": "mobility of the platform at a configuration",
    "show": "show the mechanism and its free motions, animated, in meshcat",
    "scan": "mobility and singularities along a path or over a workspace slice",
    "sweep": "a design-space sweep: per design its mobility and a workspace scan",
    "glossary": "the terms the reports use, explained",
    "fix": "write the mechanism file with minimal closures (no redundant closure equation), in its own format",
}


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``pinmob`` argument parser with its seven commands.

    Args:
        command: a command whose arguments alone are added (:func:`parsed_command` of the command line): the
            others are listed (``pinmob --help``, the choices of a usage error) without their arguments, which
            parsing a command line that names ``command`` never reads. None (or not a command): every command's.
    """
    parser = Parser(
        prog="pinmob", description="Platform mobility of parallel and closed-chain robots.", epilog=GLOSSARY
    )
    parser.add_argument("--version", action="version", version=f"pinmob {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, help_text in COMMAND_HELP.items():
        p = sub.add_parser(name, help=help_text, epilog=GLOSSARY)
        if command is None or command == name or command not in COMMAND_HELP:
            _ARGUMENTS[name](p)
    return parser


def parser_for(argv: Sequence[str]) -> argparse.ArgumentParser:
    """The parser of a command line: :func:`build_parser` of the command it names (:func:`parsed_command`).

    Built once per command and set of registered report parts in this process: parsing a command line leaves a
    parser as it was.
    """
    command = parsed_command(argv)
    return _built(command if command in COMMAND_HELP else None, tuple(REPORT_PARTS.values()))


@functools.lru_cache(maxsize=16)
def _built(command: str | None, parts: tuple[object, ...]) -> argparse.ArgumentParser:
    """:func:`build_parser` (``parts``: the report parts registered, whose options ``analyze`` takes)."""
    return build_parser(command)


def parsed_command(argv: Sequence[str]) -> str | None:
    """The command a command line names: its first word that is not an option (None when there is none).

    The top-level options (``--help``, ``--version``) take no value, so the first other word is the command.
    """
    for word in argv:
        if word == "--":
            return None
        if not word.startswith("-"):
            return word
    return None


def _models(p: argparse.ArgumentParser) -> None:
    p.add_argument("--json", action="store_true", help="print JSON")


def _analyze(p: argparse.ArgumentParser) -> None:
    p.add_argument("mechanism", help="built-in model name (any case) or path to a mechanism file")
    p.add_argument("--config", "-c", help="named configuration (default: the first one in the file)")
    form = p.add_mutually_exclusive_group()
    form.add_argument("--json", action="store_true", help="print the result as JSON")
    form.add_argument(
        "--brief",
        action="store_true",
        help="print only the one-line answer (DoF, type, motions, singularity; with --finite, the finite DoF)",
    )
    p.add_argument(
        "--rtol", type=float, default=None, help=f"relative tolerance of rank decisions (default {RTOL:.0e})"
    )
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
        "--restarts",
        type=int,
        default=RESTARTS,
        help="random restarts when searching a closed configuration (default %(default)s)",
    )
    add_part_options(p)
    add_model_options(p)


def _show(p: argparse.ArgumentParser) -> None:
    p.add_argument("mechanism", help="built-in model name (any case) or path to a mechanism file")
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
        "--amplitude",
        type=float,
        help="distance of each motion: m for translations, rad for rotations/screws "
        "(default: 0.2 L for translations, L the mechanism's length scale; 0.35 rad for rotations and screws)",
    )
    p.add_argument(
        "--steps", type=int, default=FOLLOW_STEPS, help="continuation steps per direction (default %(default)s)"
    )
    add_model_options(p)


def _scan(p: argparse.ArgumentParser) -> None:
    p.add_argument("mechanism", help="built-in model name (any case) or path to a mechanism file")
    p.add_argument(
        "--from",
        dest="start",
        help="path start: configuration name, pose x,y,z,roll,pitch,yaw [m, rad], or joint values "
        "NAME=VALUE,... [rad or m] (a joint path; naming a pose coordinate, e.g. roll=0.2,pitch=0.1, a path in "
        "those coordinates, the others held or following as for --grid; default: first configuration)",
    )
    p.add_argument(
        "--to", dest="end", help="path end: configuration name, pose or joint values (default: second configuration)"
    )
    p.add_argument(
        "--joints",
        action="store_true",
        help="interpolate the actuated joint values from --from to --to (forward kinematics) instead of platform "
        "poses; implied by joint values in --from/--to and for a mechanism without a platform",
    )
    p.add_argument("--samples", "-n", type=int, default=None, help="samples along a path (default 21)")
    p.add_argument(
        "--grid",
        nargs="+",
        metavar="COORD:LO:HI:N",
        help="scan a grid instead of a path: one to three coordinates, each a platform pose coordinate (x, y, z [m], "
        "roll, pitch, yaw [rad]) or a joint (actuated or not) [rad or m]. The others: of the pose coordinates "
        "(a joint grid: of the actuated joints) those the mechanism can still move at --at with the gridded ones "
        "held are held at their --at values; the rest follow the mechanism (a lower-mobility platform's "
        "parasitic coordinates, every passive joint): see 'pinmob glossary held'",
    )
    p.add_argument(
        "--at",
        help="grid: configuration (or pose x,y,z,roll,pitch,yaw) whose coordinates the held ones keep, and where "
        "the grid's walk starts (default: first configuration)",
    )
    p.add_argument("--csv", help="write the samples to this CSV file")
    p.add_argument("--json", dest="json_out", help="write the samples to this JSON file")
    p.add_argument("--parquet", help="write the samples to this Parquet file (a typed column per CSV column)")
    p.add_argument(
        "--plot", help="write a PNG plot here (path: singular values; grid: maps of motion type and distance)"
    )
    p.add_argument(
        "--show",
        action="store_true",
        help="show the reachable set in 3D in meshcat (a point per assembled sample at the platform origin [m], "
        "coloured by distance to singularity, singular and refined points marked) beside the mechanism",
    )
    p.add_argument("--html", metavar="FILE", help="write that 3D view to a self-contained HTML file instead")
    p.add_argument(
        "--sample",
        type=int,
        metavar="K",
        help="with --show or --html: draw the mechanism at the assembled sample of index K (default: at --at, or "
        "at --from for a path)",
    )
    p.add_argument(
        "--force",
        action="store_true",
        help="overwrite the --csv, --json, --parquet, --plot and --html files if they exist",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=1,
        help="worker processes of a Dask LocalCluster, used when the scan is long enough to pay for it "
        "(results identical to 1; default 1)",
    )
    p.add_argument("--scheduler", metavar="ADDRESS", help="run the scan's chunks on the Dask cluster at this address")
    p.add_argument("--no-progress", action="store_true", help="no progress bar (none either when not a terminal)")
    p.add_argument(
        "--rtol", type=float, default=None, help=f"relative tolerance of rank decisions (default {RTOL:.0e})"
    )
    _finite_options(
        p,
        "also give each sample's finite DoF (platform and mechanism; the finite analysis per sample, "
        "tens to hundreds of ms each: see 'pinmob glossary finite')",
    )
    add_model_options(p, joints=False)


def _sweep(p: argparse.ArgumentParser) -> None:
    p.add_argument("spec", help="sweep spec file (TOML): a family or template, the designs, the scan of each")
    p.add_argument("--out", metavar="FILE.parquet", help="write the records here (streamed; re-running resumes)")
    p.add_argument("--csv", metavar="FILE.csv", help="also write the records as CSV (at the end of a complete run)")
    p.add_argument("--atlas", metavar="FILE.png", help="atlas plot (default with --out: OUT_atlas.png)")
    p.add_argument("--pareto", metavar="FILE.png", help="Pareto-front plot (default with --out: OUT_pareto.png)")
    p.add_argument("--no-plots", action="store_true", help="no plot")
    p.add_argument("--workers", type=int, default=1, help="worker processes of a Dask LocalCluster (default 1: here)")
    p.add_argument("--scheduler", metavar="ADDRESS", help="compute the designs on the Dask cluster at this address")
    p.add_argument("--force", action="store_true", help="overwrite --csv and plot files, or an --out of another sweep")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")


def _glossary(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "term", nargs="?", help="print only the entries of the terms containing this (any case); default: all"
    )


def _fix(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "mechanism", help="built-in model name (any case) or path to a TOML, Extended URDF (.yaml) or MJCF file"
    )
    p.add_argument("--output", "-o", required=True, help="the file to write (a new file; never the input)")
    p.add_argument("--force", action="store_true", help="overwrite --output if it exists (never the input)")
    p.add_argument("--config", "-c", help="configuration where the proposal is computed (default: the first named one)")
    p.set_defaults(actuated=None)  # the file's actuators are kept as they are
    p.add_argument("--closure-tol", type=float, default=None, help="largest closure residual accepted (default 1e-6)")


#: Per command, the function that adds its arguments to its parser.
_ARGUMENTS: dict[str, Callable[[argparse.ArgumentParser], None]] = {
    "models": _models,
    "analyze": _analyze,
    "show": _show,
    "scan": _scan,
    "sweep": _sweep,
    "glossary": _glossary,
    "fix": _fix,
}


def _finite_options(p: argparse.ArgumentParser, what: str) -> None:
    """``--finite`` (helped by ``what``) and ``--finite-order K``, which implies it (``pinmob analyze`` and ``scan``)."""
    p.add_argument("--finite", action="store_true", help=what)
    p.add_argument(
        "--finite-order",
        type=int,
        default=None,
        metavar="K",
        help=f"the highest order of the conditions the finite analysis checks ({ORDERS[0]}..{ORDERS[-1]}, default {ORDER}); "
        "implies --finite",
    )
