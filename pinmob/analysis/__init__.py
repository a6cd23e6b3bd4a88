"""Analyses at a closed configuration, from the one state object to the one report.

At this level: :mod:`~pinmob.analysis.configuration` (:class:`Configuration`, the state object),
:mod:`~pinmob.analysis.configuration_choice` (the configuration asked for, by name or joint values),
:mod:`~pinmob.analysis.limbs` (limb twists), :mod:`~pinmob.analysis.mobility` (platform mobility),
:mod:`~pinmob.analysis.motion` (the classified motions and constraints), :mod:`~pinmob.analysis.generic`
(generic ranks), :mod:`~pinmob.analysis.ambiguity` (ranks the tolerance does not decide),
:mod:`~pinmob.analysis.paper` (the seed paper's view), :mod:`~pinmob.analysis.modes` (assembly modes),
:mod:`~pinmob.analysis.report` (:class:`~pinmob.analysis.report.Report`, with
:mod:`~pinmob.analysis.report_html`, :mod:`~pinmob.analysis.summary` and :mod:`~pinmob.analysis.expectation`),
:mod:`~pinmob.analysis.entry_point` (:func:`~pinmob.analysis.entry_point.analyze`, the one entry point) and
:mod:`~pinmob.analysis.shortcuts` (one part of the report at a time).

Subpackages, one concept each: :mod:`pinmob.analysis.chain` (the whole closed chain: closure Jacobian,
mechanism mobility, redundancy, actuation), :mod:`pinmob.analysis.singularity` (the singularity result and
its function), :mod:`pinmob.analysis.finite` (finite versus instantaneous mobility),
:mod:`pinmob.analysis.follow` (following a motion, and what stops it) and :mod:`pinmob.analysis.batch` (many
configurations at once).
"""

from typing import TYPE_CHECKING

from pinmob.analysis.batch.batch_analysis import analyze_jacobians, motion_types
from pinmob.analysis.chain.actuation import Actuation, actuator_sets
from pinmob.analysis.chain.closed_chain import closed_chain, frame_rows
from pinmob.analysis.chain.closure_jacobian_twists import closure_jacobian_twists
from pinmob.analysis.chain.mechanism_mobility import (
    ClosureRank,
    FrameMobility,
    MechanismMobility,
    frame_mobility,
    mechanism_mobility,
)
from pinmob.analysis.configuration import Configuration, as_configuration, parked
from pinmob.analysis.entry_point import analyze, asked_configuration
from pinmob.analysis.finite.higher_order import ORDER, ORDERS, check_order
from pinmob.analysis.fixed_closures import FixCheck, check_fixed, chosen_proposal, fix_closures, minimal_closures
from pinmob.analysis.follow import STEPS as FOLLOW_STEPS
from pinmob.analysis.generic import (
    generic_configurations,
    generic_constraint_rank,
    generic_states,
    generic_twist_ranks,
)
from pinmob.analysis.limbs import LimbMobility, limbwise_obstacle
from pinmob.analysis.minimal import MinimalClosure, MinimalClosures
from pinmob.analysis.minimal.proposal import FIX_HINT, describe
from pinmob.analysis.mobility import Constraint, Mobility, Motion, platform_mobility
from pinmob.analysis.modes import assembly_modes
from pinmob.analysis.motion import KIND_WORDS, Method, View, vector
from pinmob.analysis.report import Report
from pinmob.analysis.report_parts import REPORT_PARTS, part_keywords
from pinmob.analysis.shortcuts import analyze_mechanism, analyze_singularity, paper_view
from pinmob.analysis.singularity.classification import require_platform
from pinmob.analysis.singularity.result import (
    NEAR_FACTOR,
    Singularity,
    distance_of,
    generic_locked_dof,
    padded,
    ratio,
    tied,
)
from pinmob.lazy_names import lazy_getattr

if TYPE_CHECKING:  # the finite analysis and motion following load when first used (see _LAZY)
    from pinmob.analysis.finite.branches import branch_point_name
    from pinmob.analysis.finite.finite_mobility import FiniteMobility, finite_mobility
    from pinmob.analysis.finite.loop_screws import check_joints
    from pinmob.analysis.finite.verdicts import MotionVerdict, Verdict
    from pinmob.analysis.follow.motion_path import MotionPath, follow_motion

#: the names whose modules load when first read: the finite analysis and motion following are not part of
#: ``import pinmob`` nor of an analysis without ``finite=True`` (tests/test_fast_paths.py)
_LAZY = {
    "branch_point_name": "pinmob.analysis.finite.branches",
    "FiniteMobility": "pinmob.analysis.finite.finite_mobility",
    "finite_mobility": "pinmob.analysis.finite.finite_mobility",
    "check_joints": "pinmob.analysis.finite.loop_screws",
    "MotionVerdict": "pinmob.analysis.finite.verdicts",
    "Verdict": "pinmob.analysis.finite.verdicts",
    "MotionPath": "pinmob.analysis.follow.motion_path",
    "follow_motion": "pinmob.analysis.follow.motion_path",
}


#: A name of :data:`_LAZY`, its module imported when it is first read (PEP 562).
__getattr__ = lazy_getattr(__name__, _LAZY)


__all__ = [
    "FIX_HINT",
    "FOLLOW_STEPS",
    "Actuation",
    "ClosureRank",
    "Configuration",
    "Constraint",
    "FiniteMobility",
    "FixCheck",
    "FrameMobility",
    "KIND_WORDS",
    "LimbMobility",
    "MechanismMobility",
    "Method",
    "MinimalClosure",
    "MinimalClosures",
    "Mobility",
    "Motion",
    "MotionPath",
    "MotionVerdict",
    "NEAR_FACTOR",
    "ORDER",
    "ORDERS",
    "REPORT_PARTS",
    "Report",
    "Singularity",
    "Verdict",
    "View",
    "actuator_sets",
    "analyze",
    "analyze_jacobians",
    "analyze_mechanism",
    "analyze_singularity",
    "as_configuration",
    "asked_configuration",
    "assembly_modes",
    "branch_point_name",
    "check_fixed",
    "check_joints",
    "check_order",
    "chosen_proposal",
    "closed_chain",
    "closure_jacobian_twists",
    "describe",
    "distance_of",
    "finite_mobility",
    "fix_closures",
    "follow_motion",
    "frame_mobility",
    "frame_rows",
    "generic_configurations",
    "generic_states",
    "generic_constraint_rank",
    "generic_locked_dof",
    "generic_twist_ranks",
    "limbwise_obstacle",
    "mechanism_mobility",
    "minimal_closures",
    "motion_types",
    "padded",
    "parked",
    "paper_view",
    "part_keywords",
    "platform_mobility",
    "ratio",
    "tied",
    "require_platform",
    "vector",
]
