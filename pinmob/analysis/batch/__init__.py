"""Many configurations of one mechanism at once: the platform's DoF and singularity ranks per row.

:mod:`~pinmob.analysis.batch.batch_analysis` (:func:`analyze_batch`, the choice of engine),
:mod:`~pinmob.analysis.batch.batch_kernel` (the numba kernel), :mod:`~pinmob.analysis.batch.batch_numpy`
(the same in numpy) and :mod:`~pinmob.analysis.batch.batch_result` (:class:`BatchResult`).
"""

from pinmob.analysis.batch.batch_analysis import analyze_batch, analyze_jacobians
from pinmob.analysis.batch.batch_result import BatchResult

__all__ = ["BatchResult", "analyze_batch", "analyze_jacobians"]
