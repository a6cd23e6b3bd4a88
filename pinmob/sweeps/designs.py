"""Design sets: which parameter values a sweep visits (grid, random, Latin hypercube, table).

A design set is indexed ``0 .. count - 1``; :meth:`DesignSet.values` gives the
parameter values of design i without building the others (a grid's index is
decomposed, the first parameter varying slowest; a random design is drawn from
its own generator seeded with ``(seed, i)``), so that a sweep of 100,000
designs holds at most the Latin hypercube's ``(count, d)`` table in memory.

A design set holds at most ``max_designs`` designs (default ``MAX_DESIGNS``;
a spec raises it with ``design.max_designs``): a sweep keeps a byte per design
(which are written) and a table or Latin hypercube ``8 d`` bytes per design, and a
grid of 1e5 x 1e5 values is a typing error more often than a plan.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field

import numpy as np

from pinmob.exceptions import ConfigurationError
from pinmob.screw import Array

#: The design methods, in the order listed in error messages.
METHODS = ("grid", "random", "latin-hypercube", "table")
#: Default bound on the number of designs of a sweep (``design.max_designs`` raises it).
MAX_DESIGNS = 1_000_000


def check_count(count: int, bound: int, where: str = "the sweep") -> int:
    """``count`` if it is within ``bound``; else a :class:`ConfigurationError` naming the bound and how to raise it."""
    if count > bound:
        raise ConfigurationError(
            f"{where}: the design set has {count:,} designs, more than the bound of {bound:,}; split the sweep, "
            f"or raise the bound in the spec's [design] table: max_designs = {count}"
        )
    return count


@dataclass(frozen=True)
class DesignSet:
    """The swept parameters' values per design (picklable).

    Attributes:
        method: one of ``METHODS``.
        names: the swept parameters, in order.
        ranges: per name ``(low, high, count)`` (grid; count 0 for random and Latin hypercube).
        samples: designs of a random or Latin-hypercube set.
        seed: seed of their generator.
        table: (count, len(names)) values of a table (and of a Latin hypercube, drawn once).
        max_designs: the bound on the number of designs (not part of the identity: it changes no record).
    """

    method: str
    names: tuple[str, ...]
    ranges: tuple[tuple[float, float, int], ...] = ()
    samples: int = 0
    seed: int = 0
    table: Array = field(default_factory=lambda: np.zeros((0, 0)), repr=False)
    max_designs: int = MAX_DESIGNS

    @property
    def count(self) -> int:
        """Number of designs (a Python integer: a grid's product does not overflow)."""
        if self.method == "grid":
            return math.prod(int(n) for _, _, n in self.ranges)
        if self.method == "random":
            return self.samples
        return int(self.table.shape[0])

    def values(self, i: int) -> dict[str, float]:
        """Parameter values of design i (0 <= i < count)."""
        if self.method == "grid":
            out, rest = {}, i
            for name, (lo, hi, n), size in zip(self.names, self.ranges, self._strides()):
                k, rest = divmod(rest, size)
                out[name] = lo + (hi - lo) * k / (n - 1) if n > 1 else lo
            return out
        if self.method == "random":
            u = np.random.default_rng([self.seed, i]).random(len(self.names))
            return {name: lo + (hi - lo) * float(x) for name, (lo, hi, _), x in zip(self.names, self.ranges, u)}
        return {name: float(v) for name, v in zip(self.names, self.table[i])}

    def _strides(self) -> list[int]:
        counts = [int(n) for _, _, n in self.ranges]
        return [math.prod(counts[k + 1 :]) for k in range(len(counts))]

    def describe(self) -> str:
        """One line: the method and the swept parameters."""
        if self.method == "grid":
            return "grid " + " x ".join(f"{n} ({c} values)" for n, (_, _, c) in zip(self.names, self.ranges))
        return f"{self.method} ({self.count} designs) over {', '.join(self.names)}"

    def identity(self) -> dict[str, object]:
        """What determines the designs (for a sweep's identity)."""
        out: dict[str, object] = {
            "method": self.method,
            "names": list(self.names),
            "ranges": [list(r) for r in self.ranges],
        }
        out |= {"samples": self.samples, "seed": self.seed}
        if self.method in ("table", "latin-hypercube"):  # a digest: the table may hold max_designs rows
            out["table"] = hashlib.sha256(np.ascontiguousarray(self.table, float).tobytes()).hexdigest()
            out["shape"] = list(self.table.shape)
        return out


def latin_hypercube(ranges: tuple[tuple[float, float, int], ...], samples: int, seed: int) -> Array:
    """(samples, d) Latin-hypercube design in the boxes ``[low, high]`` (scipy.stats.qmc, seeded)."""
    from scipy.stats import qmc

    unit = qmc.LatinHypercube(d=len(ranges), seed=np.random.default_rng(seed)).random(samples)
    lo = np.array([r[0] for r in ranges])
    hi = np.array([r[1] for r in ranges])
    return lo + (hi - lo) * unit
