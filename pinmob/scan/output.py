"""Scan results on disk: rows streamed to CSV and JSON, and columns read back from the CSV.

Both directions keep memory flat in the number of samples: :class:`RowWriter`
holds only the current row (and writes through temporary files renamed at the end), :func:`read_columns` parses only the columns asked
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
from pinmob.signals import deferred_interrupts


class RowWriter:
    """Stream rows to a CSV file and/or a JSON file (``{"scan": {...}, "samples": [...]}``) as they come.

    A JSON row's keys come in the CSV's column order (reachable and unreachable rows alike).

    Use as a context manager; nothing is kept in memory but the current row. The
    rows go to temporary files in the targets' folders (:class:`~pinmob.output_files.Replacing`),
    renamed over the targets when the block ends normally: an error, Ctrl-C or a
    handled signal leaves the targets as they were (an old file is not truncated
    at the start) and removes the temporary files.
    """

    def __init__(
        self, cols: list[str], meta: dict[str, Any], csv_path: str | None = None, json_path: str | None = None
    ):
        self.cols = cols
        self._known = set(cols)
        self.meta = meta
        self.csv_path, self.json_path = csv_path, json_path
        self.count = 0
        self._stack = contextlib.ExitStack()
        self._targets: list[Replacing] = []

    def _open(self, target: str) -> Any:
        replacing = Replacing(target)
        path = self._stack.enter_context(replacing)
        self._targets.append(replacing)
        return self._stack.enter_context(open(path, "w", newline="", encoding="utf-8"))

    def __enter__(self) -> RowWriter:
        try:
            # a signal while a temporary file is created and registered for removal is raised once both are done
            with deferred_interrupts():
                self._csv_fh = self._open(self.csv_path) if self.csv_path else None
                self._csv = csv.DictWriter(self._csv_fh, self.cols) if self._csv_fh else None
                if self._csv:
                    self._csv.writeheader()
                self._json = self._open(self.json_path) if self.json_path else None
                if self._json:
                    self._json.write('{"scan": ' + json.dumps(self.meta) + ', "samples": [')
        except BaseException:
            self._stack.close()
            raise
        return self

    def write(self, row: dict[str, Any]) -> None:
        """Append one row to each output file.

        Raises:
            OSError: a file cannot be written (a full disk, a file size limit), naming the file.
        """
        if self._csv:
            with _naming(self.csv_path):
                self._csv.writerow({k: (f"{v:.10g}" if isinstance(v, float) else v) for k, v in row.items()})
        if self._json:
            keys = [k for k in self.cols if k in row] + [k for k in row if k not in self._known]  # the CSV's order
            clean = {k: (None if isinstance(row[k], float) and not np.isfinite(row[k]) else row[k]) for k in keys}
            with _naming(self.json_path):
                self._json.write((",\n" if self.count else "\n") + json.dumps(clean, allow_nan=False))
        self.count += 1

    def __exit__(self, kind: type[BaseException] | None, *exc: object) -> None:
        failed = kind is not None
        try:
            if not failed:
                if self._json:
                    with _naming(self.json_path):
                        self._json.write("\n]}\n")
                for fh, path in ((self._csv_fh, self.csv_path), (self._json, self.json_path)):
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
                with contextlib.suppress(OSError):
                    self._stack.close()
            else:
                self._stack.close()  # nothing left to remove


@contextlib.contextmanager
def _naming(path: str | None) -> Iterator[None]:
    """An OSError inside the block names ``path`` (a write's error, e.g. a full disk, names no file)."""
    try:
        yield
    except OSError as exc:
        if exc.filename or path is None:
            raise
        raise OSError(exc.errno, f"cannot write {path!r}: {exc.strerror or exc}") from None


#: Columns read as text; every other column is read as float (blank: NaN; True/False: 1/0).
TEXT_COLUMNS = frozenset({"motion_type", "singularity", "closest", "singular_limbs", "dependent_limbs", "uncontrolled"})


def header(csv_path: str | Path) -> list[str]:
    """The column names of a scan CSV."""
    with open(csv_path, newline="") as fh:
        return next(csv.reader(fh), [])


def read_columns(csv_path: str | Path, names: Sequence[str]) -> dict[str, np.ndarray]:
    """The named columns of a scan CSV: floats (NaN for blanks, 1/0 for True/False) or text arrays.

    Columns the file does not have are left out.
    """
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
