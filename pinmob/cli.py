"""Command line: ``pinmob models``, ``pinmob analyze``.

Errors are printed as one line on stderr (``pinmob: error: ...``) with exit
status 2, never with a traceback.
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from collections.abc import Callable, Sequence

from .exceptions import PinmobError

COMMANDS: dict[str, Callable[[argparse.Namespace], int]] = {}


def command(name: str) -> Callable[[Callable[[argparse.Namespace], int]], Callable[[argparse.Namespace], int]]:
    def deco(fn: Callable[[argparse.Namespace], int]) -> Callable[[argparse.Namespace], int]:
        COMMANDS[name] = fn
        return fn

    return deco


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="pinmob", description="Platform mobility of parallel and closed-chain robots.")
    sub = parser.add_subparsers(dest="command", required=True)

    p = sub.add_parser("models", help="list the built-in mechanisms")
    p.add_argument("--json", action="store_true", help="print JSON")

    p = sub.add_parser("analyze", help="mobility of the platform at a configuration")
    p.add_argument("mechanism", help="built-in model name or path to a mechanism file")
    p.add_argument("--config", "-c", help="named configuration (default: the first one in the file)")
    p.add_argument("--json", action="store_true", help="print the result as JSON")
    p.add_argument("--paper-view", action="store_true", help="also show the seed paper's view: generic limb wrenches carried to the configuration")
    p.add_argument("--rtol", type=float, default=None, help="relative tolerance of rank decisions (default 1e-6)")
    p.add_argument("--frame", action="append", default=None, help="end frame whose motion is reported (repeatable; default: the platform, else the tree's free leaf bodies)")
    p.add_argument("--relax", action="store_true", help="if the loops cannot be closed as declared, relax the over-constraining closures to 3d and say which")
    p.add_argument("--restarts", type=int, default=20, help="random restarts when searching a closed configuration (default 20)")
    p.add_argument("--search-actuators", type=int, default=None, metavar="K", help="also list every valid set of K actuated joints (exhaustive)")
    return parser


@command("models")
def _models(args: argparse.Namespace) -> int:
    from .mechanism_file import builtin_models, load

    rows = []
    for name in builtin_models():
        mech = load(name)
        rows.append(
            {
                "name": name,
                "limbs": [{"name": b.name, "joints": list(b.joints)} for b in mech.limbs],
                "configurations": {
                    c: {"expected": ({"dof": mech.expected[c].dof, "motion_type": mech.expected[c].motion_type} if c in mech.expected else None)}
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
    from .constraints import analyze_mechanism
    from .exceptions import ConfigurationError
    from .mechanism_file import load
    from .mobility import analyze, paper_view
    from .report import format_expectation
    from .screw import RTOL

    mech = load(args.mechanism)
    config = args.config
    rtol = RTOL if args.rtol is None else args.rtol
    if not 0 < rtol < 1:
        raise ConfigurationError(f"--rtol must be in (0, 1), got {rtol}")
    if config is None and not mech.configurations:
        return _analyze_closed_chain(args, mech, rtol)
    if config is None:
        config = next(iter(mech.configurations))
    q = mech.configuration(config)
    if not mech.limbs:
        return _analyze_closed_chain(args, mech, rtol, q, config)
    mob = analyze(mech, q, configuration=config, rtol=rtol)
    mm = analyze_mechanism(mech, q, configuration=config, frames=args.frame, rtol=rtol)
    paper = paper_view(mech, config, rtol=rtol) if args.paper_view else None
    if args.json:
        out = mob.to_dict()
        out.update({k: v for k, v in mm.to_dict().items() if k in MECHANISM_KEYS})
        if config in mech.expected:
            exp = mech.expected[config]
            out["expected"] = {"dof": exp.dof, "motion_type": exp.motion_type, "source": exp.source, "agrees": exp.dof == mob.dof and exp.motion_type == mob.motion_type}
        if paper is not None:
            out["paper_view"] = paper.to_dict()
        print(json.dumps(out, indent=2, allow_nan=False))
        return 0
    print(mob)
    if config in mech.expected:
        print(format_expectation(mob, mech.expected[config]))
    print()
    print(mm)
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


#: keys of the whole-mechanism result added to the JSON of a limb-and-platform analysis
MECHANISM_KEYS = (
    "nv", "closure_rows", "closure_rank", "mechanism_dof", "idle_dof", "idle_joints", "redundant_constraints",
    "redundant_by_closure", "grubler", "actuation", "closures", "end_frames", "frames",
)


def _analyze_closed_chain(args: argparse.Namespace, mech: object, rtol: float, q: object = None, config: str | None = None) -> int:
    """``pinmob analyze`` for a mechanism without limbs (Extended URDF, MJCF, TOML closures only)."""
    from .closure import ClosureError, find_closed, find_closed_relaxed, unclosable
    from .constraints import actuator_sets, analyze_mechanism

    relaxed: tuple[str, ...] = ()
    method = f"named configuration {config!r}"
    if q is None:
        if args.relax:
            mech, found, relaxed = find_closed_relaxed(mech, restarts=args.restarts)  # type: ignore[arg-type]
        else:
            try:
                found = find_closed(mech, restarts=args.restarts)  # type: ignore[arg-type]
            except ClosureError as exc:
                bad = unclosable(mech)  # type: ignore[arg-type]
                hint = f"closures that cannot close even on their own: {', '.join(bad)}. " if bad else ""
                raise ClosureError(
                    f"{mech.name!r} (as declared) could not be closed from the neutral configuration nor {args.restarts} random restarts. "  # type: ignore[attr-defined]
                    f"{hint}Rerun with --relax to turn the over-constraining closures into 3d (ball) closures. Largest residual "
                    f"of the best attempt: {max(max(r) for r in exc.residuals.values()):.2e} (m or rad)",
                    exc.residuals,
                ) from None
        q, method = found.q, found.method
        residual = found.residual
    else:
        residual = 0.0
    mm = analyze_mechanism(mech, q, configuration=config, frames=args.frame, rtol=rtol)  # type: ignore[arg-type]
    sets = actuator_sets(mech, q, args.search_actuators, frames=args.frame, rtol=rtol) if args.search_actuators else None  # type: ignore[arg-type]
    if args.json:
        out = mm.to_dict()
        out["closed_configuration"] = {"method": method, "residual": residual, "relaxed_closures": list(relaxed), "q": [float(x) for x in q]}  # type: ignore[union-attr]
        if mech.has_platform and mm.frames:  # type: ignore[attr-defined]
            out["platform"] = mm.frames[0].to_dict()
        if sets is not None:
            out["valid_actuator_sets"] = [list(x) for x in sets]
        print(json.dumps(out, indent=2, allow_nan=False))
        return 0
    print(f"closed configuration: {method} (largest residual {residual:.1e})")
    if relaxed:
        print(f"relaxed to 3d (the file's closures cannot all close as declared): {', '.join(relaxed)}")
    print(mm)
    if sets is not None:
        print(f"valid sets of {args.search_actuators} actuated joints: {len(sets)}")
        for x in sets[:50]:
            print("  " + ", ".join(x))
        if len(sets) > 50:
            print(f"  ... ({len(sets) - 50} more)")
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
