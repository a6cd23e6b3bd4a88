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
from pinmob.scan.row_columns import ArrayRow
from pinmob.screw import Array


@dataclass(slots=True)
class Head:
    """A sample's head (``index``, the line parameters, ``refined`` False) kept as its row of the group's columns.

    ``params``: the names of the line parameters and their (B, A) values (:meth:`ScanSpec.param_columns
    <pinmob.scan.scan_spec.ScanSpec.param_columns>` of the group's samples), the sample's at row ``at``.
    :meth:`GroupRows.table` reads the heads of the batch's rows as those columns; :meth:`dict` makes one.
    """

    index: int
    params: tuple[list[str], Array]
    at: int

    def line_params(self) -> dict[str, float]:
        """The sample's line parameters (:meth:`ScanSpec.params_of <pinmob.scan.scan_spec.ScanSpec.params_of>`'s)."""
        names, values = self.params
        return dict(zip(names, values[self.at].tolist()))

    def dict(self) -> dict[str, Any]:
        """The head as the row dict's first keys."""
        return {"index": self.index, **self.line_params(), "refined": False}


def head_dict(head: dict[str, Any] | Head) -> dict[str, Any]:
    """A head as a dict (a :class:`Head` made into one)."""
    return head.dict() if isinstance(head, Head) else head


@dataclass
class BatchRow:
    """A row the batch decided: its head, reason and joint values, and its entry ``at`` in the batch's columns.

    The head: ``index``, the line parameters, ``refined`` (a dict, or a :class:`Head`); the reason: the joints
    outside their limits, or empty; the joint values: a dict or a :class:`~pinmob.scan.row_columns.ArrayRow`; the
    verdicts are the batch's columns' entries.
    """

    at: int
    head: dict[str, Any] | Head
    reason: str
    values: dict[str, float] | ArrayRow


@dataclass
class GroupRows:
    """A group's rows in order: row dicts, and :class:`BatchRow` entries of ``batch`` for the rows it decided."""

    entries: list[dict[str, Any] | BatchRow]
    batch: BatchRows | None = None

    def dicts(self) -> list[dict[str, Any]]:
        """The rows as dicts (a batch row: its head, the batch's verdicts, the reason, the joint values)."""
        batch = self.batch
        return [
            e if isinstance(e, dict) else {**head_dict(e.head), **_row(batch, e.at), "reason": e.reason, **e.values}
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
        heads, values = [e.head for e in ours], [e.values for e in ours]
        known = set(self.batch.columns)  # the batch's own columns: not read from the heads or values
        columns.update(_head_columns(heads) or _transposed([head_dict(h) for h in heads], names, known | set(columns)))
        columns.update(_value_columns(values) or _transposed(values, names, known | set(columns)))
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


def _head_columns(heads: list[dict[str, Any] | Head]) -> dict[str, Any] | None:
    """The columns of heads that are all :class:`Head` rows of one group's columns, as arrays (else None)."""
    ours = [h for h in heads if isinstance(h, Head)]
    if len(ours) < len(heads) or any(h.params is not ours[0].params for h in ours):
        return None
    names, values = ours[0].params
    at = np.array([h.at for h in ours], np.int64)
    picked = values[at]
    return {"index": np.array([h.index for h in ours], np.int64),
            **{n: picked[:, j].copy() for j, n in enumerate(names)}, "refined": np.zeros(len(at), bool)}  # fmt: skip


def _value_columns(values: list[dict[str, float] | ArrayRow]) -> dict[str, Any] | None:
    """The columns of joint values that are all :class:`ArrayRow` rows of one table, as arrays (else None)."""
    ours = [v for v in values if isinstance(v, ArrayRow)]
    if len(ours) < len(values) or any(v.table is not ours[0].table for v in ours):
        return None
    picked = ours[0].table[np.array([v.at for v in ours], np.int64)]
    return {n: picked[:, j].copy() for j, n in enumerate(ours[0].names)}


def _transposed(dicts: list[Any], names: list[str], known: set[str]) -> dict[str, list[Any]]:
    """The values of the columns ``names`` in ``dicts`` (each has the same keys), column by column, in one pass.

    The columns are those of ``names`` the first dict has and ``known`` does not (those already read).
    """
    keys = [n for n in names if n in dicts[0] and n not in known]
    if len(keys) < 2:
        return {key: [d[key] for d in dicts] for key in keys}
    return dict(zip(keys, map(list, zip(*map(itemgetter(*keys), dicts)))))
