"""The local dimension of the closed set near q, estimated from closed samples: the numerical check.

Closed configurations near q are sampled: random first-order motions ``u`` (unit, dimensionless
joint rates in ``null K``) give the starts ``q (+) radius u``, each projected back onto the closed
set by the minimum-norm damped least-squares solver of :mod:`pinmob.assembly.solver` (held joints
kept; :class:`ClosedProjector`, the one projection :mod:`pinmob.analysis.finite.sample_modes` uses too). A sample's displacement ``d`` from q (dimensionless joint metric) lies, up to the branch's
curvature, in the tangent space of the branch it landed on: it is assigned to the branch whose
tangent rates ``R_b`` it is closest to (``sin angle <= ASSIGN_SIN``; farther: *unexplained*). The
samples of a branch span, in its coordinates ``R_b^T d``, as many dimensions as the branch has
(singular values above ``SAMPLE_RTOL`` of the largest, and of the radius: round-off is no dimension).

The platform's dimension on a branch is measured at the samples themselves: at a sample where the
closed chain's instantaneous DoF equals the branch's dimension (a regular point of the branch), the
rank of the platform Jacobian on the closed chain's rates there; the largest over the branch's
samples is the dimension of the platform poses it reaches (a workspace boundary at q, where the
platform gains a motion only to second order, shows there). A branch with no regular sample (a
shaky family such as the flat 3-PUU's, every point of which has extra first-order motions) falls
back on the span of its samples' platform displacements (twists ``[v / L; w]`` from q's pose).
The estimate agrees with the higher-order analysis when the largest of these equal the finite DoF
found and no sample is unexplained; the analysis says it cannot decide otherwise.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.analysis.chain.actuation import rank_of
from pinmob.analysis.chain.closed_chain import closed_chain_columns, frame_rows
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.follow.displacement import displacement
from pinmob.analysis.follow.path_follower import closed_rates
from pinmob.assembly import closure_residual, compute_kinematics, solve
from pinmob.model import short_difference
from pinmob.screw import RTOL, Array, twist_scaling

#: Size of the perturbations [rad, or m / L].
RADIUS = 0.02
#: A sample belongs to a branch when the sine of its angle to the branch's tangent space is at most this.
ASSIGN_SIN = 0.3
#: Singular values of a branch's samples above this fraction of the largest count as a dimension.
SAMPLE_RTOL = 0.05
#: Samples closer to q than this fraction of the radius are not used (they fell back onto q).
NEAR = 0.1
#: Damped iterations of each projection (a start that does not close by then is dropped).
MAX_ITER = 60
#: Convergence target of each projection (dimensionless residual); a projection is kept when it closes within
#: the configuration's closure tolerance.
PROJECT_TOL = 1e-12


class ClosedProjector:
    """The minimum-norm projection on the closed set near a configuration, the held joints kept.

    The one sampler of the closed set: :func:`local_dimension` and :mod:`pinmob.analysis.finite.sample_modes`
    both project with it. A start is damped-least-squares solved (:mod:`pinmob.assembly.solver`) to
    ``PROJECT_TOL`` in at most ``MAX_ITER`` iterations and kept when it closes within ``conf.closure_tol``.
    """

    def __init__(self, conf: Configuration, held: tuple[int, ...]) -> None:
        mech = self.mech = conf.mechanism
        self.col = closed_chain_columns(conf)
        self.residual = closure_residual(mech)
        self.held = held
        self.tol = conf.closure_tol
        self.free = np.ones(mech.model.nv, bool)
        self.free[list(held)] = False

    def __call__(self, q: Array, step: Array) -> Array | None:
        """The closed configuration from ``q (+) step`` (dimensionless) projected back (None when it does not close)."""
        model = self.mech.model
        start = pin.integrate(model, q, self.col * step)
        res = solve(
            model,
            self.residual,
            start,
            tol=PROJECT_TOL,
            max_iter=MAX_ITER,
            length=self.mech.length_scale,
            free=self.free,
            polish=False,
        )
        return res.q if res.residual <= self.tol else None

    def moved(self, a: Array, b: Array) -> Array:
        """(nv,) dimensionless displacement from a to b."""
        return short_difference(self.mech.model, a, b) / self.col


@dataclass(frozen=True)
class LocalDimension:
    """What the closed samples near q show.

    Attributes:
        tried: starts tried; ``samples``: those that closed.
        radius: size of the perturbations (dimensionless joint metric).
        dimension: largest number of dimensions the samples of one branch span.
        platform: largest number of dimensions their platform displacements span (None: no platform).
        per_branch: the samples' dimension on each branch (0: no sample on it).
        unexplained: samples on none of the branches' tangent spaces.
        near: samples that fell back onto q (not used).
    """

    tried: int
    samples: int
    radius: float
    dimension: int
    platform: int | None
    per_branch: tuple[int, ...]
    unexplained: int
    near: int

    def to_dict(self) -> dict[str, Any]:
        """The estimate as plain JSON."""
        return {
            "tried": self.tried,
            "samples": self.samples,
            "radius": self.radius,
            "dimension": self.dimension,
            "platform": self.platform,
            "per_branch": list(self.per_branch),
            "unexplained": self.unexplained,
        }


def _spread(rows: list[Array], floor: float) -> int:
    """Number of singular values of the stacked rows above ``SAMPLE_RTOL`` of the largest and of ``floor``."""
    if not rows:
        return 0
    s = np.linalg.svd(np.array(rows), compute_uv=False)
    return int(np.sum(s > SAMPLE_RTOL * max(float(s[0]), floor)))


def _platform_rank(conf: Configuration, q: Array, held: tuple[int, ...], dimension: int, rtol: float) -> int | None:
    """The platform's DoF on the closed chain at q (held joints still), or None when q is not a regular point."""
    mech = conf.mechanism
    here = Configuration.unchecked(mech, q)
    null = closed_rates(here, held, rtol)
    if null.shape[1] != dimension:
        return None
    return rank_of(frame_rows(here, mech.platform) @ null, rtol)


def local_dimension(
    conf: Configuration,
    kernel: Array,
    branches: Sequence[Array],
    held: tuple[int, ...] = (),
    *,
    rtol: float = RTOL,
    tries: int | None = None,
    radius: float = RADIUS,
    seed: int = 0,
) -> LocalDimension:
    """Sample the closed set near ``conf`` and measure it against the branches' tangent rates.

    Args:
        conf: the closed configuration.
        kernel: (nv, m) the instantaneous motions (dimensionless joint rates), held joints still.
        branches: (nv, d_b) orthonormal tangent rates of each branch.
        held: velocity indices of joints kept at their values.
        rtol: relative tolerance of the rank decisions at the samples.
        tries: starts (default ``2 m + 6``, at most 32).
        radius: size of the perturbations.
        seed: of the random directions.
    """
    mech = conf.mechanism
    model, length = mech.model, mech.length_scale
    rng = np.random.default_rng(seed)
    project = ClosedProjector(conf, held)
    m = kernel.shape[1]
    count = min(32, 2 * m + 6) if tries is None else tries
    data = pin.Data(model)
    start = conf.frame_placement(mech.platform_id) if mech.has_platform else None
    w = twist_scaling(length)
    moves: list[list[Array]] = [[] for _ in branches]
    poses: list[list[Array]] = [[] for _ in branches]
    ranks: list[list[int]] = [[] for _ in branches]
    closed = unexplained = near = 0
    for _ in range(count if m else 0):
        u = kernel @ rng.normal(size=m)
        u /= np.linalg.norm(u)
        q = project(conf.q, radius * u)
        if q is None:
            continue
        closed += 1
        d = project.moved(conf.q, q)
        size = float(np.linalg.norm(d))
        if size < NEAR * radius:
            near += 1
            continue
        sines = [float(np.linalg.norm(d - r @ (r.T @ d))) / size for r in branches]
        best = int(np.argmin(sines)) if sines else -1
        if best < 0 or sines[best] > ASSIGN_SIN:
            unexplained += 1
            continue
        moves[best].append(branches[best].T @ d / size)
        if start is not None:
            compute_kinematics(model, data, q)
            poses[best].append(w * displacement(start, data.oMf[mech.platform_id]))
            bound = min(6, branches[best].shape[1])  # no sample's rank exceeds it: once found, the largest is known
            if bound not in ranks[best]:
                rank = _platform_rank(conf, q, held, branches[best].shape[1], rtol)
                if rank is not None:
                    ranks[best].append(rank)
    per_branch = tuple(_spread(rows, 1.0) for rows in moves)
    platform = None
    if start is not None:
        platform = max((max(r) if r else _spread(p, radius) for r, p in zip(ranks, poses, strict=True)), default=0)
    return LocalDimension(
        count if m else 0, closed, radius, max(per_branch, default=0), platform, per_branch, unexplained, near
    )
