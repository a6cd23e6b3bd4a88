"""Screw algebra: twists, wrenches, reciprocity, the one rank decision rule, classification.

Pure numpy (LAPACK through numpy's own gufuncs; numba for :mod:`~pinmob.screw.jacobi` only); no pinocchio, no SciPy.
Submodules: :mod:`~pinmob.screw.algebra` (conventions, shifts, unit scaling),
:mod:`~pinmob.screw.rank` (:func:`decide_rank`, reciprocal bases, ``rtol`` checks),
:mod:`~pinmob.screw.bases` (canonical directions, labels, subspace gaps),
:mod:`~pinmob.screw.classify` (translations, rotations and screws; couples, forces and wrenches),
:mod:`~pinmob.screw.jacobi` (one-sided Jacobi SVDs of small matrices, compiled: its names import numba when
first read, so that ``import pinmob`` imports no numba).
"""

from typing import TYPE_CHECKING

from pinmob.lazy_names import lazy_getattr
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

if TYPE_CHECKING:
    from pinmob.screw.jacobi import column_rank, complete, orthogonalize, rotation, span

_LAZY = dict.fromkeys(("column_rank", "complete", "orthogonalize", "rotation", "span"), "pinmob.screw.jacobi")

#: A name of :data:`_LAZY`, its module imported when it is first read (PEP 562).
__getattr__ = lazy_getattr(__name__, _LAZY)

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
    "column_rank",
    "complete",
    "cross_columns",
    "decide_rank",
    "decide_ranks",
    "decision",
    "label",
    "motion_subgroup",
    "motion_type",
    "motion_type_of_orthonormal",
    "orthogonalize",
    "principal_screws",
    "rank_rule",
    "rank_rule_rows",
    "reciprocal_product",
    "reciprocal_twists",
    "reciprocal_wrenches",
    "rotate",
    "rotation",
    "shift_twists",
    "shift_wrenches",
    "singular_values",
    "span",
    "subspace_gap",
    "svd",
    "twist_from_paper",
    "twist_scaling",
    "twist_to_paper",
    "wrench_scaling",
]
