"""A spherical parallel robot (3-RRR, all axes through one point): three rotations about that point, animated.

Uses the built-in model '3-RRR-spherical' at its first named configuration, through
the shared main of examples/3puu_show.py.

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
    return _base.main(argv, model=MODEL, config=None)  # its first named configuration


if __name__ == "__main__":
    raise SystemExit(main())
