"""Definitions of the built-in models, written to ``models/`` by the builder.

Regenerate every built-in model with::

    python -m pinmob.catalog models

A test fails when a file in ``models/`` is not equivalent to what this package writes
(:mod:`.freshness`: the same up to round-off, angles modulo 2 pi).
One module per family: :mod:`.puu` (the seed paper's 3-PUU), :mod:`.tripods`
(3-UPU, 3-RPS, 3-PRS), :mod:`.gough_stewart` (6-UPS), :mod:`.delta` (Delta,
4-RUU), :mod:`.rrr` (3-RRR, 3-PRRR), :mod:`.linkages` (five-bar, Bennett,
Sarrus), :mod:`.arms` (three UR5 arms).
"""

from . import arms, delta, gough_stewart, linkages, puu, rrr, tripods  # noqa: F401  (register the models)
from .families import FAMILIES, Family, family
from .linkages import bennett_frames, bennett_theta2, dh
from .puu import three_puu
from .registry import CATALOG, Definition, check_target, checkout_models, main, register, write_all

__all__ = [
    "CATALOG",
    "Definition",
    "FAMILIES",
    "Family",
    "bennett_frames",
    "bennett_theta2",
    "check_target",
    "checkout_models",
    "dh",
    "family",
    "main",
    "register",
    "three_puu",
    "write_all",
]
