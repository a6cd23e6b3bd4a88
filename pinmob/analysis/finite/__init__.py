"""Finite versus instantaneous mobility: does each free motion of the platform survive a finite step?

:mod:`~pinmob.analysis.finite.finite_mobility` (:class:`FiniteMobility`, :func:`finite_mobility`) decides,
from :mod:`~pinmob.analysis.finite.loop_screws` (the loops' relative screws),
:mod:`~pinmob.analysis.finite.higher_order` (the order conditions),
:mod:`~pinmob.analysis.finite.coupling_rows`
(polynomial couplings, and the coordinates' Taylor series), :mod:`~pinmob.analysis.finite.tangent_cone` (the cone of second-order solutions),
:mod:`~pinmob.analysis.finite.branches` (the branches through a
singular point, and a branch point in words), :mod:`~pinmob.analysis.finite.verdicts` (one verdict per motion),
:mod:`~pinmob.analysis.finite.local_dimension` and :mod:`~pinmob.analysis.finite.sample_modes` (where the
conditions do not decide: closed samples, and the reduced equation along a single motion),
:mod:`~pinmob.analysis.finite.motion_tracing` (each motion followed), and
:mod:`~pinmob.analysis.finite.finite_side` (the analysis of one side: the mechanism free, or with joints held) or,
where a coupling's higher derivatives are not written, :mod:`~pinmob.analysis.finite.sampled_side` (closed samples
alone).
"""
