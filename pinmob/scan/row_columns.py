"""A scan's rows column-wise: the joint values and the joints outside their limits of many samples at once.

What :func:`pinmob.scan.chain_scan.joint_row` and :func:`pinmob.model.joints.outside_limits` give per configuration, for
the samples a batch assembled (:meth:`pinmob.scan.chunk._Chunk.done`), with numpy over the whole stack: the same
values and tuples. A group of chunks (:func:`pinmob.scan.lockstep.run_group`) gives its rows as :class:`GroupRows`:
row dicts, and the rows the batch decided as :class:`BatchRow` entries whose verdicts stay in the batch's columns
(:class:`~pinmob.scan.batch_rows.BatchRows`) until the table is made (:meth:`GroupRows.table`: the table of the row
dicts, :meth:`GroupRows.dicts`, without making them).
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.model import Mechanism, outside_limits
from pinmob.scan.chain_scan import joint_coordinates, joint_row
from pinmob.screw import Array


def joint_rows(
    mech: Mechanism, joints: tuple[str, ...], qs: list[Array | None], targets: list[dict[str, float] | None]
) -> list[dict[str, float] | None]:
    """:func:`~pinmob.scan.chain_scan.joint_row` of each configuration of ``qs`` with its ``targets`` (None: q None).

    Read column-wise, at once, when each joint has one coordinate.
    """
    closed = [q for q in qs if q is not None]
    columns, where = joint_coordinates(mech.model, tuple(joints), mech.model.nq)
    if where is None or not closed:
        return [None if q is None else joint_row(mech, joints, q, t) for q, t in zip(qs, targets)]
    rows = iter(np.asarray(closed, float)[:, list(where)].tolist())
    return [None if q is None else dict(zip(columns, next(rows))) for q in qs]


def limits_of(model: pin.Model, qs: list[Array | None], tol: float = 1e-9) -> list[tuple[str, ...] | None]:
    """:func:`~pinmob.model.joints.outside_limits` of each configuration of ``qs`` (None: q None).

    Every coordinate of every configuration checked at once; that function called only for the configurations with
    a coordinate outside its limits (lower < upper), so the same tuples.
    """
    closed = [q for q in qs if q is not None]
    if not closed:
        return [None] * len(qs)
    lower, upper = model.lowerPositionLimit, model.upperPositionLimit
    x = np.asarray(closed, float)
    flagged = iter(((lower < upper) & ((x < lower - tol) | (x > upper + tol))).any(axis=1).tolist())
    return [None if q is None else outside_limits(model, q, tol) if next(flagged) else () for q in qs]


class ArrayRow(Mapping[str, float]):
    """Row ``at`` of a table of named columns (``names``, (N, K) ``table``) as a mapping: a dict when first read.

    A sample's joint values (:func:`values_and_limits`) or its distances to singularity
    (:meth:`pinmob.scan.batch_rows.BatchRows.distances_of`) without a dict a row: a group's table reads the joint
    values of the batch's rows as columns (:meth:`pinmob.scan.group_rows.GroupRows.table`), and most samples'
    distances are only screened on the batch's array (:func:`pinmob.scan.chunk.to_refine`).
    """

    __slots__ = ("names", "table", "at", "_dict")

    def __init__(self, names: tuple[str, ...], table: Array, at: int) -> None:
        self.names, self.table, self.at = names, table, at
        self._dict: dict[str, float] | None = None

    def _read(self) -> dict[str, float]:
        if self._dict is None:
            self._dict = dict(zip(self.names, self.table[self.at].tolist(), strict=True))
        return self._dict

    def __getitem__(self, key: str) -> float:
        return self._read()[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self.names)

    def __len__(self) -> int:
        return len(self.names)


def values_and_limits(
    mech: Mechanism, joints: tuple[str, ...], samples: list[Any]
) -> list[tuple[Mapping[str, float] | None, tuple[str, ...] | None]]:
    """Per sample (``.q``, ``.known``: :class:`pinmob.scan.chunk._Sample`), :func:`joint_rows` and :func:`limits_of`.

    None and None for a sample not assembled (``known`` None: a finished row). Where each joint has one coordinate,
    the joint values are :class:`ArrayRow` rows of one table (the same values).
    """
    qs = [s.q if s.known is not None else None for s in samples]
    closed = [q for q in qs if q is not None]
    columns, where = joint_coordinates(mech.model, tuple(joints), mech.model.nq)
    if where is None or not closed:
        values: list[Mapping[str, float] | None] = list(joint_rows(mech, joints, qs, [s.known for s in samples]))
    else:
        table = np.asarray(closed, float)[:, list(where)]
        rows = iter(range(len(closed)))
        values = [None if q is None else ArrayRow(columns, table, next(rows)) for q in qs]
    return list(zip(values, limits_of(mech.model, qs)))
