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
from pinmob.screw.bases import AXIS_NAMES, axis_label, canonical_basis, canonical_directions, clean, subspace_gap
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
from pinmob.screw.lie import LoopSystem
from pinmob.screw.motion_label import label, motion_type_of_orthonormal
from pinmob.screw.rank import (
    AMBIGUOUS_MARGIN,
    RTOL,
    RankDecision,
    ambiguity,
    check_rtol,
    decide_rank,
    decide_ranks,
    decision,
    rank_rule,
    rank_rule_rows,
    reciprocal_twists,
    reciprocal_wrenches,
    singular_values,
    svd,
)
from pinmob.screw.subgroup import MotionSubgroup, motion_subgroup

__all__ = [
    "AMBIGUOUS_MARGIN",
    "AXIS_NAMES",
    "Array",
    "LoopSystem",
    "Mask",
    "MotionKind",
    "MotionSubgroup",
    "RTOL",
    "RankDecision",
    "Screw",
    "ScrewSystem",
    "WrenchKind",
    "ambiguity",
    "axis_label",
    "canonical_basis",
    "canonical_directions",
    "check_rtol",
    "classify_twists",
    "classify_wrenches",
    "clean",
    "cross_columns",
    "decide_rank",
    "decide_ranks",
    "decision",
    "label",
    "motion_subgroup",
    "motion_type",
    "motion_type_of_orthonormal",
    "principal_screws",
    "rank_rule",
    "rank_rule_rows",
    "reciprocal_product",
    "reciprocal_twists",
    "reciprocal_wrenches",
    "rotate",
    "shift_twists",
    "shift_wrenches",
    "singular_values",
    "subspace_gap",
    "svd",
    "twist_from_paper",
    "twist_scaling",
    "twist_to_paper",
    "wrench_scaling",
]
