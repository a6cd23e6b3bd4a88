"""``pinmob models``: the built-in mechanisms."""

from __future__ import annotations

import argparse
import json
from typing import Any

from pinmob.io import builtin_models, load
from pinmob.progress import Bar, step


def run(args: argparse.Namespace) -> int:
    """``pinmob models``: the built-in mechanisms, their configurations and expected mobility."""
    names = builtin_models()
    with step("loading the built-in models", total=len(names)) as bar:
        rows = [_row(name, bar) for name in names]

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


def _row(name: str, bar: Bar) -> dict[str, Any]:
    """One built-in model as a plain dictionary (limbs, closures, configurations, description)."""
    bar.set_postfix_str(name)
    mech = load(name)
    row = {
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
    bar.update()
    return row
