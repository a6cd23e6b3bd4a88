"""Rank decisions a report should not state with confidence: a raised tolerance, and decisions without a clear gap.

Two things make a rank decision depend on more than the mechanism's structure:

- loops that close only to a residual r well above round-off (CAD geometry): the rank tolerance is
  raised to ``10 r`` (:meth:`~pinmob.analysis.configuration.Configuration.rank_rtol`) and the report
  says so;
- singular values within a factor 10 of the tolerance on either side (:func:`~pinmob.screw.rank.ambiguity`):
  the report names the decision as ambiguous and gives the two singular values, the last counted and
  the first dropped, so that the designer can tell which count the geometry means.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from pinmob.analysis.chain.mechanism_mobility import MechanismMobility
from pinmob.analysis.configuration import RESIDUAL_FACTOR
from pinmob.analysis.mobility import Mobility
from pinmob.screw import AMBIGUOUS_MARGIN, Array, ambiguity


@dataclass(frozen=True)
class AmbiguousRank:
    """A rank decision without a clear gap around its tolerance.

    Attributes:
        decision: what was decided (``closure rank``, ``platform constraint rank``).
        rank: the rank counted.
        kept: the last singular value counted (0 for rank 0).
        dropped: the first singular value not counted (0 when none is).
        tolerance: the absolute tolerance between them.
    """

    decision: str
    rank: int
    kept: float
    dropped: float
    tolerance: float

    def to_dict(self) -> dict[str, Any]:
        """Plain JSON."""
        return {
            "decision": self.decision,
            "rank": self.rank,
            "kept": self.kept,
            "dropped": self.dropped,
            "tolerance": self.tolerance,
        }

    @property
    def alternatives(self) -> tuple[int, ...]:
        """The other ranks the geometry may mean: one less (counted value close), one more (dropped one close)."""
        out = (self.rank - 1,) if 0 < self.kept < AMBIGUOUS_MARGIN * self.tolerance else ()
        return out + ((self.rank + 1,) if self.dropped * AMBIGUOUS_MARGIN > self.tolerance else ())

    def __str__(self) -> str:
        """One line: the decision, the two singular values and the counts they allow."""
        other = " or ".join(str(r) for r in self.alternatives)
        return (
            f"ambiguous {self.decision}: singular values {self.kept:.2e} (counted) and {self.dropped:.2e} (not) lie "
            f"within a factor {AMBIGUOUS_MARGIN:g} of the tolerance {self.tolerance:.2e}, no clear gap: the rank is "
            f"{self.rank} as counted, {other} if the geometry means otherwise "
            "(check the model's accuracy, or set `rtol` / `closure_tol`)"
        )


def ambiguous_rank(decision: str, singular_values: Array, tolerance: float, rank: int) -> AmbiguousRank | None:
    """The :class:`AmbiguousRank` of a decision, or None when its gap is clear."""
    pair = ambiguity(singular_values, tolerance, rank)
    return None if pair is None else AmbiguousRank(decision, rank, pair[0], pair[1], tolerance)


def ambiguous_ranks(chain: MechanismMobility, platform: Mobility | None) -> tuple[AmbiguousRank, ...]:
    """The ambiguous decisions among the closure rank and the platform's constraint rank (when there is a platform)."""
    found = [ambiguous_rank("closure rank", chain.singular_values, chain.tolerance, chain.rank)]
    if platform is not None:
        found.append(
            ambiguous_rank(
                "platform constraint rank", platform.singular_values, platform.tolerance, platform.constraint_rank
            )
        )
    return tuple(a for a in found if a is not None)


def raised_note(asked: float, used: float, residual: float) -> str | None:
    """The sentence saying the rank tolerance was raised for a closure residual (None when it was not)."""
    if used <= asked:
        return None
    return (
        f"rank tolerance raised from {asked:g} to {used:.2g} ({RESIDUAL_FACTOR:g} x the closure residual "
        f"{residual:.2g}): the loops close only to that accuracy (CAD geometry), so smaller singular values are "
        "not counted as structural"
    )
