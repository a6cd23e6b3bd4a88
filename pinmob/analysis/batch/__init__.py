"""Many configurations of one mechanism at once: the platform's DoF and singularity ranks per row.

:mod:`~pinmob.analysis.batch.batch_analysis` (:func:`analyze_batch`, the choice of engine),
:mod:`~pinmob.analysis.batch.batch_kernel` (the numba kernel), :mod:`~pinmob.analysis.batch.batch_numpy`
(the same in numpy), :mod:`~pinmob.analysis.batch.batch_result` (:class:`BatchResult`),
:mod:`~pinmob.analysis.batch.motion_kernel` (the motion types, numba) and the compiled linear algebra they share
(:mod:`~pinmob.screw.jacobi`, :mod:`~pinmob.analysis.batch.small_matrices`).
"""

from pinmob.analysis.batch.batch_analysis import analyze_batch, analyze_jacobians
from pinmob.analysis.batch.batch_result import BatchResult

__all__ = ["BatchResult", "analyze_batch", "analyze_jacobians"]
