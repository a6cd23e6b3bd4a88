"""Per-sample cost of writing a scan's rows to JSON, CSV and Parquet: one dict a row (before) and by columns (after).

One run, per grid (microseconds per row, the best of ``--repeat`` runs, single process; the rows computed once,
untimed, by :func:`pinmob.scan.scan_run.scan_tables`, a table per group of chunks as :func:`pinmob.scan.scan` writes
them):

* ``before``: the row writer pinmob had before :class:`pinmob.scan.ScanTable` (:class:`DictRowWriter`, in this
  file: ``csv.DictWriter`` with floats as ``%.10g`` and one ``json.dumps`` per row dict), and for Parquet what a
  writer of dict rows does, ``pyarrow.Table.from_pylist`` of each group's dicts;
* ``after``: :class:`pinmob.scan.results.output.RowWriter` ``write_table`` of each group's table (the columns written
  vectorised; JSON by orjson);
* ``table``: building the tables from the engine's row dicts (:meth:`ScanTable.from_rows`, what the scan adds
  before writing; paid once for all three files).

The files are compared: the CSV byte for byte, the JSON and the Parquet as data (``same``). The versions the figures
depend on are printed first (``bench_scan.versions``).

Usage: ``python benchmarks/bench_scan_output.py [--quick] [--repeat N]``.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import tempfile
import time
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq
from bench_scan import versions  # this folder's: the versions the figures depend on

import pinmob
from pinmob.blas import one_blas_thread
from pinmob.scan import ScanTable, columns, grid_spec, scan_tables
from pinmob.scan.results.output import RowWriter

GRIDS = [
    ("3-PUU", "generic", [("x", -0.06, 0.06, 41), ("y", -0.06, 0.06, 41)]),
    ("6-UPS", "home", [("x", -0.05, 0.05, 21), ("y", -0.05, 0.05, 21)]),
    ("3-PUU", "generic", [("x", -0.3, 0.3, 41), ("y", -0.3, 0.3, 41)]),  # mostly out of reach: text reasons
]


class DictRowWriter:
    """The row writer before the table: a CSV row and a JSON object written per row dict."""

    def __init__(self, cols: list[str], meta: dict[str, Any], csv_path: Path, json_path: Path) -> None:
        self.cols, self.known = cols, set(cols)
        self.csv_fh = open(csv_path, "w", newline="", encoding="utf-8")
        self.csv = csv.DictWriter(self.csv_fh, cols)
        self.csv.writeheader()
        self.json = open(json_path, "w", encoding="utf-8")
        self.json.write('{"scan": ' + json.dumps(meta) + ', "samples": [')
        self.count = 0

    def write(self, row: dict[str, Any]) -> None:
        self.csv.writerow({k: (f"{v:.10g}" if isinstance(v, float) else v) for k, v in row.items()})
        keys = [k for k in self.cols if k in row] + [k for k in row if k not in self.known]
        clean = {k: (None if isinstance(row[k], float) and not math.isfinite(row[k]) else row[k]) for k in keys}
        self.json.write((",\n" if self.count else "\n") + json.dumps(clean, allow_nan=False))
        self.count += 1

    def close(self) -> None:
        self.json.write("\n]}\n")
        self.json.close()
        self.csv_fh.close()


def best_of(repeat: int, run: Any) -> float:
    """The smallest wall time [s] of ``repeat`` calls of ``run``."""
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        run()
        times.append(time.perf_counter() - t0)
    return min(times)


def same(a: Any, b: Any) -> bool:
    """Equal as data, NaN equal to NaN (nested)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(same(a[k], b[k]) for k in a)
    if isinstance(a, list) and isinstance(b, list):
        return len(a) == len(b) and all(same(x, y) for x, y in zip(a, b))
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return bool(a == b)


def bench(name: str, at: str, axes: list[tuple[str, float, float, int]], repeat: int, folder: Path) -> dict[str, Any]:
    """The costs of writing one grid's rows (module docstring)."""
    mech = pinmob.load(name)
    spec = grid_spec(mech, at, axes)
    cols, meta = columns(spec), {"mechanism": name}
    tables = list(scan_tables(mech, spec))
    groups = [list(t.rows()) for t in tables]  # the engine's dicts, a list per group
    rows = [row for group in groups for row in group]
    n = len(rows)
    p = {k: folder / f"{k}.{ext}" for k, ext in
         (("csv0", "csv"), ("json0", "json"), ("pq0", "parquet"), ("csv1", "csv"), ("json1", "json"),
          ("pq1", "parquet"))}  # fmt: skip

    def dict_csv_json() -> None:
        writer = DictRowWriter(cols, meta, p["csv0"], p["json0"])
        for row in rows:
            writer.write(row)
        writer.close()

    def dict_parquet() -> None:
        schema = None
        writer = None
        for group in groups:
            table = pa.Table.from_pylist(group)
            if writer is None:
                schema = table.schema
                writer = pq.ParquetWriter(p["pq0"], schema)
            writer.write_table(table.cast(schema))
        if writer is not None:
            writer.close()

    def table_writer(**files: Path) -> Any:
        def run() -> None:
            with RowWriter(cols, meta, **{k: str(v) for k, v in files.items()}) as writer:
                for table in tables:
                    writer.write_table(table)

        return run

    before_both = best_of(repeat, dict_csv_json)
    # the old writer wrote CSV and JSON in one loop: its CSV share timed alone with a JSON-less copy
    before_csv = best_of(repeat, lambda: _dict_csv_only(cols, rows, p["csv0"]))
    out = {
        "grid": f"{name} {' '.join(f'{a[0]}:{a[1]:g}:{a[2]:g}:{a[3]}' for a in axes)}",
        "rows": n,
        "json_before": (before_both - before_csv) / n * 1e6,
        "json_after": best_of(repeat, table_writer(json_path=p["json1"])) / n * 1e6,
        "csv_before": before_csv / n * 1e6,
        "csv_after": best_of(repeat, table_writer(csv_path=p["csv1"])) / n * 1e6,
        "parquet_before": best_of(repeat, dict_parquet) / n * 1e6,
        "parquet_after": best_of(repeat, table_writer(parquet_path=p["pq1"])) / n * 1e6,
        "table": best_of(repeat, lambda: [ScanTable.from_rows(cols, g) for g in groups]) / n * 1e6,
    }
    dict_csv_json()
    out["csv_equal"] = p["csv0"].read_bytes() == p["csv1"].read_bytes()
    out["json_equal"] = same(json.loads(p["json0"].read_text()), json.loads(p["json1"].read_text()))
    out["parquet_equal"] = same(pq.read_table(p["pq1"]).to_pylist(), [dict(r) for r in rows])
    return out


def _dict_csv_only(cols: list[str], rows: list[dict[str, Any]], path: Path) -> None:
    with open(path, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, cols)
        writer.writeheader()
        for row in rows:
            writer.writerow({k: (f"{v:.10g}" if isinstance(v, float) else v) for k, v in row.items()})


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the first grid only, 21 x 21")
    parser.add_argument("--repeat", type=int, default=5, help="timed runs of each writer (the best is printed)")
    args = parser.parse_args()
    grids = [(GRIDS[0][0], GRIDS[0][1], [(c, lo, hi, 21) for c, lo, hi, _ in GRIDS[0][2]])] if args.quick else GRIDS
    print("versions: " + ", ".join(f"{k} {v}" for k, v in versions().items()))
    print("microseconds per row (best of", args.repeat, "runs); before: one dict a row; after: a table a group")
    head = ("grid", "rows", "json before", "after", "csv before", "after", "parquet before", "after", "table",
            "files equal")  # fmt: skip
    print("{:<38} {:>5} {:>11} {:>6} {:>10} {:>6} {:>14} {:>6} {:>6}  {}".format(*head))
    with one_blas_thread, tempfile.TemporaryDirectory() as tmp:
        for name, at, axes in grids:
            r = bench(name, at, axes, args.repeat, Path(tmp))
            equal = "csv bytes {}, json {}, parquet {}".format(r["csv_equal"], r["json_equal"], r["parquet_equal"])
            print(f"{r['grid']:<38} {r['rows']:>5} {r['json_before']:>11.1f} {r['json_after']:>6.1f} "
                  f"{r['csv_before']:>10.1f} {r['csv_after']:>6.1f} {r['parquet_before']:>14.1f} "
                  f"{r['parquet_after']:>6.1f} {r['table']:>6.1f}  {equal}")  # fmt: skip


if __name__ == "__main__":
    main()
