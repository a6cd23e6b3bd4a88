"""What a sweep does: its mechanisms, its designs, the workspace scan of each design, its plots (picklable).

A sweep's *identity* (:meth:`SweepSpec.identity`) is a digest of everything that
determines its records: the spec (family or template texts, fixed values, the
designs, the scan, the finite analysis) and the code computing them (pinmob's
version and a digest of its own source files, :func:`code_digest`: a development
install whose code changed does not resume records of the old code). A file is
resumed only by the sweep of the same identity.
"""

from __future__ import annotations

import functools
import hashlib
import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pinmob.model import Mechanism
from pinmob.scan import ScanSpec, grid_spec, path_spec
from pinmob.screw import RTOL
from pinmob.sweeps.designs import DesignSet, check_count
from pinmob.sweeps.fields import UNITS, record_fields
from pinmob.sweeps.source import Source

#: Version of the record format: a sweep file written with another one is not resumed.
FORMAT = 2


def pinmob_version() -> str:
    """The installed pinmob's version (records of another version are not resumed)."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version("pinmob")
    except PackageNotFoundError:
        return "unknown"


@functools.cache
def code_digest() -> str:
    """This pinmob's version and a digest of its Python source files (computed once per process)."""
    return package_digest(Path(__file__).resolve().parent.parent)


def package_digest(root: Path) -> str:
    """The pinmob version and a digest of the Python source files of the package folder ``root``.

    The built-in models' folder (``pinmob/models`` once installed, ``models/`` beside the package in a checkout)
    is data, not code, and is left out: an installed pinmob and the checkout it came from have the same digest.
    """
    digest = hashlib.sha256(pinmob_version().encode())
    for path in sorted(root.rglob("*.py")):
        relative = path.relative_to(root)
        if relative.parts[0] != "models":
            digest.update(relative.as_posix().encode() + b"\0" + path.read_bytes() + b"\0")
    return digest.hexdigest()[:20]


@dataclass(frozen=True)
class ScanSettings:
    """The workspace scan of each design, as ``pinmob scan`` takes it: a grid, or a path.

    Attributes:
        axes: a grid's one to three axes ``(coordinate, low, high, count)`` (a pose coordinate or a joint,
            :func:`pinmob.scan.scan_spec.grid_spec`); empty for a path.
        at: the grid's reference (a configuration name or a pose ``x,y,z,roll,pitch,yaw``); None: the first one.
        start: a path's start (name, pose, or joint values ``name=value,...``); None: the first configuration.
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
        """A grid over one to three coordinates (else a path)."""
        return bool(self.axes)

    def parameters(self) -> list[str]:
        """The scan parameters of its rows: ``grid_<coordinate>`` per axis, or ``s``."""
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
class DesignJob:
    """What computing one design needs, beside its index and values: sent to the Dask workers once per sweep.

    Attributes:
        source: the mechanisms (a family or a template).
        scan: the workspace scan of each design.
        parameters: the record's parameter fields, in order.
        fields: (name, type) of every record field, in order.
        finite_order: the order bound of the finite analysis at the reference configuration (None: none).
    """

    source: Source
    scan: ScanSettings
    parameters: tuple[str, ...]
    fields: tuple[tuple[str, str], ...]
    finite_order: int | None = None


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
        finite_order: with a value, each record adds the finite-mobility analysis at the reference
            configuration with this order bound (:func:`pinmob.analysis.finite.finite_mobility.finite_mobility`); None: not.
    """

    name: str
    source: Source
    fixed: dict[str, float]
    designs: DesignSet
    scan: ScanSettings
    plots: dict[str, dict[str, str]] = field(default_factory=dict)
    finite_order: int | None = None

    @property
    def count(self) -> int:
        """Number of designs."""
        return self.designs.count

    def check_count(self) -> int:
        """The number of designs, refused (:class:`ConfigurationError`) above the design set's bound."""
        return check_count(self.count, self.designs.max_designs, f"sweep {self.name!r}")

    @property
    def parameters(self) -> tuple[str, ...]:
        """The record's parameter fields: the swept ones, then the fixed ones."""
        return self.designs.names + tuple(self.fixed)

    def values(self, i: int) -> dict[str, float]:
        """Every parameter value of design i."""
        return self.designs.values(i) | self.fixed

    def fields(self) -> list[tuple[str, str]]:
        """(name, type) of each record field, in order."""
        return record_fields(self.parameters, self.scan.parameters(), self.finite_order is not None)

    def job(self) -> DesignJob:
        """What a design's computation needs (not the design table: each task carries its own values)."""
        return DesignJob(self.source, self.scan, self.parameters, tuple(self.fields()), self.finite_order)

    def unit(self, name: str) -> str:
        """The unit of a record field or parameter ('' when dimensionless or unknown)."""
        if name in self.parameters:
            return self.source.units.get(name, "")
        if name.startswith("min_distance_grid_"):
            coordinate = name[18:]  # a joint's unit (rad or m) is its mechanism's business: none given
            return "rad" if coordinate in ("roll", "pitch", "yaw") else "m" if coordinate in ("x", "y", "z") else ""
        return UNITS.get(name, "")

    def spec_digest(self) -> str:
        """A digest of the spec alone: everything that determines the records but the code (computed once)."""
        return self._digests[0]

    def identity(self) -> str:
        """A digest of everything that determines the records: the spec and the code (not where they are computed)."""
        return self._digests[1]

    @functools.cached_property
    def _digests(self) -> tuple[str, str]:
        doc: dict[str, Any] = {
            "format": FORMAT,
            "family": self.source.family,
            "template": [list(t) for t in self.source.texts],
            "fixed": self.fixed,
            "designs": self.designs.identity(),
            "scan": [list(a) for a in self.scan.axes] + [self.scan.at, self.scan.start, self.scan.end],
            "path": [self.scan.samples, self.scan.joints, self.scan.rtol],
            "finite": self.finite_order,
        }
        spec = hashlib.sha256(json.dumps(doc, sort_keys=True).encode()).hexdigest()[:20]
        return spec, hashlib.sha256(f"{spec} {code_digest()}".encode()).hexdigest()[:20]
