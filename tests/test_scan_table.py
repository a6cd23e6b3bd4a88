"""Scan rows kept as columns (:class:`pinmob.scan.ScanTable`) and written column by column: the files of the
row-by-row writers, byte for byte (CSV) or as data (JSON, and the new Parquet file); the scan's report.

The reference writers below are the row writers pinmob used before the table (one ``csv.DictWriter`` row and one
``json.dumps`` per row dict), kept here only as the independent truth; the rows they write are the engine's own
dicts (:func:`pinmob.scan.lockstep.run_group`), before any table.
"""

from __future__ import annotations

import csv
import html
import io
import json
import math
import re
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq
import pytest

import pinmob
from pinmob.cli import main
from pinmob.scan import CHUNK, ScanReport, ScanTable, columns, grid_spec, path_spec, scan, with_finite
from pinmob.scan.lockstep import GROUP, LOCAL_GROUP, run_group
from pinmob.scan.results.output import RowWriter
from pinmob.scan.results.table import column_type
from pinmob.scan.scan_run import chunk_groups

DATA = Path(__file__).parent / "data"


def reference_csv(cols: list[str], rows: list[dict[str, Any]]) -> bytes:
    """The CSV the row writer wrote: floats as ``%.10g``, the rest as :mod:`csv` writes them."""
    out = io.StringIO(newline="")
    writer = csv.DictWriter(out, cols)
    writer.writeheader()
    for row in rows:
        writer.writerow({k: (f"{v:.10g}" if isinstance(v, float) else v) for k, v in row.items()})
    return out.getvalue().encode()


def reference_json(cols: list[str], meta: dict[str, Any], rows: list[dict[str, Any]]) -> Any:
    """The JSON data the row writer wrote: each row's keys in the CSV's order, non-finite floats null."""
    known = set(cols)
    samples = []
    for row in rows:
        keys = [k for k in cols if k in row] + [k for k in row if k not in known]
        samples.append({k: (None if isinstance(row[k], float) and not math.isfinite(row[k]) else row[k]) for k in keys})
    return json.loads(json.dumps({"scan": meta, "samples": samples}, allow_nan=False))


def engine_rows(mech: pinmob.Mechanism, spec: pinmob.scan.ScanSpec) -> list[dict[str, Any]]:
    """The engine's row dicts, group after group (no table involved)."""
    groups = chunk_groups(mech, spec, first_alone=False)
    return [row for group in groups for row in run_group(mech, spec, group).dicts()]


def same(a: Any, b: Any) -> bool:
    """Equal, NaN equal to NaN."""
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    return a == b and type(a) is type(b)


def scans() -> list[tuple[str, Any]]:
    """Scans whose rows hold every kind of value: refined points, unreachable rows (reasons with commas), a closed
    chain's None verdicts, finite DoF, the CAD columns."""
    puu, fivebar = pinmob.load("3-PUU"), pinmob.load(DATA / "fivebar" / "robot.yaml")
    prs = pinmob.load("3-PRS")
    return [
        ("3-PUU x-y grid with singular rows", lambda: (puu, grid_spec(puu, "generic", [("x", -0.1, -0.1, 1), ("y", -0.02, 0.02, 5)]))),
        ("3-PUU grid with unreachable rows", lambda: (puu, grid_spec(puu, "generic", [("x", -0.3, 0.3, 4), ("y", -0.3, 0.3, 3)]))),
        ("3-PRS roll x z grid", lambda: (prs, grid_spec(prs, "home", [("roll", -3.0, 3.0, 4), ("z", 0.0, 0.4, 3)]))),
        ("five-bar joint path through its edges", lambda: (fivebar, path_spec(fivebar, "mot1=0,mot2=0", "mot1=3,mot2=-3", 9))),
        ("3-PUU-flat path with finite DoF", lambda: (pinmob.load("3-PUU-flat"), with_finite(pinmob.load("3-PUU-flat"), path_spec(pinmob.load("3-PUU-flat"), "flat", "flat-raised", 4)))),
    ]  # fmt: skip


@pytest.mark.parametrize("case", range(5))
def test_files_are_the_row_writers_files(tmp_path: Path, case: int) -> None:
    """CSV byte for byte, JSON and Parquet equal as data to the row writers' files of the engine's rows."""
    name, make = scans()[case]
    mech, spec = make()
    rows = engine_rows(mech, spec)
    cols = columns(spec)
    paths = {k: tmp_path / f"s.{k}" for k in ("csv", "json", "parquet")}
    report = scan(mech, spec, progress=False, **{k: str(p) for k, p in paths.items()})
    assert paths["csv"].read_bytes() == reference_csv(cols, rows), name
    written = json.loads(paths["json"].read_bytes())
    meta = written["scan"]
    assert written == reference_json(cols, meta, rows), name
    assert meta["mechanism"] == mech.name and meta["scan"] == report.what
    table = pq.read_table(paths["parquet"])
    assert table.column_names == cols
    assert json.loads(table.schema.metadata[b"pinmob_scan"]) == meta
    for k, row in enumerate(table.to_pylist()):  # blank text in a typed column (a chain's unreachable row): null
        expected = {c: None if rows[k].get(c) == "" and column_type(c) != "text" else rows[k].get(c) for c in cols}
        assert all(same(row[c], expected[c]) for c in cols), (name, k)
    assert all(all(same(a[c], b[c]) for c in b) and a.keys() == b.keys() for a, b in zip(report, rows))


def same_table(a: ScanTable, b: ScanTable) -> bool:
    """The same columns, array types, values (NaN equal to NaN; objects of the same type), null and absent masks."""
    if a.names != b.names or a.null.keys() != b.null.keys() or a.absent.keys() != b.absent.keys():
        return False
    for n in a.names:
        x, y = a.data[n], b.data[n]
        if x.dtype != y.dtype or len(x) != len(y):
            return False
        if x.dtype == object and not all(same(u, v) for u, v in zip(x.tolist(), y.tolist())):
            return False
        if x.dtype != object and not np.array_equal(x, y, equal_nan=x.dtype.kind == "f"):
            return False
    return all(np.array_equal(a.null[n], b.null[n]) for n in a.null) and all(
        np.array_equal(a.absent[n], b.absent[n]) for n in a.absent
    )


def test_rows_kept_in_arrays_are_read_as_columns_only_when_all_are():
    """A group's heads and joint values are read as columns of its arrays only when every one is a row of the same
    array; a dict among them, first or after, sends the group to its dicts (the rows of a sample assembled on its
    own are dicts). A dict first raised AttributeError (its ``params``, ``table`` read) before."""
    from pinmob.scan.group_rows import Head, _head_columns, _value_columns
    from pinmob.scan.row_columns import ArrayRow

    params = (["x"], np.array([[0.1], [0.2]]))
    head = {"index": 7, "x": 0.3, "refined": False}
    got = _head_columns([Head(3, params, 1), Head(5, params, 0)])
    assert got is not None
    assert got["index"].tolist() == [3, 5] and got["x"].tolist() == [0.2, 0.1] and got["refined"].tolist() == [0, 0]
    other = (["x"], params[1].copy())  # the same numbers in another array: not one group's columns
    for heads in ([head, Head(3, params, 1)], [Head(3, params, 1), head], [Head(3, params, 1), Head(5, other, 0)]):
        assert _head_columns(heads) is None
    table = np.array([[1.0, 2.0], [3.0, 4.0]])
    got = _value_columns([ArrayRow(("q_a", "q_b"), table, 1), ArrayRow(("q_a", "q_b"), table, 0)])
    assert got is not None and got["q_a"].tolist() == [3.0, 1.0] and got["q_b"].tolist() == [4.0, 2.0]
    values = {"q_a": 5.0, "q_b": 6.0}
    for rows in ([values, ArrayRow(("q_a", "q_b"), table, 0)], [ArrayRow(("q_a", "q_b"), table, 0), values]):
        assert _value_columns(rows) is None


@pytest.mark.parametrize("robot, at, axes, mixed", [
    ("3-PUU", "generic", [("x", -0.3, 0.3, 9), ("y", -0.3, 0.3, 7)], True),  # decided, unreachable, refined rows
    ("3-PUU", "generic", [("A_slider", -0.2, 0.2, 9), ("B_slider", -0.2, 0.2, 9)], True),  # limb singularities
    ("3-RPS", "home", [("roll", -0.3, 0.3, 7), ("pitch", -0.3, 0.3, 7)], False),  # following coordinates
    ("6-UPS", "home", [("x", -0.05, 0.05, 5), ("yaw", -0.2, 0.2, 5)], False),
])  # fmt: skip
def test_a_group_table_is_the_table_of_its_row_dicts(robot: str, at: str, axes: list[Any], mixed: bool) -> None:
    """The table a group makes with the batch's rows kept as its columns (:meth:`GroupRows.table`) is the table of
    its row dicts (:meth:`ScanTable.from_rows` of :meth:`GroupRows.dicts`): the same arrays, types and masks."""
    from pinmob.scan.group_rows import BatchRow, Head
    from pinmob.scan.row_columns import ArrayRow

    mech = pinmob.load(robot)
    spec = grid_spec(mech, at, axes)
    kinds, columnar = set(), set()
    for group in chunk_groups(mech, spec, first_alone=False):
        rows = run_group(mech, spec, group)
        kinds |= {isinstance(e, BatchRow) for e in rows.entries}
        ours = [e for e in rows.entries if isinstance(e, BatchRow)]
        columnar |= {isinstance(e.head, Head) and isinstance(e.values, ArrayRow) for e in ours}
        assert same_table(rows.table(columns(spec)), ScanTable.from_rows(columns(spec), rows.dicts()))
    assert kinds == ({True, False} if mixed else {True})  # with both kinds of row: merged
    assert True in columnar  # heads and joint values kept as rows of the group's arrays, read as its columns


def test_the_rows_do_not_depend_on_the_groups() -> None:
    """A 3-PUU grid of 40 lines running off the workspace: in groups of ``GROUP`` (a Dask worker's: 32 lines and 8),
    of ``LOCAL_GROUP`` (this process's: all 40 in one) and of 7, the same table (unreachable and refined rows too)."""
    assert GROUP < 40 <= LOCAL_GROUP
    mech = pinmob.load("3-PUU")
    spec = grid_spec(mech, "generic", [("x", -0.16, 0.16, 40), ("y", -0.05, 0.05, 4)])
    names = columns(spec)
    tables = {}
    for size in (GROUP, LOCAL_GROUP, 7):
        groups = list(chunk_groups(mech, spec, first_alone=False, size=size))
        assert [len(g) for g in groups][:2] == {GROUP: [32, 8], LOCAL_GROUP: [40], 7: [7, 7]}[size]
        tables[size] = ScanTable.concat([run_group(mech, spec, g).table(names) for g in groups], names)
    rows = list(tables[GROUP].rows())
    assert any(not r["reachable"] for r in rows) and any(r["refined"] for r in rows) and len(rows) > 160
    assert same_table(tables[GROUP], tables[LOCAL_GROUP]) and same_table(tables[GROUP], tables[7])


def test_a_table_writes_every_kind_of_value_as_the_csv_module_does(tmp_path: Path) -> None:
    """Text that needs quoting, None in whole-number and boolean columns, a key a row lacks, a whole number in a
    float column, non-finite floats: the CSV of :mod:`csv`, the JSON of :mod:`json`, streamed a table at a time."""
    cols = ["index", "x", "reachable", "dof", "reason", "actuation_valid", "finite_dof", "sv1"]
    rows: list[dict[str, Any]] = [
        dict(index=0, x=0.1, reachable=True, dof=3, reason="", actuation_valid=True, finite_dof=None, sv1=float("nan")),
        dict(index=1, x=1e-17, reachable=False, dof=-1, reason='limb A open, by "2e-3 m"\nand\r B', actuation_valid=None),
        dict(index=2, x=5, reachable=True, dof=2, reason="über, ünïcode", actuation_valid=False, finite_dof=2,
             sv1=float("inf")),
        dict(index=3, x=-0.0, reachable=True, dof=2, reason=" lead space", actuation_valid=False, finite_dof=1,
             sv1=123456789012.5),
    ]  # fmt: skip
    meta = {"mechanism": "toy", "rtol": 1e-6}
    c, j, p = tmp_path / "t.csv", tmp_path / "t.json", tmp_path / "t.parquet"
    with RowWriter(cols, meta, str(c), str(j), str(p)) as writer:
        writer.write_table(ScanTable.from_rows(cols, rows[:1]))
        writer.write_table(ScanTable.from_rows(cols, []))
        writer.write_table(ScanTable.from_rows(cols, rows[1:]))
    assert c.read_bytes() == reference_csv(cols, rows)
    assert json.loads(j.read_bytes()) == reference_json(cols, meta, rows)
    back = pq.read_table(p).to_pylist()
    assert back[1]["finite_dof"] is None and back[1]["sv1"] is None and back[1]["actuation_valid"] is None
    assert back[2]["x"] == 5.0 and back[1]["reason"] == rows[1]["reason"]
    table = ScanTable.from_rows(cols, rows)
    assert table.kinds()["dof"] == "int" and table.kinds()["x"] == "object"  # 5 is not a float: written as it was
    assert [list(r) for r in table.rows()][1] == [k for k in cols if k in rows[1]]  # the keys it had, in order
    with pytest.raises(ValueError, match="not columns"):
        ScanTable.from_rows(cols[:2], rows)


def test_the_report_is_what_pinmob_scan_prints(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``str(report)`` of the Python call is the summary the command prints (the timing aside), and its dict and
    HTML carry the same counts."""
    mech = pinmob.load("3-PUU")
    spec = grid_spec(mech, "generic", [("x", -0.1, -0.1, 1), ("y", -0.02, 0.02, 5)])
    csv_path = tmp_path / "g.csv"
    report = scan(mech, spec, progress=False, csv=str(csv_path))
    assert isinstance(report, ScanReport) and len(report) == len(list(report))
    argv = ["scan", "3-PUU", "--grid", "x:-0.1:-0.1:1", "y:-0.02:0.02:5", "--at", "generic", "--no-progress"]
    assert main([*argv, "--csv", str(csv_path), "--force"]) == 0
    timing = re.compile(r"in [0-9.]+ s \([0-9.]+ samples/s")
    assert timing.sub("", capsys.readouterr().out) == timing.sub("", str(report)) + "\n"
    d = report.to_dict()
    assert d["counts"] == dict(report.summary.counts) and d["singular"] >= 1 and d["files"] == {"csv": str(csv_path)}
    assert json.loads(json.dumps(d, allow_nan=False)) == d
    assert html.escape(str(report).splitlines()[0]) in report._repr_html_()
    singular = [r for r in report if r["singularity"] != "none" and r["reachable"]]
    assert d["singular"] == sum(not r["refined"] for r in singular)
    assert np.array_equal(report.table["index"], [r["index"] for r in report])


def test_rows_reach_the_files_as_they_come(monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    """Each group of chunks is written before the next one is computed (with ``workers=2`` the first chunk runs
    alone, to time it), and nothing is kept with ``keep_rows=False``: the summary is counted as the rows pass."""
    import pinmob.scan.scan_run as run

    events: list[str] = []
    group, write = run.run_group, RowWriter.write_table
    monkeypatch.setattr(run, "run_group", lambda *a: events.append("computed") or group(*a))
    monkeypatch.setattr(RowWriter, "write_table", lambda self, t: events.append(f"wrote {len(t)}") or write(self, t))
    mech = pinmob.load("3-PUU")
    report = scan(mech, path_spec(mech, "generic", "offset", 40), workers=2, progress=False,
                  csv=str(tmp_path / "p.csv"), keep_rows=False)  # fmt: skip
    assert events[:3] == ["computed", f"wrote {CHUNK}", "computed"] and events[-1].startswith("wrote")
    assert report.table is None and sum(report.summary.counts.values()) == 40
    assert len((tmp_path / "p.csv").read_text().splitlines()) == 1 + sum(int(e[6:]) for e in events if e[0] == "w")


@pytest.mark.parametrize("reason", ["limb A open, by 2e-3 m", 'a},{"b": 1},{c', "}", [{"a": 1}, {"b": [2]}]])
def test_json_rows_are_one_object_a_line_whatever_their_text(reason: Any) -> None:
    """:meth:`ScanTable.json_lines`: each row's object on a line of its own, equal as data to :mod:`json`'s of the
    row, also where a text value holds the ``},{`` that separates two objects, or a value is a list of objects
    (then written row by row)."""
    cols = ["index", "x", "reason", "dof"]
    rows: list[dict[str, Any]] = [
        dict(index=0, x=0.5, reason="", dof=3),
        dict(index=1, x=float("nan"), reason=reason, dof=None),
        dict(index=2, x=-1e-300, reason=reason * 2, dof=2),
    ]
    lines = ScanTable.from_rows(cols, rows).json_lines().split(b",\n")  # a JSON text holds no raw line break
    assert [json.loads(line) for line in lines] == reference_json(cols, {}, rows)["samples"]


@pytest.mark.parametrize("reason", ['a","b', "x,y", "", None, 3, True, 2.5, [1, {"c": 2}]])
@pytest.mark.parametrize("leave_out", [False, True])
def test_json_rows_written_by_columns_are_each_row_dumped_by_orjson(reason: Any, leave_out: bool) -> None:
    """:meth:`ScanTable.json_lines` writes column by column (text holding commas and quotes, missing numbers,
    non-finite floats, -0.0, a text column holding other values, a column named with %) the bytes orjson gives
    each row, joined by a comma and a line break; and, where a row leaves a key out, row by row."""
    import orjson

    cols = ["index", "x", "reachable", "reason", "dof", "motion_type", "joint_%s%"]  # a joint's name holds a %
    rows: list[dict[str, Any]] = [
        dict(index=0, x=0.5, reachable=True, reason="", dof=3, motion_type="3T"),
        dict(index=1, x=float("nan"), reachable=False, reason=reason, dof=None, motion_type=None),
        dict(index=2, x=-0.0, reachable=True, reason=reason, dof=2, motion_type='"1T,2R"'),
        dict(index=3, x=float("inf"), reachable=True, reason="}", dof=-1, motion_type="1T,2R"),
    ]
    for i, row in enumerate(rows):
        row["joint_%s%"] = 0.1 * i
    if leave_out:
        del rows[2]["dof"]
    assert ScanTable.from_rows(cols, rows).json_lines() == b",\n".join(orjson.dumps(row) for row in rows)


def test_json_rows_of_columns_of_any_array_type_are_each_row_dumped_by_orjson() -> None:
    """:meth:`ScanTable.from_columns` keeps arrays as they are: a numpy string column (commas in its text) and a 2-D
    column are written value by value, as orjson writes each row (only 1-D numbers and booleans are split at
    commas)."""
    import orjson

    table = ScanTable.from_columns(["reason", "x", "pair"], {"reason": np.array(["a,b", 'c","d']),
                                                              "x": np.array([1.0, 2.0]),
                                                              "pair": np.array([[1.0, 2.0], [3.0, 4.0]])})  # fmt: skip
    rows = [{"reason": "a,b", "x": 1.0, "pair": [1.0, 2.0]}, {"reason": 'c","d', "x": 2.0, "pair": [3.0, 4.0]}]
    assert table.json_lines() == b",\n".join(orjson.dumps(row) for row in rows)


def test_json_number_columns_written_from_their_arrays_are_each_row_dumped_by_orjson() -> None:
    """A number or boolean column with a value in every row is written from its array (orjson's numpy encoder): the
    bytes of each row's dict of Python values, for floats of every exponent and the non-finite ones, whole numbers to
    2**62 and booleans (a column with a missing value: from its list)."""
    import orjson

    rng = np.random.default_rng(3)
    n = 400
    x = rng.normal(size=n) * 10.0 ** rng.integers(-300, 300, n)
    x[:8] = [np.nan, np.inf, -np.inf, 0.0, -0.0, 5e-324, 1.7976931348623157e308, 0.1]
    data = {"index": rng.integers(-(2**62), 2**62, n), "x": x, "reachable": rng.random(n) > 0.5}
    table = ScanTable.from_columns(["index", "x", "reachable"], data)
    rows = [{k: v for k, v in zip(data, values)} for values in zip(*(a.tolist() for a in data.values()))]
    assert table.json_lines() == b",\n".join(orjson.dumps(row) for row in rows)


@pytest.mark.parametrize("names", [["x", "x"], ["x", 1]])
def test_a_table_refuses_repeated_or_non_text_column_names(names: list[Any]) -> None:
    """A table's columns are distinct names: a repeated one or one that is not text (which a JSON object's key
    must be) is refused, naming the columns."""
    with pytest.raises(ValueError, match="distinct names"):
        ScanTable.from_columns(names, {n: np.zeros(2) for n in names})
