"""Checks shared by the parts of a sweep spec file, and its [design] table (see :mod:`pinmob.sweeps.spec_file`)."""

from __future__ import annotations

import csv
import math
from pathlib import Path
from typing import Any

import numpy as np

from pinmob.exceptions import ConfigurationError
from pinmob.name_matching import choices
from pinmob.sweeps.designs import MAX_DESIGNS, METHODS, DesignSet, check_count, latin_hypercube

DESIGN = ("method", "parameters", "samples", "seed", "table", "rows", "max_designs")


def keys(where: str, prefix: str, table: dict[str, Any], valid: tuple[str, ...]) -> None:
    """Refuse a key of ``table`` not in ``valid`` (the message lists them)."""
    for key in table:
        if key not in valid:
            raise ConfigurationError(f"{where}: unknown key {prefix + key!r}; valid: {choices(valid)}")


def table_of(where: str, key: str, doc: dict[str, Any]) -> dict[str, Any]:
    """The table ``doc[key]`` (empty when absent; anything else is an error)."""
    value = doc.get(key, {})
    if not isinstance(value, dict):
        raise ConfigurationError(f"{where}: {key!r} must be a table ([{key}]), got {value!r}")
    return value


def number(where: str, key: str, value: object) -> float:
    """A finite number (not a boolean)."""
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ConfigurationError(f"{where}: {key} must be a finite number, got {value!r}")
    return float(value)


def integer(where: str, key: str, value: object, least: int) -> int:
    """A whole number of at least ``least``."""
    if isinstance(value, bool) or not isinstance(value, int) or value < least:
        raise ConfigurationError(f"{where}: {key} must be a whole number, at least {least}, got {value!r}")
    return value


def read_designs(path: Path, table: dict[str, Any]) -> DesignSet:
    """The design set of a [design] table (grid, random, Latin hypercube or table).

    The number of designs is checked against ``design.max_designs`` (default
    :data:`~pinmob.sweeps.designs.MAX_DESIGNS`) before anything of that size is built.
    """
    where = str(path)
    keys(where, "design.", table, DESIGN)
    method = table.get("method", "grid")
    if method not in METHODS:
        raise ConfigurationError(f"{where}: unknown design.method {method!r}; valid: {choices(METHODS)}")
    bound = integer(where, "design.max_designs", table.get("max_designs", MAX_DESIGNS), 1)
    if method == "table":
        return _design_table(path, table, bound)
    params = table.get("parameters", {})
    if not isinstance(params, dict) or not params:
        raise ConfigurationError(f"{where}: [design.parameters] must name at least one swept parameter")
    ranges = []
    for name, value in params.items():
        key, size = f"design.parameters.{name}", (3 if method == "grid" else 2)
        shape = "[low, high, count]" if method == "grid" else "[low, high]"
        if not isinstance(value, list) or len(value) != size:
            raise ConfigurationError(f"{where}: {key} must be {shape} for a {method} design, got {value!r}")
        lo, hi = number(where, key, value[0]), number(where, key, value[1])
        count = integer(where, f"{key} count", value[2], 0) if method == "grid" else 0
        if lo > hi or (method == "grid" and count == 0):
            raise ConfigurationError(f"{where}: {key} is an empty range {value!r} (need low <= high and count >= 1)")
        if method == "grid" and lo == hi and count > 1:
            raise ConfigurationError(f"{where}: {key} = {value!r} repeats one value {count} times; give count 1")
        ranges.append((lo, hi, count))
    names = tuple(params)
    if method == "grid":
        grid = DesignSet("grid", names, tuple(ranges), max_designs=bound)
        check_count(grid.count, bound, where)
        return grid
    samples = check_count(integer(where, "design.samples", table.get("samples", 0), 1), bound, where)
    seed = integer(where, "design.seed", table.get("seed", 0), 0)
    if method == "random":
        return DesignSet("random", names, tuple(ranges), samples, seed, max_designs=bound)
    hypercube = latin_hypercube(tuple(ranges), samples, seed)
    return DesignSet(method, names, tuple(ranges), samples, seed, hypercube, max_designs=bound)


def _design_table(path: Path, table: dict[str, Any], bound: int) -> DesignSet:
    where = str(path)
    if ("table" in table) == ("rows" in table):
        raise ConfigurationError(f'{where}: a table design takes table = "FILE.csv" or rows = [...], one of them')
    if "rows" in table:
        rows = table["rows"]
        if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) for r in rows):
            raise ConfigurationError(f"{where}: design.rows must be a non-empty list of tables {{name = value}}")
        names = tuple(rows[0])
        for i, row in enumerate(rows):
            if tuple(row) != names:
                raise ConfigurationError(f"{where}: design.rows[{i}] names {list(row)}, row 0 names {list(names)}")
        check_count(len(rows), bound, where)
        values = [[number(where, f"design.rows[{i}].{k}", row[k]) for k in names] for i, row in enumerate(rows)]
    else:
        csv_path = path.parent / str(table["table"])
        try:
            with open(csv_path, newline="", encoding="utf-8") as fh:
                reader = csv.reader(fh)
                names = tuple(h.strip() for h in next(reader, []))
                lines = []
                for line in reader:  # read no further than the bound
                    if line:
                        lines.append(line)
                        if len(lines) > bound:
                            raise ConfigurationError(
                                f"{where}: design.table {str(csv_path)!r} has more than {bound:,} designs, the bound; "
                                "split the sweep, or raise the bound in the spec's [design] table: max_designs = N"
                            )
        except (OSError, UnicodeDecodeError, csv.Error) as exc:
            raise ConfigurationError(f"{where}: design.table {str(csv_path)!r} cannot be read: {exc}") from None
        if not names or not lines:
            raise ConfigurationError(f"{where}: design.table {str(csv_path)!r} needs a header and at least one row")
        values = []
        for i, line in enumerate(lines):
            if len(line) != len(names):
                raise ConfigurationError(
                    f"{where}: {csv_path.name} row {i + 1} has {len(line)} values for {len(names)} names"
                )
            try:
                values.append([float(v) for v in line])
            except ValueError:
                raise ConfigurationError(
                    f"{where}: {csv_path.name} row {i + 1} holds a value that is not a number"
                ) from None
            if not all(math.isfinite(v) for v in values[-1]):
                raise ConfigurationError(f"{where}: {csv_path.name} row {i + 1} holds a value that is not finite")
    return DesignSet("table", names, table=np.array(values, float), max_designs=bound)
