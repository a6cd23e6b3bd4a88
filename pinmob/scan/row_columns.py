"""A scan's rows column-wise: joint values and limits of many samples at once, a group's rows with the batch's columns.

What :func:`pinmob.scan.chain_scan.joint_row` and :func:`pinmob.model.joints.outside_limits` give per configuration, for
the samples a batch assembled (:meth:`pinmob.scan.chunk._Chunk.complete`), with numpy over the whole stack: the same
values and tuples. A group of chunks (:func:`pinmob.scan.lockstep.run_group`) gives its rows as :class:`GroupRows`:
row dicts, and the rows the batch decided as :class:`BatchRow` entries whose verdicts stay in the batch's columns
(:class:`~pinmob.scan.batch_rows.BatchRows`) until the table is made (:meth:`GroupRows.table`: the table of the row
dicts, :meth:`GroupRows.dicts`, without making them).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.model import Mechanism, outside_limits
from pinmob.scan.batch_rows import BatchRows
from pinmob.scan.chain_scan import joint_coordinates, joint_row
from pinmob.scan.results.table import ScanTable
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


def values_and_limits(mech: Mechanism, joints: tuple[str, ...], samples: list[Any]) -> list[tuple[Any, Any]]:
    """Per sample (``.q``, ``.known``: :class:`pinmob.scan.chunk._Sample`), :func:`joint_rows` and :func:`limits_of`.

    None and None for a sample not assembled (``known`` None: a finished row).
    """
    qs = [s.q if s.known is not None else None for s in samples]
    return list(zip(joint_rows(mech, joints, qs, [s.known for s in samples]), limits_of(mech.model, qs)))


@dataclass
class BatchRow:
    """A row the batch decided: its head, reason and joint values, and its entry ``at`` in the batch's columns.

    The head: ``index``, the line parameters, ``refined``; the reason: the joints outside their limits, or empty;
    the verdicts are the batch's columns' entries.
    """

    at: int
    head: dict[str, Any]
    reason: str
    values: dict[str, float]


@dataclass
class GroupRows:
    """A group's rows in order: row dicts, and :class:`BatchRow` entries of ``batch`` for the rows it decided."""

    entries: list[dict[str, Any] | BatchRow]
    batch: BatchRows | None = None

    def dicts(self) -> list[dict[str, Any]]:
        """The rows as dicts (a batch row: its head, the batch's verdicts, the reason, the joint values)."""
        batch = self.batch
        return [
            e if isinstance(e, dict) else {**e.head, **_row(batch, e.at), "reason": e.reason, **e.values}
            for e in self.entries
        ]

    def table(self, names: list[str]) -> ScanTable:
        """:meth:`ScanTable.from_rows` of :meth:`dicts` (the same arrays and masks), without the batch's row dicts.

        The table of the row dicts and the table of the batch's rows (their verdicts the batch's arrays), merged in
        order.
        """
        ours = [e for e in self.entries if isinstance(e, BatchRow)]
        if not ours or self.batch is None:
            return ScanTable.from_rows(names, self.dicts())
        plain = [e for e in self.entries if isinstance(e, dict)]
        columns: dict[str, Any] = {}
        at = np.array([e.at for e in ours], np.int64)
        for name in names:
            if name in self.batch.columns:
                columns[name] = self.batch.columns[name][at]
            elif name == "reason":
                columns[name] = [e.reason for e in ours]
            elif name in ours[0].head:
                columns[name] = [e.head[name] for e in ours]
            elif name in ours[0].values:
                columns[name] = [e.values[name] for e in ours]
            else:  # a column the batch's rows do not have (none does today): the dicts' table, absent masks and all
                return ScanTable.from_rows(names, self.dicts())
        table = ScanTable.from_columns(names, columns)
        if not plain:
            return table
        both = ScanTable.concat([ScanTable.from_rows(names, plain), table])
        mine = np.array([isinstance(e, BatchRow) for e in self.entries])
        order = np.empty(len(mine), np.int64)
        order[~mine], order[mine] = np.arange(len(plain)), len(plain) + np.arange(len(ours))
        return both.take(order)


def _row(batch: BatchRows | None, at: int) -> dict[str, Any]:
    assert batch is not None, "a batch row without its batch"
    return batch.row(at)
