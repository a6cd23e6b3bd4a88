"""Scan results on disk: rows streamed to CSV, JSON and Parquet, and columns read back from the CSV.

Both directions keep memory flat in the number of samples: :class:`RowWriter`
holds only the current table of rows (and writes through temporary files renamed at the end), :func:`read_columns` parses only the columns asked
for, line by line, into arrays.
"""

from __future__ import annotations

import contextlib
import csv
import json
from array import array
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from pinmob.output_files import Replacing
from pinmob.scan.results.table import TEXT_COLUMNS, ScanTable, column_type
from pinmob.signals import deferred_interrupts


class RowWriter:
    """Stream a scan's rows to a CSV, a JSON and/or a Parquet file as they come, a table of rows at a time.

    The JSON file is ``{"scan": {...}, "samples": [...]}``, a row's keys in the CSV's column order (a key a row does
    not have left out); the Parquet file has one typed column per CSV column (:func:`pinmob.scan.results.table.column_type`;
    null where a row has no value) and ``meta`` as JSON in its schema's metadata (key ``pinmob_scan``).

    Use as a context manager; nothing is kept in memory but the table being written
    (:meth:`write_table`, each written column by column: :class:`~pinmob.scan.results.table.ScanTable`). The
    rows go to temporary files in the targets' folders (:class:`~pinmob.output_files.Replacing`),
    renamed over the targets when the block ends normally: an error, Ctrl-C or a
    handled signal leaves the targets as they were (an old file is not truncated
    at the start) and removes the temporary files.
    """

    def __init__(
        self,
        cols: list[str],
        meta: dict[str, Any],
        csv_path: str | None = None,
        json_path: str | None = None,
        parquet_path: str | None = None,
    ):
        self.cols = list(cols)
        self.meta = meta
        self.csv_path, self.json_path, self.parquet_path = csv_path, json_path, parquet_path
        self.count = 0
        self._stack = contextlib.ExitStack()
        self._targets: list[Replacing] = []
        self._parquet: Any = None

    def _open(self, target: str) -> Any:
        replacing = Replacing(target)
        path = self._stack.enter_context(replacing)
        self._targets.append(replacing)
        return self._stack.enter_context(open(path, "wb"))

    def __enter__(self) -> RowWriter:
        try:
            # a signal while a temporary file is created and registered for removal is raised once both are done
            with deferred_interrupts():
                self._csv = self._open(self.csv_path) if self.csv_path else None
                if self._csv:
                    with _naming(self.csv_path):
                        self._csv.write(ScanTable.from_rows(self.cols, []).csv_text(header=True).encode())
                self._json = self._open(self.json_path) if self.json_path else None
                if self._json:
                    with _naming(self.json_path):
                        self._json.write(('{"scan": ' + json.dumps(self.meta) + ', "samples": [').encode())
                self._parquet_fh = self._open(self.parquet_path) if self.parquet_path else None
                if self._parquet_fh:
                    with _naming(self.parquet_path):
                        self._parquet = ParquetRows(self._parquet_fh, self.cols, self.meta)
        except BaseException:
            self._stack.close()
            raise
        return self

    def write(self, row: dict[str, Any]) -> None:
        """Append one row to each output file (:meth:`write_table` of a table of one row)."""
        self.write_table(ScanTable.from_rows(self.cols, [row]))

    def write_table(self, table: ScanTable) -> None:
        """Append the rows of ``table`` (its columns this writer's) to each output file.

        Raises:
            OSError: a file cannot be written (a full disk, a file size limit), naming the file.
        """
        if not len(table):
            return
        if self._csv:
            with _naming(self.csv_path):
                self._csv.write(table.csv_text().encode())
        if self._json:
            with _naming(self.json_path):
                self._json.write((b",\n" if self.count else b"\n") + table.json_lines())
        if self._parquet:
            with _naming(self.parquet_path):
                self._parquet.write(table)
        self.count += len(table)

    def __exit__(self, kind: type[BaseException] | None, *exc: object) -> None:
        failed = kind is not None
        try:
            if not failed:
                if self._json:
                    with _naming(self.json_path):
                        self._json.write(b"\n]}\n")
                if self._parquet:
                    with _naming(self.parquet_path):
                        self._parquet.close()
                files = (
                    (self._csv, self.csv_path),
                    (self._json, self.json_path),
                    (self._parquet_fh, self.parquet_path),
                )
                for fh, path in files:
                    if fh:
                        with _naming(path):
                            fh.close()
                for target in self._targets:
                    target.commit()
        except BaseException:
            failed = True
            raise
        finally:
            if failed:  # the files are dropped: a failing flush of another one must not hide what stopped the writing
                if self._parquet:
                    with contextlib.suppress(Exception):
                        self._parquet.close()
                with contextlib.suppress(OSError):
                    self._stack.close()
            else:
                self._stack.close()  # nothing left to remove


class ParquetRows:
    """A Parquet file of a scan's rows, written a table at a time (a row group each) to the open binary file ``fh``.

    The schema comes from the column names (:func:`pinmob.scan.results.table.column_type`), so every table has it.
    """

    TYPES = {"int": "int64", "bool": "bool_", "text": "string", "float": "float64"}

    def __init__(self, fh: Any, cols: list[str], meta: dict[str, Any]) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        self.pa = pa
        fields = [pa.field(n, getattr(pa, self.TYPES[column_type(n)])()) for n in cols]
        self.schema = pa.schema(fields, metadata={"pinmob_scan": json.dumps(meta)})
        self.writer = pq.ParquetWriter(fh, self.schema)

    def write(self, table: ScanTable) -> None:
        """Append ``table``'s rows (one row group)."""
        pa = self.pa
        arrays = []
        for f in self.schema:
            data = table.data[f.name]
            if data.dtype == object:  # values that fit no type: blank text (a closed chain's unreachable row) is null
                values = table.column(f.name)
                if f.type != pa.string():
                    values = [None if isinstance(v, str) and not v else v for v in values]
                arrays.append(pa.array(values, f.type))
            else:
                arrays.append(pa.array(data, f.type, mask=table.missing(f.name)))
        self.writer.write_table(pa.Table.from_arrays(arrays, schema=self.schema))

    def close(self) -> None:
        """Write the file's footer (the file handle stays open)."""
        self.writer.close()


@contextlib.contextmanager
def _naming(path: str | None) -> Iterator[None]:
    """An OSError inside the block names ``path`` (a write's error, e.g. a full disk, names no file)."""
    try:
        yield
    except OSError as exc:
        if exc.filename or path is None:
            raise
        raise OSError(exc.errno, f"cannot write {path!r}: {exc.strerror or exc}") from None


def header(csv_path: str | Path | ScanTable) -> list[str]:
    """The column names of a scan CSV (or of a table of rows)."""
    if isinstance(csv_path, ScanTable):
        return list(csv_path.names)
    with open(csv_path, newline="") as fh:
        return next(csv.reader(fh), [])


def read_columns(csv_path: str | Path | ScanTable, names: Sequence[str]) -> dict[str, np.ndarray]:
    """The named columns of a scan CSV (or of a table of rows): floats (NaN for blanks, 1/0 for True/False) or text.

    Columns the file does not have are left out.
    """
    if isinstance(csv_path, ScanTable):
        return _table_columns(csv_path, names)
    with open(csv_path, newline="") as fh:
        reader = csv.reader(fh)
        header = next(reader, [])
        wanted = [(n, header.index(n)) for n in names if n in header]
        values: dict[str, Any] = {n: [] if n in TEXT_COLUMNS else array("d") for n, _ in wanted}
        for line in reader:
            for n, i in wanted:
                values[n].append(line[i] if n in TEXT_COLUMNS else _number(line[i]))
    return {n: np.array(v, dtype=object) if n in TEXT_COLUMNS else np.frombuffer(v, float) for n, v in values.items()}


def _number(text: str) -> float:
    if text in ("True", "False"):
        return float(text == "True")
    return float(text) if text else float("nan")


def _table_columns(table: ScanTable, names: Sequence[str]) -> dict[str, np.ndarray]:
    """:func:`read_columns` of a table: the values its CSV would hold, read back the same way."""
    out = {}
    for n in (n for n in names if n in table.names):
        if n in TEXT_COLUMNS:
            out[n] = np.array(["" if v is None else str(v) for v in table.column(n)], dtype=object)
        elif table[n].dtype != object:
            values = table[n].astype(float)
            missing = table.missing(n)
            out[n] = values if missing is None else np.where(missing, np.nan, values)
        else:
            out[n] = np.array([float("nan") if v is None else float(v) for v in table.column(n)], float)
    return out
