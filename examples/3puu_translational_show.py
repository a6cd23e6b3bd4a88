"""A translational parallel robot: the 3-PUU at a generic configuration (3T), each translation animated.

The three clips 'T1 x', 'T2 y', 'T3 z' move the platform along each axis
while the three limbs follow; the platform never turns.

Run::

    python examples/3puu_translational_show.py --html 3puu.html
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

_spec = importlib.util.spec_from_file_location("show_3puu", Path(__file__).with_name("3puu_show.py"))
_base = importlib.util.module_from_spec(_spec)  # type: ignore[arg-type]
_spec.loader.exec_module(_base)  # type: ignore[union-attr]


def main(argv: list[str] | None = None) -> int:
    return _base.main(argv, model="3-PUU", config="generic")


if __name__ == "__main__":
    raise SystemExit(main())
