"""Reading a sweep spec (TOML): every mistake is one error naming the key and the valid choices, before any work.

::

    title = "3-PUU: link length against guide radius"   # optional
    family = "3-PUU"                  # a built-in family (pinmob.catalog.families), or:
    # template = "robot.toml"         # a pinmob mechanism file with {parameter} placeholders
    # files = ["robot.urdf"]          # the files beside it that it needs (default: the URDF it names)

    [parameters]                      # values common to every design (a family's others keep their defaults)
    small_r = 0.15

    [units]                           # a template's parameter units, for the records and plots (optional)

    [design]
    method = "grid"                   # grid, random, latin-hypercube or table
    # samples = 200, seed = 1         # random and latin-hypercube
    # table = "designs.csv"           # table: a CSV file with a header of parameter names, or
    # rows = [{link = 0.2}, ...]      # the rows inline
    [design.parameters]
    link = [0.2, 0.35, 7]             # grid: [low, high, count]; random and latin-hypercube: [low, high]
    big_r = [0.25, 0.4, 7]

    [scan]                            # per design, as pinmob scan: a grid (1 to 3 pose coordinates or joints) ...
    grid = ["x:-0.06:0.06:9", "y:-0.06:0.06:9"]
    at = "generic"                    # default: the design's first configuration
    # from = "generic", to = "offset", samples = 21, joints = false   # ... or a path (ends: names, poses,
    #                                                                 # or joint values "A=0.1,B=0.2")
    # rtol = 1e-6

    [plots]                           # optional
    atlas = { x = "link", y = "big_r", color = "singularity_free" }
    pareto = { x = "assembled", y = "min_distance", x_goal = "max", y_goal = "max" }

Top-level, optional: ``finite = true`` adds to each record the finite-mobility analysis at the
reference configuration (:data:`pinmob.sweeps.fields.FINITE_FIELDS`; ``finite_order = K``, 2..8,
default 4, sets its order bound and implies ``finite = true``); ``[design] max_designs = N`` raises
the bound on the number of designs (:data:`pinmob.sweeps.designs.MAX_DESIGNS`).
"""

from __future__ import annotations

import csv
import math
import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from pinmob.analysis import ORDER, check_order
from pinmob.catalog import family
from pinmob.exceptions import ConfigurationError, PinmobError
from pinmob.name_matching import choices
from pinmob.scan import POSE_COORDS, check_coordinates, parse_grid_axis
from pinmob.screw import check_rtol
from pinmob.sweeps.designs import MAX_DESIGNS, METHODS, DesignSet, check_count, latin_hypercube
from pinmob.sweeps.fields import TYPES
from pinmob.sweeps.source import Source, template_source
from pinmob.sweeps.sweep_spec import ScanSettings, SweepSpec

TOP = (
    "title",
    "family",
    "template",
    "files",
    "parameters",
    "units",
    "design",
    "scan",
    "plots",
    "finite",
    "finite_order",
)
SCAN = ("grid", "at", "from", "to", "samples", "joints", "rtol")
GOALS = ("max", "min")


def load_spec(path: str | Path) -> SweepSpec:
    """The sweep a TOML file describes (see the module docstring).

    Raises:
        ConfigurationError: the file is missing or not TOML, an unknown key, family or parameter, an empty
            range, a template placeholder with no value, an unknown configuration, a plot of an unknown field.
    """
    path = Path(path).expanduser()
    where = str(path)
    try:
        doc = tomllib.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise ConfigurationError(f"sweep spec {where!r} does not exist") from None
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigurationError(f"sweep spec {where!r} cannot be read as UTF-8 text: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigurationError(f"{where}: TOML syntax error: {exc}") from None
    keys(where, "", doc, TOP)
    source = _source(path, doc)
    known = source.parameters()
    fixed = {k: number(where, f"parameters.{k}", v) for k, v in table_of(where, "parameters", doc).items()}
    designs = read_designs(path, table_of(where, "design", doc))
    for name in (*fixed, *designs.names):
        if name not in known:
            what = "placeholder of the template uses" if not source.family else f"family {source.family!r} has"
            raise ConfigurationError(f"{where}: unknown parameter {name!r}: no {what} it; valid: {choices(known)}")
    both = sorted(set(fixed) & set(designs.names))
    if both:
        raise ConfigurationError(f"{where}: parameter {both[0]!r} is both fixed ([parameters]) and swept ([design])")
    if not source.family:
        _every_placeholder_has_a_value(where, source, set(fixed) | set(designs.names))
    scan = _scan(where, table_of(where, "scan", doc))
    spec = SweepSpec(str(doc.get("title") or path.stem), source, fixed, designs, scan,
                     finite_order=_finite_order(where, doc))  # fmt: skip
    spec = _with_references(where, spec)
    return _with_plots(where, spec, table_of(where, "plots", doc))


def _finite_order(where: str, doc: dict[str, Any]) -> int | None:
    """The finite analysis's order bound (None: not asked for); ``finite_order`` implies ``finite = true``."""
    finite = doc.get("finite")
    if finite is not None and not isinstance(finite, bool):
        raise ConfigurationError(f"{where}: finite must be true or false, got {finite!r}")
    if "finite_order" not in doc:
        return ORDER if finite else None
    if finite is False:
        raise ConfigurationError(f"{where}: finite_order sets the finite analysis's order bound, but finite = false")
    try:
        return check_order(doc["finite_order"])
    except PinmobError as exc:
        raise ConfigurationError(f"{where}: finite_order: {exc}") from None


def _source(path: Path, doc: dict[str, Any]) -> Source:
    where = str(path)
    if ("family" in doc) == ("template" in doc):
        raise ConfigurationError(
            f"{where}: give either family = NAME (a built-in family) or template = FILE (a mechanism file with "
            "{parameter} placeholders), not both nor neither"
        )
    units = table_of(where, "units", doc)
    if "family" in doc:
        for key in ("files", "units"):
            if key in doc:
                raise ConfigurationError(f"{where}: {key!r} belongs to a template; a family knows its files and units")
        try:
            fam = family(str(doc["family"]))
        except PinmobError as exc:
            raise ConfigurationError(f"{where}: {exc}") from None
        return Source(family=fam.name, units=fam.units())
    files = doc.get("files", [])
    if not isinstance(files, list) or not all(isinstance(f, str) for f in files):
        raise ConfigurationError(f"{where}: files must be a list of file names, got {files!r}")
    if not all(isinstance(u, str) for u in units.values()):
        raise ConfigurationError(f'{where}: [units] values must be strings such as "m" or "rad"')
    return template_source(path.parent / str(doc["template"]), files, units, where)


def _every_placeholder_has_a_value(where: str, source: Source, given: set[str]) -> None:
    from pinmob.sweeps.template import names_used, placeholders

    for fname, text in source.texts:
        for expr in placeholders(text):
            missing = sorted(names_used(expr, fname) - given)
            if missing:
                raise ConfigurationError(
                    f"{where}: template placeholder {{{expr}}} in {fname} uses {missing[0]!r}, which has no value; "
                    f"give it in [parameters] or [design.parameters] (given: {choices(given)})"
                )


def _scan(where: str, table: dict[str, Any]) -> ScanSettings:
    keys(where, "scan.", table, SCAN)
    rtol = check_rtol(table["rtol"], "scan.rtol") if "rtol" in table else ScanSettings.rtol
    if "grid" in table:
        path_keys = [k for k in ("from", "to", "samples", "joints") if k in table]
        if path_keys:
            raise ConfigurationError(
                f"{where}: scan.grid scans a workspace slice; {', '.join(path_keys)} belong to a path"
            )
        grid = table["grid"]
        if not isinstance(grid, list) or not 1 <= len(grid) <= 3:
            raise ConfigurationError(
                f'{where}: scan.grid must be one to three axes ["x:LO:HI:N", "y:LO:HI:N"] (pose coordinates or '
                f"joints), got {grid!r}"
            )
        axes = tuple(parse_grid_axis(text, "scan.grid") for text in grid)
        for name, lo, hi, n in axes:
            if not name:
                raise ConfigurationError(
                    f"{where}: scan.grid axis without a coordinate; give a pose coordinate ({choices(POSE_COORDS)}) "
                    "or a joint name"
                )
            if n < 1 or lo > hi:
                raise ConfigurationError(f"{where}: scan.grid axis {name} is an empty range ({lo}, {hi}, {n})")
        names = [a[0] for a in axes]
        if len(set(names)) != len(names):
            raise ConfigurationError(f"{where}: scan.grid needs different coordinates, got {names}")
        return ScanSettings(axes=axes, at=_text(where, table, "at"), rtol=rtol)
    if "at" in table:
        raise ConfigurationError(
            f"{where}: scan.at fixes the other coordinates of a scan.grid; a path takes from and to"
        )
    samples = integer(where, "scan.samples", table.get("samples", 21), 2)
    joints = table.get("joints", False)
    if not isinstance(joints, bool):
        raise ConfigurationError(f"{where}: scan.joints must be true or false, got {joints!r}")
    return ScanSettings(start=_text(where, table, "from"), end=_text(where, table, "to"), samples=samples,
                        joints=joints, rtol=rtol)  # fmt: skip


def _text(where: str, table: dict[str, Any], key: str) -> str | None:
    value = table.get(key)
    if value is not None and not isinstance(value, str):
        raise ConfigurationError(f"{where}: scan.{key} must be a configuration name or a pose 'x,y,z,roll,pitch,yaw'")
    return value


def _with_references(where: str, spec: SweepSpec) -> SweepSpec:
    """Configuration names checked against the first design's mechanism file; defaults filled in."""
    from dataclasses import replace

    try:
        names = spec.source.configuration_names(spec.values(0))
    except PinmobError as exc:
        raise ConfigurationError(f"{where}: the first design's mechanism file cannot be read: {exc}") from None
    scan = spec.scan
    wanted = {"at": scan.at} if scan.is_grid else {"from": scan.start, "to": scan.end}
    needed = 1 if scan.is_grid else 2
    for i, (key, value) in enumerate(wanted.items()):
        if value is None:
            if len(names) < needed:
                raise ConfigurationError(
                    f"{where}: the mechanism has {len(names)} named configuration(s); give scan.{key}"
                )
            wanted[key] = names[i]
        elif value not in names and len(value.split(",")) != 6 and (scan.is_grid or "=" not in value):
            joints = "" if scan.is_grid else ", nor joint values NAME=VALUE,... [rad or m]"
            raise ConfigurationError(
                f"{where}: scan.{key} {value!r} is neither a configuration of {spec.source.name!r} "
                f"({choices(names)}) nor a pose 'x,y,z,roll,pitch,yaw' [m, rad]{joints}"
            )
    if scan.is_grid and any(a[0] not in POSE_COORDS for a in scan.axes):
        _check_grid_joints(where, spec)
    if scan.is_grid:
        return replace(spec, scan=replace(scan, at=wanted["at"]))
    return replace(spec, scan=replace(scan, start=wanted["from"], end=wanted["to"]))


def _check_grid_joints(where: str, spec: SweepSpec) -> None:
    """A grid's coordinates checked against the first design's mechanism (its joints are known once it is loaded)."""
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        try:
            mech = spec.source.mechanism(spec.values(0), Path(folder))
        except PinmobError as exc:
            raise ConfigurationError(f"{where}: the first design's mechanism cannot be loaded: {exc}") from None
        try:
            check_coordinates(mech, [a[0] for a in spec.scan.axes], "scan.grid")
        except ConfigurationError as exc:
            raise ConfigurationError(f"{where}: scan.grid: {exc}") from None


def _with_plots(where: str, spec: SweepSpec, table: dict[str, Any]) -> SweepSpec:
    from dataclasses import replace

    keys(where, "plots.", table, ("atlas", "pareto"))
    numeric = [n for n, k in spec.fields() if k in ("int", "float", "bool") and n != "design"]
    fields = [n for n, _ in spec.fields() if n != "design"]
    swept = spec.designs.names
    plots: dict[str, dict[str, str]] = {}
    atlas = dict(table.get("atlas", {}))
    keys(where, "plots.atlas.", atlas, ("x", "y", "color"))
    if atlas or len(swept) >= 2:
        atlas = {
            "x": swept[0] if swept else "",
            "y": swept[1] if len(swept) > 1 else "",
            "color": "singularity_free",
        } | atlas
        for key in ("x", "y"):
            if atlas[key] not in spec.parameters:
                raise ConfigurationError(
                    f"{where}: plots.atlas.{key} {atlas[key]!r} is not a parameter; valid: {choices(spec.parameters)}"
                )
        if atlas["color"] not in fields:
            raise ConfigurationError(
                f"{where}: plots.atlas.color {atlas['color']!r} is not a record field; valid: {choices(fields)}"
            )
        plots["atlas"] = atlas
    pareto = {"x": "assembled", "y": "min_distance", "x_goal": "max", "y_goal": "max"} | dict(table.get("pareto", {}))
    keys(where, "plots.pareto.", pareto, ("x", "y", "x_goal", "y_goal"))
    for key in ("x", "y"):
        if pareto[key] not in numeric or TYPES.get(pareto[key]) == "bool":
            raise ConfigurationError(
                f"{where}: plots.pareto.{key} {pareto[key]!r} is not a numeric field; valid: {choices(numeric)}"
            )
        if pareto[f"{key}_goal"] not in GOALS:
            raise ConfigurationError(
                f"{where}: plots.pareto.{key}_goal must be one of {choices(GOALS)}, got {pareto[key + '_goal']!r}"
            )
    plots["pareto"] = pareto
    return replace(spec, plots=plots)


# The [design] table (its keys below), and the checks every table of the file shares

#: The keys of the [design] table
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
