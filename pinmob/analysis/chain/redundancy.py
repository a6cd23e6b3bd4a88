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

from pinmob.model import Mechanism
from pinmob.screw import Array, decide_rank, rank_rule, singular_values

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


#: How clearly K's rank and each closure's part of its dependencies must be decided for the one-SVD path.
CLEAR = 10.0


def closure_ranks(
    mech: Mechanism, k_hat: Array, rtol: float, reference: float, left_null: Array, margin: float
) -> tuple[ClosureRank, ...]:
    """Per closure: own rank and ``essential_c = rank K - rank K_-c`` (see :func:`implied_rows`).

    When K has full row rank (an empty left null space) with a clear margin, every closure is
    essential (``essential_c = rows_c``) and has full rank without an SVD: the singular values of a
    block of K's rows are at least K's smallest, ``sigma_min(K_c) >= sigma_min(K) >= CLEAR * tol``
    (``sigma_min(K_c) = min |K_c^T y|`` over unit y, a minimum over fewer vectors than K's). That
    answer depends on the mechanism only: it is kept in its cache.

    Args:
        mech: the mechanism (its closures, in the order of K's rows).
        k_hat: (rows, nv) the dimensionless closure Jacobian.
        rtol: the relative tolerance K's rank was decided with.
        reference: K's largest singular value (each closure's own rank counts its rows' singular values
            above ``rtol * reference``, K's threshold; computed in one batch per row count).
        left_null: (rows, rows - rank) orthonormal basis of K's left null space.
        margin: how clearly K's rank was decided (:attr:`~pinmob.screw.rank.RankDecision.margin`).
    """
    closures = mech.all_closures
    if not left_null.shape[1] and margin >= CLEAR:  # full row rank, clearly: every block has full rank
        return mech.memo(
            "closure ranks, full row rank",
            lambda: tuple(ClosureRank(c.name, str(c.type), c.rows, c.rows, c.rows) for c in closures),
        )
    implied = implied_rows(mech, left_null, rtol, margin)
    if implied is None:  # a rank too close to call: the straightforward computation decides it
        return closure_ranks_by_removal(mech, k_hat, rtol, reference)
    sizes = [c.rows for c in closures]
    starts = [0]
    for rows in sizes:
        starts.append(starts[-1] + rows)
    own: dict[int, int] = {}
    for rows in set(sizes):
        which = [i for i, size in enumerate(sizes) if size == rows]
        if len(which) == len(sizes):  # every closure has this many rows: K's rows are the stack already
            stack = k_hat.reshape(len(sizes), rows, k_hat.shape[1])
        else:
            stack = np.stack([k_hat[starts[i] : starts[i + 1]] for i in which])
        for i, s in zip(which, singular_values(stack)):
            own[i] = rank_rule(s, rtol, reference=reference)[0]
    return tuple(ClosureRank(c.name, str(c.type), c.rows, own[i], c.rows - implied[i]) for i, c in enumerate(closures))


def implied_rows(mech: Mechanism, left_null: Array, rtol: float, margin: float) -> list[int] | None:
    """Per closure, ``rows_c - essential_c`` from K's left null space N; None where that is not clear-cut.

    ``rank K - rank K_-c = rows_c - rank N_c`` (``N_c``: N's rows of closure
    c): the combinations of c's equations that the others also give are
    exactly the c-parts of the dependencies ``y^T K = 0``. One SVD of K instead
    of one per closure. ``rank N_c`` counts the singular values above ``rtol``
    (a block of an orthonormal basis). The two computations agree whenever the
    decisions are clear: K's rank with a margin of at least ``CLEAR`` and no
    singular value of an ``N_c`` within a factor ``CLEAR`` of ``rtol``; otherwise
    (a soft dependency at a loose ``rtol``) this returns None. The tests compare
    both on every built-in model and the Extended URDF robots.
    """
    if margin < CLEAR:
        return None
    out, start = [], 0
    for c in mech.all_closures:
        block = left_null[start : start + c.rows]
        start += c.rows
        if not block.size:
            out.append(0)
            continue
        s = singular_values(block)
        if np.any((s > rtol / CLEAR) & (s < rtol * CLEAR)):
            return None
        out.append(rank_rule(s, rtol, at_least=1.0)[0])
    return out


def closure_ranks_by_removal(mech: Mechanism, k_hat: Array, rtol: float, reference: float) -> tuple[ClosureRank, ...]:
    """:func:`closure_ranks` the straightforward way: an SVD of K without each closure's rows, and of each one's rows."""

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
