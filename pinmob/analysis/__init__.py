"""Analyses at a closed configuration, from the one state object to the one report.

:mod:`~pinmob.analysis.configuration` (:class:`Configuration`, the state object),
:mod:`~pinmob.analysis.configuration_choice` (the configuration asked for, by name or joint values),
:mod:`~pinmob.analysis.limbs` (limb twists), :mod:`~pinmob.analysis.mobility`
(platform mobility), :mod:`~pinmob.analysis.closure_jacobian` and
:mod:`~pinmob.analysis.closed_chain` (whole mechanism), :mod:`~pinmob.analysis.actuation`,
:mod:`~pinmob.analysis.generic` (generic ranks), :mod:`~pinmob.analysis.singularity`
and :mod:`~pinmob.analysis.singularity_analysis`, :mod:`~pinmob.analysis.paper`
(the seed paper's view), :mod:`~pinmob.analysis.modes` (assembly modes),
:mod:`~pinmob.analysis.motion_path` and :mod:`~pinmob.analysis.path_follower` (following a
motion), :mod:`~pinmob.analysis.motion_limits` (what stops it), finite versus instantaneous mobility (:mod:`~pinmob.analysis.finite`, from
:mod:`~pinmob.analysis.loop_screws`, :mod:`~pinmob.analysis.higher_order`,
:mod:`~pinmob.analysis.tangent_cone`, :mod:`~pinmob.analysis.branches`,
:mod:`~pinmob.analysis.verdicts`, :mod:`~pinmob.analysis.local_dimension`,
:mod:`~pinmob.analysis.sample_modes` and :mod:`~pinmob.analysis.reduced_equation` (where the conditions do
not decide), :mod:`~pinmob.analysis.branch_names` and :mod:`~pinmob.analysis.finite_side`),
:mod:`~pinmob.analysis.batch` (many configurations), and
:mod:`~pinmob.analysis.report` (:class:`~pinmob.analysis.report.Report`) and
:mod:`~pinmob.analysis.entry_point` (:func:`~pinmob.analysis.entry_point.analyze`, the one entry point).
"""
