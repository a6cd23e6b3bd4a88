"""Motion modes from closed samples: the evidence that decides where the higher-order conditions do not.

The tangent-cone tests of :mod:`pinmob.analysis.finite.finite_side` decide nothing when the second-order cone is
not a union of linear spaces (a branch that is itself singular at q, such as the Delta's tilting mode at
``rods-horizontal``), or when a condition lands near its tolerance. :func:`decide_by_samples` then uses
what an independent check would:

1. **Closed samples near q.** Starts ``q (+) RADIUS u`` along random first-order motions, points of the
   second-order cone off its linear components, and the linear components, projected on the closed set.
2. **Their local dimension.** At a sample p each first-order motion (the kernel at p) is probed: p moved
   ``PROBE`` along it and projected back. The motions that extend (landing about all the way along) span
   the tangent space of the closed set at p, the others (landing about where they started) exist to
   first order only; the number that extend is the mode's DoF at p, and the platform's DoF and motion
   type on the mode are those of that tangent space.
3. **Modes.** Regular samples on a linear cone component's tangent space (and of its dimension)
   confirm it as a branch; the others are grouped by (dimension, platform DoF): a mode whose tangent
   cone at q is not linear. The finite DoF are the largest found.
4. **The reduced equation.** With a single first-order motion left, the order at which the closure
   equations reduced to it start (:mod:`pinmob.analysis.finite.sample_modes`): ``s^k``, k >= 2, makes q isolated.

Every figure the decision rests on is far from its threshold (a probe extends by about 1 or 0) or an
integer; the evidence is printed in words, so that it does not depend on round-off (nor on the BLAS).
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass

import numpy as np
import pinocchio as pin

from pinmob.analysis.chain.closed_chain import closed_chain_columns
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.finite.branches import Branch, platform_motions
from pinmob.analysis.finite.higher_order import HigherOrder
from pinmob.analysis.finite.local_dimension import ClosedProjector, LocalDimension
from pinmob.analysis.finite.tangent_cone import cone_point
from pinmob.analysis.finite.verdicts import sine_to
from pinmob.analysis.follow.path_follower import closed_rates
from pinmob.analysis.motion import Motion
from pinmob.assembly import closure_residual
from pinmob.screw import Array, decide_rank

#: Distance of the samples from q (dimensionless joint metric: rad, or m / L).
RADIUS = 0.03
#: Size of the probes of a sample's first-order motions.
PROBE = 0.002
#: A probed direction extends when its share of the probes' displacements is above this (a real motion: about 1).
EXTENDS = 0.5
#: Relative rank tolerance of the platform's motions on a sample's tangent (the probes leave about 1e-3 near q).
SAMPLE_RTOL = 1e-2
#: Random first-order motions and cone points tried as starts.
STARTS = 3
#: Samples probed per linear component (more landing on it are not probed).
PER_COMPONENT = 2
#: Random starts of the search for cone points off the linear components.
CONE_TRIES = 16
#: Linear components (the largest first) each given a start of its own.
COMPONENT_STARTS = 2
#: A sample belongs to a linear component when the sine of its displacement's angle to it is at most this.
ON_COMPONENT = 0.3
#: Directions below this fraction of the largest are not in the span of the samples' tangents.
REACH_TOL = 0.05


@dataclass(frozen=True)
class ModeSample:
    """A regular closed sample near q: the mode it lies on, seen there.

    Attributes:
        displacement: (nv,) its dimensionless displacement from q.
        dimension: the mode's DoF (the closed chain's, held joints still).
        dof, motion_type, motions: the platform's DoF, motion type and motions on it (None, None, ()
            without a platform).
        rates: (nv, dimension) the mode's tangent rates at the sample.
    """

    displacement: Array
    dimension: int
    dof: int | None
    motion_type: str | None
    motions: tuple[Motion, ...]
    rates: Array


@dataclass(frozen=True)
class Evidence:
    """What the closed samples (or the reduced equation) decide.

    Attributes:
        finite_mechanism_dof, finite_dof: the finite DoF found (None: not decided, or no platform).
        branches: the linear components the samples confirm, then the modes whose tangent cone is not linear.
        how: the evidence that decided, in words ('' when nothing did).
        conflict: why it did not decide, with the numbers ('' when it did).
        samples: the samples as a local-dimension estimate (starts tried, closed, the radius, the largest
            dimension and platform DoF, each mode's dimension; none unexplained, ``near``: those fallen back onto q).
        reach: (nv, k) orthonormal joint rates spanning every regular sample's tangent (to ``REACH_TOL``).
    """

    finite_mechanism_dof: int | None
    finite_dof: int | None
    branches: tuple[Branch, ...]
    how: str
    conflict: str
    samples: LocalDimension
    reach: Array


def regular_sample(
    conf: Configuration, q: Array, project: ClosedProjector, rtol: float, known: int | None = None
) -> ModeSample | None:
    """The :class:`ModeSample` at the closed q near conf, or None where its probes do not tell.

    ``known``: the dimension of the traced linear branch q lies on; a kernel of that dimension at q makes q
    a regular point of the branch, not probed.

    Each first-order motion u_i at q (the kernel's basis, held joints still) is probed: q moved ``+-PROBE u_i``
    and projected back. The central differences over ``PROBE``, D, map the kernel onto the closed set's tangent
    space at q: singular values about 1 (a motion that extends) or 0 (one that exists to first order only).
    The mode's dimension is the number above ``EXTENDS``; one between ``EXTENDS / 2`` and ``1 - EXTENDS / 2``
    tells nothing: None.
    """
    mech = conf.mechanism
    here = Configuration.unchecked(mech, q)
    null = closed_rates(here, project.held, rtol)
    moves = []
    for i in range(0 if null.shape[1] == known else null.shape[1]):
        ends = [project(q, sign * PROBE * null[:, i]) for sign in (1.0, -1.0)]
        if ends[0] is None or ends[1] is None:
            return None
        moves.append(project.moved(ends[1], ends[0]) / (2 * PROBE))  # central: the curvature's share cancels
    tangent = null if null.shape[1] == known else np.zeros((mech.model.nv, 0))
    if moves:
        _, sv, vt = np.linalg.svd(np.array(moves).T, full_matrices=False)  # D = U S V^T, (nv, d)
        if np.any((sv > EXTENDS / 2) & (sv < 1 - EXTENDS / 2)):
            return None
        tangent = null @ vt[: int(np.sum(sv > EXTENDS))].T  # the kernel's combinations that extend
    if not mech.has_platform:
        return ModeSample(project.moved(conf.q, q), tangent.shape[1], None, None, (), tangent)
    # every motion extends: the tangent is the kernel, exact (classified as at q); else found to about PROBE^2
    dof, kind, motions = platform_motions(here, tangent, rtol if tangent.shape[1] == null.shape[1] else SAMPLE_RTOL)
    return ModeSample(project.moved(conf.q, q), tangent.shape[1], dof, kind, motions, tangent)


def cone_directions(ho: HigherOrder, avoid: list[Array], count: int, rng: np.random.Generator) -> list[Array]:
    """Up to ``count`` unit cone points (``Q(y) = 0``, from random starts), none within ``ON_COMPONENT`` of ``avoid``."""
    h = ho.forms()
    m = ho.m
    if m == 0 or h.shape[0] == 0:
        return []
    out: list[Array] = []
    for _ in range(CONE_TRIES):
        if len(out) == count:
            break
        x = cone_point(h, np.asarray(rng.normal(size=m), float))
        y = x / np.linalg.norm(x)
        if float(np.max(np.abs(np.einsum("lab,a,b->l", h, y, y)))) > ho.tol:
            continue
        if any(float(np.linalg.norm(y - b @ (b.T @ y))) <= ON_COMPONENT for b in avoid):
            continue
        out.append(y)
    return out


def _on(sample: ModeSample, branch: Branch) -> bool:
    """The sample lies on the branch's tangent space (and has its dimension)."""
    return sample.dimension == branch.dimension and sine_to(sample.displacement, branch.rates) <= ON_COMPONENT


def _group(samples: list[ModeSample], branches: tuple[Branch, ...]) -> tuple[list[Branch], list[list[ModeSample]]]:
    """(the linear components some sample confirms, the other samples grouped by (dimension, platform DoF))."""
    rest: list[ModeSample] = []
    taken = [False] * len(branches)
    for sample in samples:
        on = [i for i, b in enumerate(branches) if _on(sample, b)]
        if on:
            taken[on[0]] = True
        else:
            rest.append(sample)
    confirmed: list[Branch] = [b for b, t in zip(branches, taken, strict=True) if t]
    groups: dict[tuple[int, int], list[ModeSample]] = {}
    for sample in rest:
        groups.setdefault((sample.dimension, sample.dof or 0), []).append(sample)
    return confirmed, [groups[k] for k in sorted(groups, reverse=True)]


def _mode(group: list[ModeSample]) -> Branch:
    """A mode seen only at its samples: its platform motion type is the most frequent among them (ties: by name)."""
    kinds = Counter(s.motion_type for s in group)
    kind = min(kinds, key=lambda k: (-kinds[k], k or ""))
    sample = next(s for s in group if s.motion_type == kind)
    note = "its tangent cone at q is not a linear space: seen at closed samples near q"
    return Branch(sample.dimension, sample.dof, kind, sample.motions, "near q", sample.rates, None, 0.0, note)


def decide_by_samples(
    conf: Configuration,
    kernel: Array,
    ho: HigherOrder | None,
    branches: tuple[Branch, ...],
    held: tuple[int, ...],
    rtol: float,
    seed: int = 0,
) -> Evidence:
    """Decide the finite DoF from closed samples near q and, with one motion left, the reduced equation.

    Args:
        conf: the closed configuration.
        kernel: (nv, m) the first-order motions at q (dimensionless joint rates, held joints still).
        ho: the higher-order conditions there (held joints held), whose second-order cone gives starts off
            its linear components; None where they are not written (:mod:`pinmob.analysis.finite.sampled_side`):
            then every sample is probed, none taken for a regular point of a candidate branch.
        branches: the candidate branches: the linear cone components that passed the conditions, or (without
            ``ho``) the whole first-order kernel.
        held: velocity indices of the joints held.
        rtol: relative tolerance of the rank decisions.
        seed: of the random starts.
    """
    mech = conf.mechanism
    nv = mech.model.nv
    has_platform = mech.has_platform
    m = kernel.shape[1]
    if m == 1:
        k = reduced_growth(conf, kernel[:, 0], held)
        if k is not None:
            how = f"the closure equations reduced to the one first-order motion: they grow like s^{k}, q is isolated"
            none = LocalDimension(0, 0, RADIUS, 0, 0 if has_platform else None, (), 0, 0)
            return Evidence(0, 0 if has_platform else None, (), how, "", none, np.zeros((nv, 0)))
    rng = np.random.default_rng(seed)
    project = ClosedProjector(conf, held)
    starts = [kernel @ rng.normal(size=m) for _ in range(STARTS if m else 0)]
    if ho is not None:
        on_kernel = [np.linalg.qr(np.linalg.lstsq(kernel, b.rates, rcond=None)[0])[0] for b in branches]
        starts += [kernel @ y for y in cone_directions(ho, on_kernel, STARTS, rng)]
    for b in sorted(branches, key=lambda b: -b.dimension)[:COMPONENT_STARTS]:
        starts.append(b.rates @ rng.normal(size=b.dimension))
    samples: list[ModeSample] = []
    tried = closed = back = 0
    for u in starts:
        norm = float(np.linalg.norm(u))
        if norm < 1e-12:
            continue
        tried += 1
        q = project(conf.q, RADIUS * u / norm)
        closed += q is not None
        if q is None or float(np.linalg.norm(project.moved(conf.q, q))) < 0.1 * RADIUS:
            back += q is not None
            continue
        d = project.moved(conf.q, q)
        near = [i for i, b in enumerate(branches) if sine_to(d, b.rates) <= ON_COMPONENT]
        if near and sum(_on(s, branches[near[0]]) for s in samples) >= PER_COMPONENT:
            continue  # that linear component has its samples: the probes (the cost) go to the others
        known = branches[near[0]].dimension if ho is not None and near and branches[near[0]].traced > 0 else None
        sample = regular_sample(conf, q, project, rtol, known)
        if sample is not None:
            samples.append(sample)

    def estimate(dimension: int, dof: int | None, per_branch: tuple[int, ...]) -> LocalDimension:
        return LocalDimension(tried, closed, RADIUS, dimension, dof, per_branch, 0, back)

    if not samples and tried and back == tried:
        how = "closed samples near q: every one fell back onto q, which is isolated"
        return Evidence(
            0, 0 if has_platform else None, (), how, "", estimate(0, 0 if has_platform else None, ()), np.zeros((nv, 0))
        )
    if not samples:
        conflict = f"the probes of none of {tried} closed samples near q tell its dimension (probe {PROBE:g})"
        return Evidence(None, None, (), "", conflict, estimate(0, None, ()), np.zeros((nv, 0)))
    confirmed, groups = _group(samples, branches)
    found = tuple(confirmed) + tuple(_mode(g) for g in groups)
    mech_dof = max(s.dimension for s in samples)
    dof = max(s.dof or 0 for s in samples) if has_platform else None
    how = "closed samples near q (at each, the first-order motions that extend when probed)"
    reach = decide_rank(np.hstack([s.rates for s in samples]).T, REACH_TOL, at_least=1.0).row_space.T
    return Evidence(mech_dof, dof, found, how, "", estimate(mech_dof, dof, tuple(b.dimension for b in found)), reach)


# ------------------------------------------------------------------ the reduced equation
#
# The closure equations reduced to a single first-order motion: the order at which they start.
#
# Where one first-order motion n is left (``m == 1``: e.g. the actuators held at a constraint singularity where
# two modes meet), the closure equations ``F(q (+) x) = 0`` split (Lyapunov-Schmidt) into a part solved in every
# direction w orthogonal to n (the Jacobian has full rank there) and what is left, the reduced equation
# ``g(s) = min_w |F(q (+) (s n + w))|`` along n. q is an isolated solution when g grows like ``s^k`` (k >= 2) on both
# sides; a curve through q along n makes g vanish. The higher-order conditions ask the same question order by
# order; this answers it from the equations themselves, at steps far above round-off
# (:mod:`pinmob.analysis.finite.sample_modes` uses it where the conditions up to the order bound do not decide).

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
