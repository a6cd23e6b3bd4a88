"""``pinmob models``: the built-in mechanisms."""

from __future__ import annotations

import argparse
import json
from typing import Any

from pinmob.io.builtin import builtin_models
from pinmob.io.loader import load


def run(args: argparse.Namespace) -> int:
    """``pinmob models``: the built-in mechanisms, their configurations and expected mobility."""
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
