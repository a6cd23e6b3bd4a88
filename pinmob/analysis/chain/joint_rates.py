"""Joint-rate vectors as printed: by joint name, largest 1, on one canonical basis of their space.

The motions left with the actuators locked, the finite analysis's internal motions and branch
tangents are spaces of joint rates; each is printed on :func:`canonical_rates`' basis, so that what
is printed does not depend on the basis an SVD gave (nor on the order of the limbs).
"""

from __future__ import annotations

import numpy as np

from pinmob.model import Mechanism
from pinmob.screw import Array, canonical_basis

#: Dimensionless joint rates closer than this are ties in their canonical basis (:func:`canonical_rates`: the
#: earlier joint in model order wins, as for the printed rates, which have six decimals: round-off near a singularity
#: must not pick the sign).
RATE_TIE = 1e-6


def canonical_rates(rates: Array) -> Array:
    """The canonical orthonormal basis of the span of dimensionless joint rates (nv, k) (see :data:`RATE_TIE`).

    :func:`~pinmob.screw.bases.canonical_basis` with ties within :data:`RATE_TIE`: the motions printed for a
    space of joint rates do not depend on the basis an SVD gave, so neither on the order of the limbs.
    """
    return canonical_basis(rates, RATE_TIE)


def joint_rates(mech: Mechanism, dq: Array) -> dict[str, float]:
    """Joint rates by name (largest magnitude 1, below 1e-6 dropped); a multi-degree joint by its largest component.

    That component is the first within :data:`RATE_TIE` of the largest (a free joint whose two largest
    components are equal in size printed one or the other, as round-off had it).

    Ordered by magnitude to three significant digits (as printed), then as the joints are in the model: rates equal by
    symmetry (a five-bar's two elbows) keep one order rather than the one round-off picks.
    """
    big = float(np.max(np.abs(dq))) if dq.size else 0.0
    out: dict[str, float] = {}
    if big == 0:
        return out
    rates = (dq / big).tolist()
    for name, start, stop in velocity_segments(mech):
        if stop == start + 1:  # one component (most joints): itself
            if abs(rates[start]) > 1e-6:
                out[name] = round(rates[start], 6)
            continue
        part = rates[start:stop]
        size = [abs(x) for x in part]
        top = max(size)
        if top > 1e-6:  # the first largest component, within RATE_TIE (round-off must not pick between equal ones)
            out[name] = round(part[next(k for k, x in enumerate(size) if x >= top - RATE_TIE)], 6)
    return dict(sorted(out.items(), key=lambda kv: -float(f"{abs(kv[1]):.3g}")))


def velocity_segments(mech: Mechanism) -> tuple[tuple[str, int, int], ...]:
    """Each joint with a velocity, in model order: (name, first velocity index, one past its last); once per mechanism."""

    def compute() -> tuple[tuple[str, int, int], ...]:
        model = mech.model
        joints = [(model.names[j], model.joints[j]) for j in range(1, model.njoints)]
        return tuple((name, joint.idx_v, joint.idx_v + joint.nv) for name, joint in joints if joint.nv)

    return mech.memo("velocity segments", compute)
