"""A scan's result: :class:`ScanReport`, the summary ``pinmob scan`` prints, its dict and HTML, and the rows.

:func:`pinmob.scan.scan` returns it. The summary (:class:`Summary`) is gathered table by table as the rows come
(:class:`~pinmob.scan.results.table.ScanTable`), so it needs no row kept: how many samples of each DoF and motion type
(a closed chain's: DoF, closure rank, idle motions, actuation verdict), the finite DoF with ``finite_order``, the
singular, near-singular and refined counts, the first sample that did not assemble and why, and the first
``LISTED`` rows that are not regular, each on one line.
"""

from __future__ import annotations

import html
import math
from collections import Counter
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from pinmob.analysis import NEAR_FACTOR
from pinmob.exceptions import ConfigurationError
from pinmob.model import Mechanism
from pinmob.scan.results.table import ScanTable
from pinmob.scan.scan_spec import ScanSpec

#: Rows listed in the summary (singular, near-singular or refined), at most.
LISTED = 20


def describe(spec: ScanSpec, rank_rtol: float | None = None) -> str:
    """What a scan is, for its header line: ``grid x:-0.06:0.06:41 x y:... at 'generic'``, ``pose path ...``.

    ``rank_rtol``: the rank tolerance of its decisions, named with a raised closure tolerance (``spec.cad``).
    """
    at = spec.ends or ("?",) * 2
    if spec.kind == "grid":
        axes = " x ".join(f"{name}:{lo:g}:{hi:g}:{n}" for name, lo, hi, n in spec.axes)
        what = f"grid {axes} at {at[0]!r}" + held_text(spec)
    else:
        joints = "" if spec.platform else f" ({', '.join(spec.joints)})"  # a closed chain's actuated joints
        kind = {"joints": "actuated-joint", "coords": f"coordinate ({', '.join(spec.coords)})"}.get(spec.kind, "pose")
        what = f"{kind} path{joints} {at[0]!r} -> {at[-1]!r}, {spec.samples} samples" + held_text(spec)
    if spec.finite_order is not None:
        what += f", finite DoF per sample (order bound {spec.finite_order})"
    if spec.cad:  # loops closed to CAD accuracy (pinmob.assembly.cad_gaps)
        used = spec.rtol if rank_rtol is None else rank_rtol
        what += f", closure tolerance {spec.closure_tol:g} (CAD gaps of the reference held; rank tolerance {used:.2g})"
    return what


def held_text(spec: ScanSpec) -> str:
    """What a scan holds and what follows the mechanism, for its header line ('' when nothing is held)."""
    if spec.following:
        held = ", ".join(c for c, _ in spec.held) or "none"
        return f"; held: {held}; following the mechanism: {', '.join(spec.following)}"
    if spec.held and not spec.pose_grid:
        return f"; held: {', '.join(c for c, _ in spec.held)}"
    return ""


def scan_meta(mech: Mechanism, spec: ScanSpec, what: str, rank_rtol: float) -> dict[str, Any]:
    """The ``scan`` object of a JSON file (and the Parquet file's metadata): mechanism, scan, tolerances."""
    key = "generic_rank" if spec.platform else "generic_closure_rank"
    meta = {"mechanism": mech.name, "scan": what, key: spec.generic_rank, "rtol": spec.rtol,
            "near_singular_band": NEAR_FACTOR * rank_rtol, "length_scale": mech.length_scale}  # fmt: skip
    if spec.cad:
        meta.update(closure_tol=spec.closure_tol, rank_rtol=rank_rtol)
    return meta


def _truth(table: ScanTable, name: str) -> np.ndarray:
    """The truth of each value of a column (None false), as a boolean array."""
    data = table[name]
    if data.dtype == bool:
        missing = table.missing(name)
        return data if missing is None else data & ~missing
    return np.array([bool(v) for v in table.column(name)], bool)


@dataclass
class Summary:
    """What the summary of a scan counts, gathered table by table (:meth:`add`)."""

    platform: bool
    finite: bool
    counts: Counter[str] = field(default_factory=Counter)
    tally: Counter[str] = field(default_factory=Counter)
    finite_dof: Counter[str] = field(default_factory=Counter)
    listed: list[dict[str, Any]] = field(default_factory=list)
    listed_total: int = 0
    first_unreachable: dict[str, Any] | None = None

    def add(self, table: ScanTable) -> None:
        """Count the rows of ``table`` (the next rows of the scan)."""
        if not len(table):
            return
        refined, reachable = _truth(table, "refined"), _truth(table, "reachable")
        singular = reachable & ~refined & (table["singularity"] != "none")
        near = ~refined & ~singular & _truth(table, "near_singular")
        self.tally.update(
            refined=int(refined.sum()), singular=int(singular.sum()), **{"near-singular": int(near.sum())}
        )
        kept = ~refined
        self.counts["unreachable"] += int((kept & ~reachable).sum())
        assembled = table.take(kept & reachable)
        self.counts.update(self._count_keys(assembled))
        if not self.counts["unreachable"]:
            del self.counts["unreachable"]
        if self.finite:
            dof = assembled.column("finite_dof" if self.platform else "finite_mechanism_dof")
            self.finite_dof.update("cannot decide" if d is None else f"{d} DoF" for d in dof)
        listed = np.flatnonzero(refined | singular | near)
        self.listed_total += len(listed)
        if len(self.listed) < LISTED and len(listed):
            self.listed += table.take(listed[: LISTED - len(self.listed)]).rows()
        if self.first_unreachable is None and "reason" in table.names:
            why = np.flatnonzero(~reachable & _truth(table, "reason"))
            if len(why):
                self.first_unreachable = table.row(int(why[0]))

    def _count_keys(self, table: ScanTable) -> Counter[str]:
        """How the summary counts assembled samples: the platform's DoF and type, or the closed chain's verdict."""
        if "motion_type" in table.names:
            pairs = Counter(zip(table.column("dof"), table.column("motion_type")))
            return Counter({f"{dof} DoF {motion}": k for (dof, motion), k in pairs.items()})
        out: Counter[str] = Counter()
        keys = zip(*(table.column(n) for n in ("dof", "closure_rank", "idle_dof", "actuation_valid")))
        for (dof, rank, idle, valid), k in Counter(keys).items():
            verdict = {True: "actuation valid", False: "actuation NOT valid"}.get(valid, "no actuated joint")
            out[f"mechanism DoF {dof}, closure rank {rank}, {idle} idle, {verdict}"] += k
        return out


@dataclass(frozen=True)
class ScanReport:
    """The result of a scan (:func:`pinmob.scan.scan`): ``str(report)`` is the summary ``pinmob scan`` prints.

    Attributes:
        mechanism: the mechanism's name.
        spec: what was scanned.
        what: what the scan is, in words (:func:`describe`).
        summary: the counts and listed rows (:class:`Summary`).
        seconds: how long the scan took, its files written [s].
        where: where its chunks ran (``1 worker (this process)``, a cluster).
        rank_rtol: the rank tolerance of its decisions (``spec.rtol``; raised for CAD gaps, ``spec.cad``).
        actuated: the mechanism's actuated joints (a refined point lists those not on the grid).
        files: the files written: ``csv``, ``json``, ``parquet`` -> path.
        table: every row (:class:`~pinmob.scan.results.table.ScanTable`), when kept (``keep_rows``), else None.
    """

    mechanism: str
    spec: ScanSpec
    what: str
    summary: Summary = field(repr=False)
    seconds: float
    where: str
    rank_rtol: float
    actuated: tuple[str, ...] = ()
    files: dict[str, str] = field(default_factory=dict)
    table: ScanTable | None = field(default=None, repr=False)

    @property
    def band(self) -> float:
        """The near-singular band: a sample whose distance is below it is near-singular."""
        return NEAR_FACTOR * self.rank_rtol

    def __len__(self) -> int:
        return len(self.rows_table)

    @property
    def rows_table(self) -> ScanTable:
        """The table of rows (an error when the rows were not kept)."""
        if self.table is None:
            raise ValueError("this scan kept no rows (keep_rows=False): read them from its files")
        return self.table

    def __iter__(self) -> Any:
        """The rows as dicts, in order (samples and refined points)."""
        return self.rows_table.rows()

    def plot(self, mech: Mechanism, png_path: str | Path) -> Path:
        """A PNG plot of the rows (kept); returns its path.

        A grid over two coordinates as two maps (:func:`~pinmob.scan.results.workspace_map.plot_map`), a path as its singular
        values, distance and DoF (:func:`~pinmob.scan.results.scan_plot.plot_path`).

        Raises:
            ConfigurationError: a grid over one or three coordinates (a map needs two).
        """
        from pinmob.scan.coordinates import coordinate_unit
        from pinmob.scan.results.scan_plot import plot_path, varied_joint
        from pinmob.scan.results.workspace_map import plot_map

        spec, title = self.spec, f"{self.mechanism}: {self.what}"
        if spec.kind != "grid":
            joint = varied_joint(mech, spec)
            return plot_path(self.rows_table, png_path, title, self.rank_rtol, mech.length_scale, joint, spec.platform)
        if len(spec.axes) != 2:
            raise ConfigurationError(f"a map is drawn over two coordinates; this grid has {len(spec.axes)}")
        units = {a[0]: coordinate_unit(mech, a[0]) for a in spec.axes}
        return plot_map(self.rows_table, png_path, title, rtol=self.rank_rtol, units=units)

    def lines(self) -> list[str]:
        """The summary, line by line."""
        spec, s, n = self.spec, self.summary, self.spec.size
        generic = "generic constraint rank" if spec.platform else "generic closure rank"
        out = [f"{self.mechanism}: {self.what}",
               f"{n} samples in {self.seconds:.2f} s ({n / self.seconds:.1f} samples/s, {self.where}); "
               f"{generic} {spec.generic_rank}"]  # fmt: skip
        out += [f"  {k:5d} x {key}" for key, k in sorted(s.counts.items())]
        if s.finite_dof:
            out.append(f"finite DoF of the {'platform' if spec.platform else 'mechanism'} at the assembled samples: "
                       + ", ".join(f"{k} x {key}" for key, k in sorted(s.finite_dof.items())))  # fmt: skip
        out.append(f"singular samples: {s.tally['singular']}; near-singular samples (distance < {self.band:.0e}): "
                   f"{s.tally['near-singular']}; refined singular points: {s.tally['refined']}")  # fmt: skip
        if s.first_unreachable is not None:
            row = s.first_unreachable
            out.append(f"first sample not assembled: #{row['index']} ({_params(row)}): {row['reason']}")
        for row in s.listed:
            out.append("  " + (format_row(row, self.rank_rtol, self.actuated) if spec.platform
                               else format_chain_row(row, self.rank_rtol)))  # fmt: skip
        if s.listed_total > len(s.listed):
            out.append(f"  ... ({s.listed_total - len(s.listed)} more in the output files)")
        out += [f"{label}: {path}" for label, path in self.files.items()]
        return out

    def __str__(self) -> str:
        return "\n".join(self.lines())

    def to_dict(self) -> dict[str, Any]:
        """The summary as plain data (JSON-ready: non-finite figures None)."""
        s = self.summary
        key = "generic_rank" if self.spec.platform else "generic_closure_rank"
        return {
            "mechanism": self.mechanism,
            "scan": self.what,
            "samples": self.spec.size,
            "seconds": self.seconds,
            "where": self.where,
            key: self.spec.generic_rank,
            "rtol": self.spec.rtol,
            "rank_rtol": self.rank_rtol,
            "near_singular_band": self.band,
            "counts": dict(sorted(s.counts.items())),
            "finite_dof": dict(sorted(s.finite_dof.items())),
            "singular": s.tally["singular"],
            "near_singular": s.tally["near-singular"],
            "refined": s.tally["refined"],
            "first_unreachable": _plain(s.first_unreachable),
            "listed": [_plain(row) for row in s.listed],
            "files": dict(self.files),
        }

    def _repr_html_(self) -> str:
        """The summary in a notebook: its lines, then the counts as a table."""
        rows = "".join(
            f"<tr><td>{html.escape(key)}</td><td>{k}</td></tr>" for key, k in sorted(self.summary.counts.items())
        )
        return (f"<pre>{html.escape(str(self))}</pre>"
                f"<table><tr><th>samples</th><th>count</th></tr>{rows}</table>")  # fmt: skip


def _plain(row: dict[str, Any] | None) -> dict[str, Any] | None:
    if row is None:
        return None
    return {k: None if isinstance(v, float) and not math.isfinite(v) else v for k, v in row.items()}


def _distance(distance: float, rtol: float) -> str:
    """``distance 3.52e-04``, or ``distance <= 1e-06`` at a singularity (at most ``rtol``: the figure is round-off)."""
    return f"distance <= {rtol:g}" if distance <= rtol else f"distance {distance:.2e}"


def format_chain_row(row: dict[str, Any], rtol: float) -> str:
    """One listed row of a closed chain's joint path: where, class, DoF, motions left with the actuators locked."""
    where = f"#{row['index']}+ refined" if row["refined"] else f"#{row['index']}"
    names = [k for k in row if k.startswith("q_")]
    values = ", ".join(f"{k[2:]} = {row[k]:.6g}" for k in names[:6]) + (", ..." if len(names) > 6 else "")
    label = row["singularity"] if row["singularity"] != "none" else f"near-singular ({row['closest']})"
    left = f", locked: {row['locked_dof']} motion(s) left ({row['uncontrolled']})" if row["uncontrolled"] else ""
    if "finite_mechanism_dof" in row:  # with finite_order
        dof = row["finite_mechanism_dof"]
        left += f", finite mechanism DoF {'cannot decide' if dof is None else dof}"
    return (f"{where} (s = {round(row['s'], 12):.6g}; {values}): {label}; mechanism DoF {row['dof']}, "
            f"closure rank {row['closure_rank']}{left}, {_distance(row['distance'], rtol)}")  # fmt: skip


def _params(row: dict[str, Any]) -> str:
    """Where a row is: ``s = 0.5``, or ``x = 0.01, y = -0.02`` (the grid's coordinates)."""
    return ", ".join(f"{k} = {round(row[k], 12):.6g}" for k in row if k == "s" or k.startswith("grid_"))


def format_row(row: dict[str, Any], rtol: float, actuated: tuple[str, ...] = ()) -> str:
    """One listed row of a platform scan: where, class, limbs, uncontrolled motions, DoF, distance.

    A refined point also gives its actuated joints' values (those not on the grid).
    """
    params = _params(row)
    where = f"#{row['index']}+ refined" if row["refined"] else f"#{row['index']}"
    joints = [n for n in actuated if f"q_{n}" in row and n not in {k[5:] for k in row if k.startswith("grid_")}]
    if row["refined"] and joints:
        params += "; " + ", ".join(f"{n} = {row['q_' + n]:.6g}" for n in joints)
    label = row["singularity"] if row["singularity"] != "none" else f"near-singular ({row['closest']})"
    limbs = f", limbs {row['singular_limbs']}" if row["singular_limbs"] else ""
    dep = f", dependent limbs {row['dependent_limbs']}" if row["dependent_limbs"] else ""
    unc = f", uncontrolled {row['uncontrolled']}" if row["uncontrolled"] else ""
    fin = ""
    if "finite_dof" in row:  # with finite_order
        fin = f" (finite {'cannot decide' if row['finite_dof'] is None else row['finite_dof']})"
    return (f"{where} ({params}): {label}{limbs}{dep}{unc}; {row['dof']} DoF {row['motion_type']}{fin}, "
            f"{_distance(row['distance'], rtol)}")  # fmt: skip
