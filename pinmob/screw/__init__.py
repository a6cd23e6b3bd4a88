"""Screw algebra: twists, wrenches, reciprocity, the one rank decision rule, classification.

Pure numpy (LAPACK through numpy's own gufuncs); no pinocchio, no SciPy.
Submodules: :mod:`~pinmob.screw.algebra` (conventions, shifts, unit scaling),
:mod:`~pinmob.screw.rank` (:func:`decide_rank`, reciprocal bases, ``rtol`` checks),
:mod:`~pinmob.screw.bases` (canonical directions, labels, subspace gaps),
:mod:`~pinmob.screw.classify` (translations, rotations and screws; couples, forces and wrenches).
"""

from pinmob.screw.algebra import (
    Array,
    Mask,
    cross_columns,
    reciprocal_product,
    rotate,
    shift_twists,
    shift_wrenches,
    twist_from_paper,
    twist_scaling,
    twist_to_paper,
    wrench_scaling,
)
from pinmob.screw.bases import AXIS_NAMES, axis_label, canonical_directions, clean, subspace_gap
from pinmob.screw.classify import (
    MotionKind,
    Screw,
    ScrewSystem,
    WrenchKind,
    classify_twists,
    classify_wrenches,
    motion_type,
    principal_screws,
)
from pinmob.screw.rank import (
    RTOL,
    RankDecision,
    check_rtol,
    decide_rank,
    reciprocal_twists,
    reciprocal_wrenches,
    svd,
)

__all__ = [
    "AXIS_NAMES",
    "RTOL",
    "Array",
    "Mask",
    "MotionKind",
    "RankDecision",
    "Screw",
    "ScrewSystem",
    "WrenchKind",
    "axis_label",
    "canonical_directions",
    "check_rtol",
    "classify_twists",
    "classify_wrenches",
    "clean",
    "cross_columns",
    "decide_rank",
    "motion_type",
    "principal_screws",
    "reciprocal_product",
    "reciprocal_twists",
    "reciprocal_wrenches",
    "rotate",
    "shift_twists",
    "shift_wrenches",
    "subspace_gap",
    "svd",
    "twist_from_paper",
    "twist_scaling",
    "twist_to_paper",
    "wrench_scaling",
]
