"""Which samples of :func:`pinmob.assembly.batched.batch_solver.solve_poses` go on after an iteration: its stopping rule.

Plain Python loops over the samples still running, so that numba compiles the very same function
(:mod:`pinmob.assembly.batched.batch_newton_kernel`'s ``advance``) and the numpy path runs it as it is: one call per
iteration instead of a dozen numpy calls on a few samples each.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from pinmob.screw import Array, Mask


def advance(
    now: Array,
    active: NDArray[np.intp],
    it: int,
    best: Array,
    history: Array,
    tol: float,
    floor: float,
    stall_window: int,
    stall_gain: float,
    polish_gain: float,
    diverged: float,
) -> tuple[Mask, Mask]:
    """After iteration ``it``, per running sample (its index in ``active``): improved, and goes on.

    ``now`` is each running sample's ``max |e|``; ``best`` (per sample of the solve) and ``history`` (per sample
    and iteration) are updated in place. A sample stops at ``floor``, after a step within ``tol`` that kept more
    than ``polish_gain`` of ``max |e|^2`` (the single-sample solver's polish), when it gained less than
    ``stall_gain`` over ``stall_window`` iterations, when a step made it grow ``diverged``-fold, or when it is not
    finite.
    """
    n = now.size
    better, keep = np.zeros(n, np.bool_), np.zeros(n, np.bool_)
    for s in range(n):
        b, x = active[s], now[s]
        previous = best[b]
        if x < previous:
            better[s] = True
            best[b] = x
        history[b, it] = x
        before = history[b, it - stall_window] if it >= stall_window else math.inf
        polished = x <= floor or (previous <= tol and x * x > polish_gain * previous * previous)
        stalled = x > (1.0 - stall_gain) * before
        keep[s] = not (polished or stalled or x > diverged * previous or not math.isfinite(x))
    return better, keep
