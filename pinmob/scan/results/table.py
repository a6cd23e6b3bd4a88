"""A scan's rows as columns: :class:`ScanTable`, one numpy array per column, and its text for CSV and JSON files.

A scan's column names are fixed by its spec (:func:`pinmob.scan.scan_run.columns`); each column's type by its name
(:func:`column_type`): whole numbers (``index``, ``dof``, the ranks, the finite DoF), booleans (``refined``,
``reachable``, ``near_singular``, ``actuation_valid``), text (the motion type, the singularity's labels, the
reason) and floats (every other: coordinates, distances, singular values, joint values). A value missing from a row
(None) is masked (``null``); a key a row does not have is masked too (``absent``: a JSON row leaves it out, a CSV
row leaves it blank). A column whose values do not fit its type keeps them as objects (written as they are).

:meth:`ScanTable.csv_text` and :meth:`ScanTable.json_lines` write the rows column by column, the same text as
:mod:`csv`'s writer of each row's values (floats as ``%.10g``) and the same data as :func:`json.dumps` of each row
(non-finite floats as null): ``tests/test_scan_table.py`` compares them with those writers.
"""

from __future__ import annotations

from collections.abc import Iterable, Iterator, Mapping, Sequence
from dataclasses import dataclass, field
from operator import itemgetter
from typing import Any

import numpy as np

#: Columns of whole numbers (-1 where a sample did not assemble; None where the analysis cannot decide).
INT_COLUMNS = frozenset({"index", "dof", "constraint_rank", "locked_dof", "closure_rank", "closure_rows",
                         "redundant_constraints", "idle_dof", "redundant_actuators", "finite_dof",
                         "finite_mechanism_dof"})  # fmt: skip
#: Columns of booleans (``actuation_valid`` None: no actuated joint).
BOOL_COLUMNS = frozenset({"refined", "reachable", "near_singular", "actuation_valid"})
#: Columns of text.
TEXT_COLUMNS = frozenset({"motion_type", "singularity", "closest", "singular_limbs", "dependent_limbs",
                          "uncontrolled", "reason"})  # fmt: skip

_DTYPES = {"int": np.dtype(np.int64), "bool": np.dtype(bool), "text": np.dtype(object), "float": np.dtype(float)}
_FITS: dict[str, frozenset[type]] = {
    "int": frozenset({int, np.int64, np.int32}),
    "bool": frozenset({bool, np.bool_}),
    "text": frozenset({str}),
    "float": frozenset({float, np.float64}),
}
_FILL = {"int": 0, "bool": False, "text": "", "float": float("nan")}


def column_type(name: str) -> str:
    """``int``, ``bool``, ``text`` or ``float``: the type of a scan column, by its name."""
    if name in INT_COLUMNS:
        return "int"
    if name in BOOL_COLUMNS:
        return "bool"
    return "text" if name in TEXT_COLUMNS else "float"


class _Absent:
    """A key a row does not have (told apart from a value None)."""


_ABSENT = _Absent()


@dataclass(frozen=True)
class ScanTable:
    """A scan's rows, column by column (the rows in order of the line parameter, refined points among them).

    Attributes:
        names: the columns, in the files' order.
        data: per column, its (n,) array: int64, bool, float64 or object (text, or values that fit no type).
        null: per column with missing values (None), its (n,) mask of them (their entries in ``data`` are fill).
        absent: per column some rows do not have, its (n,) mask of those rows.
    """

    names: tuple[str, ...]
    data: dict[str, np.ndarray]
    null: dict[str, np.ndarray] = field(default_factory=dict)
    absent: dict[str, np.ndarray] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not all(isinstance(n, str) for n in self.names) or len(set(self.names)) != len(self.names):
            raise ValueError(f"a table's columns are distinct names (text): {list(self.names)}")

    @classmethod
    def from_rows(cls, names: Sequence[str], rows: Sequence[Mapping[str, Any]]) -> ScanTable:
        """The table of ``rows`` (dicts keyed by column; a key outside ``names`` is an error, as for a CSV row).

        Raises:
            ValueError: a row has a key that is not a column.
        """
        names = tuple(names)
        known = set(names)
        extra = [k for row in rows if not known.issuperset(row) for k in row if k not in known]
        if extra:
            raise ValueError(f"row has keys that are not columns: {sorted(set(extra))}")
        table = cls(names, {})
        if len(names) > 1 and rows and all(len(row) == len(names) for row in rows):  # every row has every column
            for name, values in zip(names, zip(*map(itemgetter(*names), rows))):
                table._set(name, list(values))
            return table
        for name in names:
            table._set(name, [row.get(name, _ABSENT) for row in rows])
        return table

    @classmethod
    def from_columns(cls, names: Sequence[str], columns: Mapping[str, np.ndarray | list[Any]]) -> ScanTable:
        """The table of ``columns`` (one per name, equally long): arrays as they are, lists typed by :meth:`from_rows`.

        An array must be what :meth:`from_rows` would make of its values: int64, bool, float64, or object (text).
        """
        table = cls(tuple(names), {})
        for name in table.names:
            values = columns[name]
            if isinstance(values, np.ndarray):
                table.data[name] = values
            else:
                table._set(name, values)
        return table

    def _set(self, name: str, values: list[Any]) -> None:
        kind = column_type(name)
        types = set(map(type, values))
        if _Absent in types:
            self.absent[name] = np.fromiter((v is _ABSENT for v in values), bool, len(values))
        if _Absent in types or type(None) in types:
            missing = np.fromiter((v is None or v is _ABSENT for v in values), bool, len(values))
            if kind == "text" or not types - {_Absent, type(None)} <= _FITS[kind]:
                kind = "object"
            else:
                self.null[name] = missing
            fill = None if kind == "object" else _FILL[kind]
            values = [fill if m else v for v, m in zip(values, missing.tolist())]
        elif not types <= _FITS[kind]:
            kind = "object"
        array = np.empty(len(values), object) if kind in ("object", "text") else None
        if array is not None:
            array[:] = values
            self.data[name] = array
        else:
            self.data[name] = np.array(values, _DTYPES[kind]) if values else np.empty(0, _DTYPES[kind])

    @classmethod
    def concat(cls, tables: Iterable[ScanTable], names: Sequence[str] = ()) -> ScanTable:
        """One table of ``tables`` in order (``names``: the columns of an empty result)."""
        tables = list(tables)
        if len(tables) == 1:
            return tables[0]
        if not tables:
            return cls.from_rows(names, [])
        if len({t.names for t in tables}) > 1:
            raise ValueError("tables with different columns")
        names = tables[0].names
        if all(t.kinds() == tables[0].kinds() and not t.absent for t in tables):
            out = cls(names, {n: np.concatenate([t.data[n] for t in tables]) for n in names})
            for n in {n for t in tables for n in t.null}:
                out.null[n] = np.concatenate([t.null.get(n, np.zeros(len(t), bool)) for t in tables])
            return out
        return cls.from_rows(names, [row for t in tables for row in t.rows()])

    def kinds(self) -> dict[str, str]:
        """Each column's array type: ``int``, ``bool``, ``float`` or ``object``."""
        return {n: {"i": "int", "b": "bool", "f": "float"}.get(a.dtype.kind, "object") for n, a in self.data.items()}

    def __len__(self) -> int:
        return len(self.data[self.names[0]]) if self.names else 0

    def __getitem__(self, name: str) -> np.ndarray:
        """The column ``name`` (its array; masked entries hold fill: see :meth:`column`)."""
        return self.data[name]

    def missing(self, name: str) -> np.ndarray | None:
        """The rows of column ``name`` without a value (None, or no such key); None when every row has one."""
        mask = self.null.get(name)
        if name in self.absent:
            mask = self.absent[name] if mask is None else mask | self.absent[name]
        return mask

    def column(self, name: str) -> list[Any]:
        """The column ``name`` as Python values (None where a row has no value)."""
        values = self.data[name].tolist()
        mask = self.missing(name)
        if mask is not None:
            for i in np.flatnonzero(mask).tolist():
                values[i] = None
        return values

    def rows(self) -> Iterator[dict[str, Any]]:
        """The rows as dicts, as the scan built them (a key a row did not have is left out)."""
        columns = [self.column(n) for n in self.names]
        rows = [dict(zip(self.names, values)) for values in zip(*columns)]
        for name, mask in self.absent.items():
            for i in np.flatnonzero(mask).tolist():
                del rows[i][name]
        return iter(rows)

    def row(self, i: int) -> dict[str, Any]:
        """Row ``i`` as a dict (as :meth:`rows` gives it)."""
        return next(self.take([i]).rows())

    def take(self, which: Sequence[int] | np.ndarray) -> ScanTable:
        """The rows ``which`` (indices or a boolean mask), as a table."""
        return ScanTable(self.names, {n: a[which] for n, a in self.data.items()},
                         {n: m[which] for n, m in self.null.items()},
                         {n: m[which] for n, m in self.absent.items()})  # fmt: skip

    def csv_text(self, header: bool = False) -> str:
        """The rows as CSV lines (CR LF after each, :mod:`csv`'s excel dialect), with the header line first.

        One ``%`` format per row: ``%.10g`` for a float column, ``%d`` for a whole-number one, ``%s`` for the
        others and for the columns with missing values (formatted first, column by column).
        """
        lines = [",".join(map(_quoted, self.names))] if header else []
        if len(self):
            specs, columns = zip(*(self._csv_column(n) for n in self.names))
            fmt = ",".join(specs) + "\r\n"
            return "".join(line + "\r\n" for line in lines) + "".join(map(fmt.__mod__, zip(*columns)))
        return "".join(line + "\r\n" for line in lines)

    def _csv_column(self, name: str) -> tuple[str, list[Any]]:
        """A column's ``%`` format and values for :meth:`csv_text`."""
        array = self.data[name]
        kind = array.dtype.kind
        mask = self.missing(name)
        if kind == "O":
            return "%s", [_csv_value(v) for v in array.tolist()]
        if mask is None:
            return {"f": "%.10g", "i": "%d"}.get(kind, "%s"), array.tolist()
        text = [_csv_value(v) for v in array.tolist()]
        for i in np.flatnonzero(mask).tolist():
            text[i] = ""
        return "%s", text

    def json_lines(self) -> bytes:
        """The rows as JSON objects (orjson), one a line, separated by a comma and a line break.

        Column by column: each column's values encoded at once (numbers, booleans and null: the column's list in one
        ``orjson.dumps`` call, split at its commas; text: each distinct value once), then each row's object by one
        ``%`` format of its columns' pieces: the same bytes as ``orjson.dumps`` of the row (:meth:`rows`; numpy scalars
        in an object column as Python values). A table with absent keys (a row leaves them out) is written row by row.
        """
        import orjson

        if not len(self):
            return b""
        if self.absent:
            option = orjson.OPT_SERIALIZE_NUMPY
            return b",\n".join(orjson.dumps(row, default=_plain, option=option) for row in self.rows())
        keys = (orjson.dumps(name).replace(b"%", b"%%") for name in self.names)  # a row: one % format
        row = b"{" + b",".join(key + b":%b" for key in keys) + b"}"
        return b",\n".join(map(row.__mod__, zip(*map(self._json_column, self.names))))

    def _json_column(self, name: str) -> list[bytes]:
        """Each row's value of column ``name`` as JSON (orjson; None, NaN and infinities as null)."""
        import orjson

        array = self.data[name]
        if array.dtype.kind in "biuf" and array.ndim == 1:  # numbers, booleans and null: no comma inside a value
            if self.missing(name) is None:  # the array itself: orjson writes its numbers as those of its list
                return orjson.dumps(np.ascontiguousarray(array), option=orjson.OPT_SERIALIZE_NUMPY)[1:-1].split(b",")
            return orjson.dumps(self.column(name))[1:-1].split(b",")
        values = self.column(name)
        if set(map(type, values)) <= {str, type(None)}:  # text: a few distinct values
            text = {v: orjson.dumps(v) for v in set(values)}
            return [text[v] for v in values]
        return [orjson.dumps(v, default=_plain, option=orjson.OPT_SERIALIZE_NUMPY) for v in values]


def _plain(value: Any) -> Any:
    """A value orjson does not encode itself (a numpy scalar in an object column) as a plain one."""
    if isinstance(value, np.generic):
        return value.item()
    raise TypeError(f"{type(value).__name__} is not JSON serialisable")


def _quoted(text: str) -> str:
    """A CSV field as :mod:`csv` writes it (QUOTE_MINIMAL): quoted when it holds a comma, quote or line break."""
    if "," in text or '"' in text or "\n" in text or "\r" in text:
        return '"' + text.replace('"', '""') + '"'
    return text


def _csv_value(value: Any) -> str:
    """One value of an object column, as the row writer wrote it (floats as ``%.10g``; None blank)."""
    if value is None:
        return ""
    if isinstance(value, float):
        return f"{value:.10g}"
    return _quoted(value if isinstance(value, str) else str(value))
