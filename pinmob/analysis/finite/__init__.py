"""Finite versus instantaneous mobility: does each free motion of the platform survive a finite step?

:mod:`~pinmob.analysis.finite.finite_mobility` (:class:`FiniteMobility`, :func:`finite_mobility`) decides,
from :mod:`~pinmob.analysis.finite.loop_screws` (the loops' relative screws),
:mod:`~pinmob.analysis.finite.higher_order` (the order conditions),
:mod:`~pinmob.analysis.finite.coupling_rows` and :mod:`~pinmob.analysis.finite.coordinate_series`
(polynomial couplings), :mod:`~pinmob.analysis.finite.tangent_cone` (the cone of second-order solutions),
:mod:`~pinmob.analysis.finite.branches` and :mod:`~pinmob.analysis.finite.branch_names` (the branches through a
singular point), :mod:`~pinmob.analysis.finite.verdicts` (one verdict per motion),
:mod:`~pinmob.analysis.finite.local_dimension`, :mod:`~pinmob.analysis.finite.sample_modes` and
:mod:`~pinmob.analysis.finite.reduced_equation` (where the conditions do not decide),
:mod:`~pinmob.analysis.finite.motion_tracing` (each motion followed), and
:mod:`~pinmob.analysis.finite.finite_side` (the analysis of one side: the mechanism free, or with joints held) or,
where a coupling's higher derivatives are not written, :mod:`~pinmob.analysis.finite.sampled_side` (closed samples
alone).
"""
