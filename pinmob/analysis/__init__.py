"""Analyses at a closed configuration, from the one state object to the one report.

:mod:`~pinmob.analysis.configuration` (:class:`Configuration`, the state object),
:mod:`~pinmob.analysis.limbs` (limb twists), :mod:`~pinmob.analysis.mobility`
(platform mobility), :mod:`~pinmob.analysis.closure_jacobian` and
:mod:`~pinmob.analysis.closed_chain` (whole mechanism), :mod:`~pinmob.analysis.actuation`,
:mod:`~pinmob.analysis.generic` (generic ranks), :mod:`~pinmob.analysis.singularity`
and :mod:`~pinmob.analysis.singularity_analysis`, :mod:`~pinmob.analysis.paper`
(the seed paper's view), :mod:`~pinmob.analysis.modes` (assembly modes),
:mod:`~pinmob.analysis.motion_path` (following a motion), :mod:`~pinmob.analysis.motion_limits`
(what stops it), :mod:`~pinmob.analysis.batch`
(many configurations), and :mod:`~pinmob.analysis.report` (:class:`Report` and
:func:`analyze`, the one entry point).
"""
