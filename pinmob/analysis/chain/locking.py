"""The closed chain's motions with some joints locked: the motions left, and the idle ones among them.

With the closed chain's dimensionless motions N (nv, m), the locked joints' rates ``S N`` (k, m) and
the output rows times the motions ``O N`` (o, m) (:func:`pinmob.analysis.chain.closed_chain.output_motions`:
output frames, joint centres, closure points): ``locked = null(S N)``, ``idle = null([S N; O N])``. The
one computation behind the actuation verdict, the idle joints and the actuator search
(:mod:`pinmob.analysis.chain.actuation`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field

import numpy as np

from pinmob.analysis.chain.closed_chain import output_motions
from pinmob.analysis.configuration import Configuration
from pinmob.screw import Array, decide_rank


@dataclass(frozen=True)
class Locked:
    """The closed-chain motions with some joints locked, and the idle ones among them (dimensionless bases)."""

    rank_a: int  # rank of the locked joints' rates on the closed chain
    locked: Array  # (m, l) motions that move no locked joint
    idle: Array  # (m, i) motions that move no locked joint and no output (a subspace of `locked`)
    singular_values: Array = field(default_factory=lambda: np.zeros(0))  # of the rates, the rank decided

    def valid(self, count: int) -> bool:
        """``count`` locked joints are independent and leave only idle motions (a valid actuation)."""
        return self.rank_a == count and self.locked.shape[1] == self.idle.shape[1]


def lock(rates: Array, outputs: Callable[[], Array], rtol: float, m: int) -> Locked:
    """Split closed-chain motions by locked-joint rates ``rates`` (k, m) and output rows ``outputs()`` (o, m).

    ``locked = null(rates)``, ``idle = null([rates; outputs])``: the one computation behind the actuation
    verdict, the idle joints and the actuator search (tolerances ``rtol * max(1, sigma_1)``, as ``rank_of``).
    ``outputs()`` is called only when the rates have rank m (for the bound) or not (for the stacked SVD);
    the SVD is skipped (``idle`` empty) when the rates' smallest singular value exceeds
    ``2 rtol max(1, ||[rates; outputs]||_F)``: adding rows lowers no singular value and the Frobenius norm
    bounds the largest, so the SVD would find rank m (the factor 2 covers its round-off).
    """
    dec = decide_rank(rates, rtol, m, at_least=1.0)
    s = dec.singular_values
    if dec.rank == m:
        bound = 2.0 * rtol * max(1.0, math.hypot(math.sqrt(s @ s), float(np.linalg.norm(outputs()))))
        if m == 0 or s[m - 1] > bound:
            return Locked(dec.rank, dec.null_space.T, np.zeros((m, 0)), s)
    idle = decide_rank(np.vstack([rates, outputs()]), rtol, m, at_least=1.0).null_space.T
    return Locked(dec.rank, dec.null_space.T, idle, s)


def lock_motions(conf: Configuration, null: Array, held: Array, frames: Sequence[str], rtol: float) -> Locked:
    """:func:`lock` of the closed chain's motions ``null`` (nv, m) by the ``held`` rates (k, m), ``frames`` the outputs.

    The output rows times the motions come from :func:`~pinmob.analysis.chain.closed_chain.output_motions`,
    computed once, when :func:`lock` first needs them (what is printed depends on the spans found, not on
    their bases: :mod:`pinmob.analysis.chain.joint_rates`).
    """
    return lock(held, functools.cache(lambda: output_motions(conf, frames, null)), rtol, null.shape[1])
