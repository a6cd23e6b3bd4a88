"""What a sweep does: its mechanisms, its designs, the workspace scan of each design, its plots (picklable)."""

from __future__ import annotations

import hashlib
import json
from dataclasses import dataclass, field
from typing import Any

from pinmob.model.mechanism import Mechanism
from pinmob.scan.spec import ScanSpec, grid_spec, path_spec
from pinmob.screw.rank import RTOL
from pinmob.sweeps.designs import DesignSet
from pinmob.sweeps.fields import UNITS, record_fields
from pinmob.sweeps.source import Source

#: Version of the record format: a sweep file written with another one is not resumed.
FORMAT = 1


def _version() -> str:
    """The installed pinmob's version (records of another version are not resumed)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("pinmob")
    except PackageNotFoundError:
        return "unknown"


@dataclass(frozen=True)
class ScanSettings:
    """The workspace scan of each design, as ``pinmob scan`` takes it: a grid, or a path.

    Attributes:
        axes: a grid's two axes ``(coordinate, low, high, count)``; empty for a path.
        at: the grid's reference (a configuration name or a pose ``x,y,z,roll,pitch,yaw``); None: the first one.
        start: a path's start (name or pose); None: the first configuration.
        end: a path's end; None: the second configuration.
        samples: samples along a path.
        joints: a path in actuated joint values.
        rtol: relative tolerance of the rank decisions.
    """

    axes: tuple[tuple[str, float, float, int], ...] = ()
    at: str | None = None
    start: str | None = None
    end: str | None = None
    samples: int = 21
    joints: bool = False
    rtol: float = RTOL

    @property
    def is_grid(self) -> bool:
        """A grid over two pose coordinates (else a path)."""
        return bool(self.axes)

    def parameters(self) -> list[str]:
        """The scan parameters of its rows: ``grid_<coordinate>`` twice, or ``s``."""
        return [f"grid_{a[0]}" for a in self.axes] if self.is_grid else ["s"]

    def spec(self, mech: Mechanism) -> ScanSpec:
        """The scan of one design's mechanism (references default to its first configurations)."""
        names = list(mech.configurations)
        if self.is_grid:
            return grid_spec(mech, self.at or (names[0] if names else ""), list(self.axes), self.rtol)
        start = self.start or (names[0] if names else "")
        end = self.end or (names[1] if len(names) > 1 else "")
        return path_spec(mech, start, end, self.samples, joints=self.joints, rtol=self.rtol)

    def describe(self) -> str:
        """One line, e.g. ``grid x:-0.05:0.05:9 x y:-0.05:0.05:9 at 'generic'``."""
        if self.is_grid:
            axes = " x ".join(f"{c}:{lo:g}:{hi:g}:{n}" for c, lo, hi, n in self.axes)
            return f"grid {axes} at {self.at!r}"
        kind = "actuated-joint" if self.joints else "pose"
        return f"{kind} path {self.start!r} -> {self.end!r}, {self.samples} samples"


@dataclass(frozen=True)
class SweepSpec:
    """A design-space sweep (see :func:`pinmob.sweeps.spec_file.load_spec` for the file that describes one).

    Attributes:
        name: a title (default: the spec file's stem).
        source: the mechanisms (a family or a template).
        fixed: parameter values common to every design.
        designs: the swept parameters' values per design.
        scan: the workspace scan of each design.
        plots: ``atlas`` ``{x, y, color}`` and ``pareto`` ``{x, y, x_goal, y_goal}`` (goals ``max`` or ``min``).
    """

    name: str
    source: Source
    fixed: dict[str, float]
    designs: DesignSet
    scan: ScanSettings
    plots: dict[str, dict[str, str]] = field(default_factory=dict)

    @property
    def count(self) -> int:
        """Number of designs."""
        return self.designs.count

    @property
    def parameters(self) -> tuple[str, ...]:
        """The record's parameter fields: the swept ones, then the fixed ones."""
        return self.designs.names + tuple(self.fixed)

    def values(self, i: int) -> dict[str, float]:
        """Every parameter value of design i."""
        return self.designs.values(i) | self.fixed

    def fields(self) -> list[tuple[str, str]]:
        """(name, type) of each record field, in order."""
        return record_fields(self.parameters, self.scan.parameters())

    def unit(self, name: str) -> str:
        """The unit of a record field or parameter ('' when dimensionless or unknown)."""
        if name in self.parameters:
            return self.source.units.get(name, "")
        if name.startswith("min_distance_grid_"):
            return "rad" if name[18:] in ("roll", "pitch", "yaw") else "m"
        return UNITS.get(name, "")

    def identity(self) -> str:
        """A digest of everything that determines the records (not where they are computed)."""
        doc: dict[str, Any] = {
            "format": FORMAT,
            "pinmob": _version(),
            "family": self.source.family,
            "template": [list(t) for t in self.source.texts],
            "fixed": self.fixed,
            "designs": self.designs.identity(),
            "scan": [list(a) for a in self.scan.axes] + [self.scan.at, self.scan.start, self.scan.end],
            "path": [self.scan.samples, self.scan.joints, self.scan.rtol],
        }
        return hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()[:20]
