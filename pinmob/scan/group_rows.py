"""A group's rows (:func:`pinmob.scan.lockstep.run_group`): row dicts, and the rows the batch decided, in its columns.

A group of chunks gives its rows in order as :class:`GroupRows`: row dicts, and the rows the batch decided as
:class:`BatchRow` entries whose verdicts stay in the batch's arrays (:class:`~pinmob.scan.batch_rows.BatchRows`)
until the table is made (:meth:`GroupRows.table`: the table of the row dicts, :meth:`GroupRows.dicts`, without
making them).
"""

from __future__ import annotations

from dataclasses import dataclass
from operator import itemgetter
from typing import Any

import numpy as np

from pinmob.scan.batch_rows import BatchRows
from pinmob.scan.results.table import ScanTable


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
        at = np.array([e.at for e in ours], np.int64)
        columns: dict[str, Any] = {"reason": [e.reason for e in ours]}
        for dicts in ([e.head for e in ours], [e.values for e in ours]):  # the same keys in every row
            keys = [n for n in names if n in dicts[0] and n not in self.batch.columns and n not in columns]
            columns.update(_transposed(dicts, keys))
        for name in names:
            if name in self.batch.columns:
                columns[name] = self.batch.columns[name][at]
            elif name not in columns:  # a column the batch's rows do not have (none does today): the dicts' table
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


def _transposed(dicts: list[dict[str, Any]], keys: list[str]) -> dict[str, list[Any]]:
    """The values of ``keys`` in ``dicts`` (each has them all), column by column, read in one pass."""
    if len(keys) < 2:
        return {key: [d[key] for d in dicts] for key in keys}
    return dict(zip(keys, map(list, zip(*map(itemgetter(*keys), dicts)))))
