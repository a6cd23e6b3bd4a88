"""Show the seed paper's 3-PUU at its flat configuration (beta = 0), free motions animated.

At 'flat' the analysis finds 1T1R: the platform can rise along z with all three
sliders (a finite motion) and has an instantaneous rotation about z that cannot
be followed any finite amount (the links are exactly R - r long). The clip
'T1 z' shows the first; 'R1 z' stays still and the script says why.

Run::

    python examples/3puu_show.py                 # live: starts a meshcat server, prints its URL
    python examples/3puu_show.py --html flat.html  # a self-contained file, no server
"""

from __future__ import annotations

import argparse
import sys

import pinmob
import pinmob.assembly
import pinmob.viewer


def main(
    argv: list[str] | None = None,
    model: str = "3-PUU-flat",
    config: str | None = "flat",
    actuated: dict[str, float] | None = None,
) -> int:
    """Analyse ``model`` at ``config`` (default: its first named configuration) and show it.

    With ``actuated`` (joint values by name), the configuration shown is the one
    those actuated values close to from ``config`` (forward kinematics).
    """
    models = pinmob.builtin_models()
    if model not in models:
        print(f"error: this pinmob has no built-in model {model!r}; it has: {', '.join(models)}", file=sys.stderr)
        return 2
    config = config or next(iter(pinmob.load(model).configurations))
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--html", help="write this HTML file instead of starting a server")
    parser.add_argument("--force", action="store_true", help="overwrite the HTML file if it exists")
    parser.add_argument("--config", default=config, help=f"named configuration (default {config!r})")
    args = parser.parse_args(argv)
    try:
        mech = pinmob.load(model)
        q = pinmob.closed_configuration(mech, args.config)
        if actuated:
            q = pinmob.assembly.assemble_joints(mech, actuated, q)
        mob = pinmob.analyze(mech, q, configuration=args.config if not actuated else None)
        print(mob)
        if args.html:
            scene = pinmob.viewer.export_html(mech, q, args.html, mob, overwrite=args.force)
            print(f"wrote {scene.html}: clips {', '.join(scene.clips)}")
        else:
            scene = pinmob.viewer.show(mech, q, mob)
            print(
                f"open {scene.url}: clips {', '.join(scene.clips)} "
                f"(the server runs until you kill pid {scene.server.pid})"
            )
    except pinmob.PinmobError as exc:
        print(f"{model}: error: {exc}", file=sys.stderr)
        return 2
    for note in scene.notes:
        print(f"note: {note}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
