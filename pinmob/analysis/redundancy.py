"""Redundant closure equations, per closure and independent of the order of declaration.

With the dimensionless closure Jacobian ``K``: per closure c, ``essential_c = rank K - rank K_-c``
(``K_-c``: K without c's rows) is the number of constraint directions only c provides (removing c
frees that many motions; 0 = c is not needed), and ``redundant_c = rows_c - essential_c`` its
equations implied by the rest. Two closures that repeat each other both count theirs, so these add
up to at least ``rows - rank K``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from pinmob.model.mechanism import Mechanism
from pinmob.screw.algebra import Array
from pinmob.screw.rank import decide_rank

#: How the per-closure redundancy is computed, said in the JSON document.
REDUNDANCY_RULE = (
    "per closure: rows minus the rank it alone adds to all the others (rank K - rank K without it); "
    "independent of the order of declaration"
)


@dataclass(frozen=True)
class ClosureRank:
    """One closure's equations among all of them, independent of the order of declaration.

    Attributes:
        name, type: the closure.
        rows: its scalar equations.
        rank: rank of its own rows.
        essential: ``rank K - rank K_-c``: constraint directions no other closure
            provides; removing the closure frees this many motions.
    """

    name: str
    type: str
    rows: int
    rank: int
    essential: int

    @property
    def redundant(self) -> int:
        """Its equations implied by the rest (its own other rows and the other closures): ``rows - essential``."""
        return self.rows - self.essential

    @property
    def needed(self) -> bool:
        """Removing the closure changes the mechanism (``essential > 0``)."""
        return self.essential > 0

    def to_dict(self) -> dict[str, Any]:
        """One entry of ``closures`` in the JSON document."""
        return {
            "name": self.name,
            "type": str(self.type),
            "rows": self.rows,
            "rank": self.rank,
            "essential": self.essential,
            "redundant": self.redundant,
            "needed": self.needed,
        }


def closure_ranks(mech: Mechanism, k_hat: Array, rtol: float, reference: float) -> tuple[ClosureRank, ...]:
    """Per closure: own rank and ``rank K - rank K_-c``, each block judged with K's own threshold.

    Args:
        mech: the mechanism (its closures, in the order of K's rows).
        k_hat: (rows, nv) the dimensionless closure Jacobian.
        rtol: the relative tolerance K's rank was decided with.
        reference: K's largest singular value (the blocks' ranks count singular values above ``rtol * reference``).
    """

    def rank(rows: Array) -> int:
        return decide_rank(rows, rtol, reference=reference).rank if rows.size else 0

    total = rank(k_hat)
    out, start = [], 0
    for c in mech.all_closures:
        own = np.arange(start, start + c.rows)
        others = np.delete(k_hat, own, axis=0)
        out.append(ClosureRank(c.name, str(c.type), c.rows, rank(k_hat[own]), total - rank(others)))
        start += c.rows
    return tuple(out)
