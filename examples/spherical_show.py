"""A spherical parallel robot (3-RRR, all axes through one point): three rotations about that point, animated.

Uses the built-in model '3-RRR-spherical' through the shared main of examples/3puu_show.py,
at a generic configuration: the actuated joints at A_r1 = 1.07, B_r1 = 0.36, C_r1 = 0.2 rad
(closed from 'generic'). There every limb is far from its stretched (serially singular)
pose (smallest singular value of each limb's angular Jacobian > 0.26; at 'generic' limb A's
is 0.05), so the three rotations about the centre are followed without drifting.

Run::

    python examples/spherical_show.py --html spherical.html
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

MODEL = "3-RRR-spherical"

_spec = importlib.util.spec_from_file_location("show_3puu", Path(__file__).with_name("3puu_show.py"))
_base = importlib.util.module_from_spec(_spec)  # type: ignore[arg-type]
_spec.loader.exec_module(_base)  # type: ignore[union-attr]


def main(argv: list[str] | None = None) -> int:
    return _base.main(argv, model=MODEL, config="generic", actuated={"A_r1": 1.07, "B_r1": 0.36, "C_r1": 0.2})


if __name__ == "__main__":
    raise SystemExit(main())
