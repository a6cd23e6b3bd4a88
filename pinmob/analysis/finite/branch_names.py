"""A branch point in words: how many motion branches meet, each one's DoF and the platform's motion type on it.

``two 3-DoF branches meet: 3T and 3H`` (the Delta with horizontal rods), ``a 4-DoF and a 2-DoF branch meet:
3T1R and 2R`` (the 4-RUU at its parallel-axes configuration). The DoF named are the platform's on each
branch (the closed chain's, and no motion type, for a mechanism without a platform); the branches are
named in the order the analysis lists them (:func:`pinmob.analysis.finite.branches.branch_order`, the same on
every machine). The text, the JSON (``branch_point``) and the viewer's panel say it alike.
"""

from __future__ import annotations

from collections.abc import Sequence

from pinmob.analysis.finite.branches import Branch

#: Words for small counts.
COUNTS = {2: "two", 3: "three", 4: "four", 5: "five", 6: "six", 7: "seven", 8: "eight", 9: "nine"}


def _and(items: Sequence[str]) -> str:
    """``a``, ``a and b``, ``a, b and c``."""
    return items[0] if len(items) == 1 else ", ".join(items[:-1]) + " and " + items[-1]


def branch_point_name(branches: Sequence[Branch]) -> str | None:
    """The branch point's name (None where fewer than two branches pass through q)."""
    if len(branches) < 2:
        return None
    dofs = [b.dimension if b.dof is None else b.dof for b in branches]
    kinds = [b.motion_type for b in branches if b.motion_type is not None]
    if len(set(dofs)) == 1:
        head = f"{COUNTS.get(len(dofs), str(len(dofs)))} {dofs[0]}-DoF branches meet"
    elif len(dofs) == 2:
        head = f"a {dofs[0]}-DoF and a {dofs[1]}-DoF branch meet"
    else:
        head = f"branches of {_and([str(d) for d in dofs])} DoF meet"
    return head + (f": {_and(kinds)}" if len(kinds) == len(branches) else "")
