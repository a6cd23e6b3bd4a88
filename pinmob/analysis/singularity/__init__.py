"""Singularities at a configuration: the result and the function that computes it.

:mod:`~pinmob.analysis.singularity.result` (:class:`Singularity`: the classes, the limbs and joints that
take part, the distances) and :mod:`~pinmob.analysis.singularity.classification` (:func:`singularity`).
"""

from pinmob.analysis.singularity.classification import singularity, singularity_from_twists
from pinmob.analysis.singularity.result import Singularity

__all__ = ["Singularity", "singularity", "singularity_from_twists"]
