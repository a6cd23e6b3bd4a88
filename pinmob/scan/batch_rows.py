"""Scan rows of many closed samples at once: one batched analysis, the single-sample one only where it decides.

A chunk's samples (:mod:`pinmob.scan.chunk`) are assembled first; then their
kinematics are computed once per sample (``computeJointJacobians`` and the
platform frame's placement) and analysed together
(:func:`pinmob.analysis.batch.batch_analysis.analyze_jacobians`: DoF, constraint, limb and
locked ranks, their singular values, the platform's free twists). A sample is
*decided* by the batch when nothing about it is singular or close to it:

* every limb has its generic twist rank, the constraint rank is the generic one
  and no motion is left with the actuators locked (``locked_dof = 0``);
* every distance to singularity (each limb's, the constraint's, the actuation's;
  the numbers of :func:`pinmob.analysis.singularity.classification.singularity`) is at
  least ``DECIDED_FACTOR`` times the near-singular band ``NEAR_FACTOR * rtol``.

Its row then has no singularity class, no singular or dependent limb and no
uncontrolled motion, its motion type is the classification of its free twists
(:func:`pinmob.screw.classify.classify_twists`, which depends on their span only)
and its figures are the batch's. Every other sample (singular, near-singular,
under-actuated, or a mechanism the batch does not cover: limbs with loops
inside them, limbs coupled by closures) gets the single-sample row
(:func:`pinmob.scan.sample.evaluate`), as do the refinements' trial points. The
rows are those of the single-sample path, the figures to round-off
(``tests/test_scan_batch.py``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.analysis import (
    NEAR_FACTOR,
    analyze_jacobians,
    generic_locked_dof,
    generic_twist_ranks,
    limbwise_obstacle,
    motion_types,
    ratio,
    tied,
)
from pinmob.assembly import POSE_COORDS, matrices_rpy, pose_vector
from pinmob.model import Mechanism, borrowed
from pinmob.scan.row_columns import ArrayRow
from pinmob.scan.unreachable import SV_COLUMNS, VERDICT_COLUMNS
from pinmob.screw import Array, Mask

#: A sample is decided by the batch when each of its distances is at least this many near-singular bands.
DECIDED_FACTOR = 2.0

#: The scan engines: ``batch`` (this module, the default) and ``single`` (every sample on its own).
ENGINES = ("batch", "single")

#: The columns of a decided sample's row, in the single-sample row's order (:func:`pinmob.scan.sample.evaluate`).
ROW_KEYS = (*POSE_COORDS, *VERDICT_COLUMNS, *SV_COLUMNS)

#: A sample's row and the distance of each question (:func:`pinmob.scan.sample.evaluate`'s numbers).
Analysed = tuple[dict[str, Any], dict[str, float]]


def batchable(mech: Mechanism) -> bool:
    """The batch can decide samples of ``mech``: a platform, actuated limbs without inner loops, none coupled."""
    return bool(
        mech.has_platform
        and mech.actuated
        and mech.limbs
        and not limbwise_obstacle(mech)
        and not any(limb.closures for limb in mech.limbs)
    )


#: Per configuration, its world joint Jacobians (6, nv) and platform placement (4, 4), when already computed.
Kinematics = list[tuple[Array, Array] | None]


def platform_kinematics(mech: Mechanism, qs: Array, known: Kinematics | None = None) -> tuple[Array, Array]:
    """(N, 6, nv) world Jacobians and (N, 6) platform poses ``[x, y, z, roll, pitch, yaw]`` of N configurations.

    ``known``: those already computed (the predictor's, :mod:`pinmob.scan.lockstep`), read instead.
    """
    model, pid = mech.model, mech.platform_id
    n = len(qs)
    pairs = [k for k in known or [] if k is not None]
    if pairs and len(pairs) == n:  # every configuration's given (the predictor closed them all): stacked at once
        full, frames = np.array([k[0] for k in pairs]), np.array([k[1] for k in pairs])
        poses = np.empty((n, 6))
        poses[:, :3] = frames[:, :3, 3]
        poses[:, 3:] = matrices_rpy(frames)
        return full, poses
    full, poses = np.empty((n, 6, model.nv)), np.empty((n, 6))
    given = [i for i, k in enumerate(known or []) if k is not None]
    if given:  # pose_vector's numbers, read off the placement matrices
        full[given] = np.array([k[0] for k in pairs])
        frames = np.array([k[1] for k in pairs])
        poses[given, :3] = frames[:, :3, 3]
        poses[given, 3:] = matrices_rpy(frames)
    others = [i for i in range(n) if known is None or known[i] is None]
    if others:  # computed here, in a pooled pin.Data
        with borrowed(model) as data:
            for i in others:
                full[i] = pin.computeJointJacobians(model, data, qs[i])
                poses[i] = pose_vector(pin.updateFramePlacement(model, data, pid))
    return full, poses


@dataclass(frozen=True)
class BatchRows:
    """The batch's analysis of a stack of N closed configurations, column by column (:func:`analyse_stack`).

    Attributes:
        decided: (N,) the batch decides the sample (module docstring); the other entries of the columns are fill.
        columns: per column of ``ROW_KEYS``, its (N,) array: float64, int64, bool, or object (text), the types the
            scan table gives those values (:meth:`pinmob.scan.results.table.ScanTable.from_rows`).
        questions: the names of the distances to singularity (each limb's, the constraint's, the actuation's).
        distances: (N, len(questions)) those distances.
    """

    decided: Mask
    columns: dict[str, np.ndarray]
    questions: tuple[str, ...]
    distances: Array

    def row(self, i: int) -> dict[str, Any]:
        """Sample i's row (a decided one), as Python values in ``ROW_KEYS``' order."""
        columns = self.columns  # text columns hold Python str (object arrays); the others numpy scalars
        return {key: columns[key][i] if columns[key].dtype == object else columns[key][i].item() for key in ROW_KEYS}

    def distances_of(self, i: int) -> dict[str, float]:
        """Sample i's distance of each question."""
        return dict(self.distance_row(i))

    def distance_row(self, i: int) -> ArrayRow:
        """:meth:`distances_of` as a row of the batch's array, made into a dict when first read."""
        return ArrayRow(self.questions, self.distances, i)

    def analysed(self, where: Sequence[int | None] | None = None) -> list[Analysed | None]:
        """Per entry of ``where`` (default: per sample, its own where decided), its row and distances, or None."""
        if where is None:
            where = [i if d else None for i, d in enumerate(self.decided.tolist())]
        return [None if i is None else (self.row(i), self.distances_of(i)) for i in where]


def analyse(
    mech: Mechanism, qs: list[Array], rtol: float, generic_rank: int, known: Kinematics | None = None
) -> list[Analysed | None]:
    """Per closed configuration, its row and distances when the batch decides it, else None (module docstring).

    ``known``: per configuration, its kinematics when already computed (:func:`platform_kinematics`).
    """
    batch = analyse_stack(mech, qs, rtol, generic_rank, known)
    return [None] * len(qs) if batch is None else batch.analysed()


def analyse_stack(
    mech: Mechanism, qs: list[Array], rtol: float, generic_rank: int, known: Kinematics | None = None
) -> BatchRows | None:
    """:func:`analyse`'s rows and distances as columns (None: no configuration, or a mechanism the batch leaves)."""
    if not qs or not batchable(mech):
        return None
    full, poses = platform_kinematics(mech, np.asarray(qs, float), known)
    res = analyze_jacobians(mech, full, poses[:, :3], rtol=rtol, singular_values=True, twists=True)
    assert res.free_twists is not None  # asked for
    g, generic = int(generic_rank), np.array(generic_twist_ranks(mech))
    rows = int(np.sum(6 - generic))  # stacked limb wrenches: the constraint singular values there are
    sv = np.where(np.arange(6) < rows, res.singular_values, np.nan)
    asv = res.actuation_singular_values
    names = [f"limb {limb.name}" for limb in mech.limbs]
    columns = [res.limb_ratio]  # the distances, column by column: distance_of of each sample's values
    if g > 0:
        names.append("constraint")
        columns.append(ratio(sv, g)[:, None])
    names.append("actuation")
    columns.append(ratio(asv, 6 - generic_locked_dof(mech, g))[:, None])
    distances = np.concatenate(columns, axis=1)
    distance = distances.min(axis=1)
    decided = (
        (res.limb_twist_rank == generic).all(axis=1)
        & (res.constraint_rank == g)
        & (res.locked_dof == 0)
        & np.isfinite(distances).all(axis=1)
        & (distance >= DECIDED_FACTOR * NEAR_FACTOR * rtol)
    )
    closest = np.argmax(tied(distances, distance[:, None]), axis=1)  # Singularity.closest_all[0]
    which = np.flatnonzero(decided)
    n = len(qs)
    motion, closest_name = np.full(n, "", object), np.array(names, object)[closest]
    motion[which] = motion_types(res.free_twists[which], res.dof[which], mech.length_scale, rtol, res.engine)
    values: list[np.ndarray] = [*poses.T, np.ones(n, bool), res.dof.astype(np.int64), motion,
                                np.full(n, g, np.int64), np.zeros(n, np.int64), np.full(n, "none", object),
                                np.zeros(n, bool), closest_name, *(np.full(n, "", object) for _ in range(3)), distance,
                                *sv.T, *asv.T]  # fmt: skip
    out = dict(zip(ROW_KEYS, (np.ascontiguousarray(v) for v in values), strict=True))
    return BatchRows(decided, out, tuple(names), distances)
