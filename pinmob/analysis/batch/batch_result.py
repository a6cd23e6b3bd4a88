"""The result of :func:`pinmob.analysis.batch.batch_analysis.analyze_batch`: per-configuration numbers of N configurations."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from pinmob.frozen import ReadOnlyArrays
from pinmob.screw import Array

#: Integer array (ranks, DoF).
Ints = NDArray[np.int64]


@dataclass(frozen=True)
class BatchResult(ReadOnlyArrays):
    """Per-configuration results of :func:`analyze_batch` (N configurations, k limbs).

    Attributes:
        dof: (N,) platform DoF, ``6 - constraint_rank``.
        constraint_rank: (N,) rank of the stacked limb wrenches.
        singular_values: (N, 6) of the stacked dimensionless limb wrenches (NaN unless asked for).
        limb_twist_rank: (N, k) rank of each limb's joint screws.
        limb_ratio: (N, k) ``sigma_r / sigma_1`` of each limb's unit-normalised dimensionless joint screws, r
            its generic rank: the limb distances of :func:`pinmob.analyze_singularity` (NaN unless asked for).
        locked_dof: (N,) platform DoF with the actuated joints locked.
        actuation_singular_values: (N, 6) of the stacked dimensionless locked-limb wrenches (NaN unless asked for).
        engine: ``numba`` or ``numpy`` (:func:`analyze_batch`); limbs with loops: ``per configuration``.
        free_twists: (N, 6, 6) an orthonormal basis of the platform's free dimensionless twists ``[v / L; w]``
            in the first ``dof`` columns, NaN in the others: the span :func:`pinmob.analyze` classifies (None
            unless asked for).
    """

    dof: Ints
    constraint_rank: Ints
    singular_values: Array
    limb_twist_rank: Ints
    limb_ratio: Array
    locked_dof: Ints
    actuation_singular_values: Array
    engine: str = "numpy"
    free_twists: Array | None = None
