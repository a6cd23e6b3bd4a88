"""A spherical parallel robot (3-RRR, all axes through one point): three rotations about that point, animated.

Uses the built-in model '3-RRR-spherical' through the shared main of examples/3puu_show.py,
at a generic configuration: the actuated joints at A_r1 = 1.07, B_r1 = 0.36, C_r1 = 0.2 rad
(closed from 'generic'). There every limb is far from its stretched (serially singular)
pose (smallest singular value of each limb's angular Jacobian > 0.26; at 'generic' limb A's
is 0.05), so each clip turns the platform about its own axis through the centre. A limb i
reaches a platform axis v_i only while the angle between v_i and its base axis u_i is at
most the sum of its two link angles; three of the six half-clips reach that edge of the
workspace within the default 0.35 rad (limb B stretched at +0.211 rad about x, C at -0.153
rad about x, A at -0.308 rad about y), stop just before it, and the script prints a note
saying so; R2 y forwards and R3 z both ways go the whole 0.35 rad.

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
