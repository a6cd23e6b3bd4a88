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
