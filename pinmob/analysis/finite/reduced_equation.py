"""The closure equations reduced to a single first-order motion: the order at which they start.

Where one first-order motion n is left (``m == 1``: e.g. the actuators held at a constraint singularity where
two modes meet), the closure equations ``F(q (+) x) = 0`` split (Lyapunov-Schmidt) into a part solved in every
direction w orthogonal to n (the Jacobian has full rank there) and what is left, the reduced equation
``g(s) = min_w |F(q (+) (s n + w))|`` along n. q is an isolated solution when g grows like ``s^k`` (k >= 2) on both
sides; a curve through q along n makes g vanish. The higher-order conditions ask the same question order by
order; this answers it from the equations themselves, at steps far above round-off
(:mod:`pinmob.analysis.finite.sample_modes` uses it where the conditions up to the order bound do not decide).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmob.analysis.chain.closed_chain import closed_chain_columns
from pinmob.analysis.configuration import Configuration
from pinmob.assembly.residual import closure_residual
from pinmob.screw.algebra import Array

#: Steps of the reduced equation along a single remaining motion (joint metric), each twice the last.
GROWTH_STEPS = (0.025, 0.05, 0.1)
#: The reduced equation decides only where its residual is above this (dimensionless; round-off is 1e-15).
GROWTH_FLOOR = 1e-9


def reduced_growth(conf: Configuration, direction: Array, held: tuple[int, ...]) -> int | None:
    """The order k at which the closure equations reduced to the single motion ``direction`` start, or None.

    For each step s of ``GROWTH_STEPS`` (both signs) the closure residual at ``q (+) (s n + w)`` is minimised
    over w orthogonal to n = ``direction`` (unit dimensionless joint rates) and to the held joints (Gauss-Newton:
    the closure Jacobian has full rank there): what is left is the reduced equation ``|g(s)|``. It decides when
    every value is above ``GROWTH_FLOOR`` and each doubling of s multiplies it by 2^k, k >= 2 the same integer
    (within 0.4) on both sides: then q is an isolated solution along n. None otherwise (a curve may exist).
    """
    mech = conf.mechanism
    model = mech.model
    col = closed_chain_columns(conf)
    residual = closure_residual(mech)
    free = np.ones(model.nv, bool)
    free[list(held)] = False
    n = direction / np.linalg.norm(direction)
    basis = np.eye(model.nv)[:, free]
    basis = basis - np.outer(n, n @ basis)
    u, s, _ = np.linalg.svd(basis, full_matrices=False)
    comp = u[:, s > 1e-9]
    slopes = []
    for sign in (1.0, -1.0):
        values = []
        for step in GROWTH_STEPS:
            x = np.zeros(comp.shape[1])
            value = np.inf
            for _ in range(30):
                qs = pin.integrate(model, conf.q, col * (sign * step * n + comp @ x))
                e, jac = residual(qs)
                value = float(np.linalg.norm(e))
                dx = np.linalg.lstsq((jac * col) @ comp, -e, rcond=1e-12)[0]
                x = x + dx
                if float(np.linalg.norm(dx)) < 1e-14:
                    break
            values.append(value)
        if min(values) <= GROWTH_FLOOR:
            return None
        slopes += [np.log2(b / a) for a, b in zip(values, values[1:], strict=False)]
    k = round(float(np.median(slopes)))
    return k if k >= 2 and all(abs(x - k) <= 0.4 for x in slopes) else None
