"""Screw algebra: twists, wrenches, reciprocity, unit-invariant bases, pitch and axes.

Pure numpy/scipy; this module does not import pinocchio.

Conventions (used everywhere in pinmob, never switched silently):

* A twist is ``t = [v; w]`` (linear velocity of the body point at the reference
  origin first, angular velocity second), Pinocchio's ``Motion`` order.
* A wrench is ``f = [f; tau]`` (force first, moment about the reference origin
  second), Pinocchio's ``Force`` order.
* The reciprocal product is the power ``f . v + tau . w``, i.e. the plain dot
  product ``wrench @ twist`` in this order. A wrench is reciprocal to (constrains
  nothing along) a twist when that product is zero.
* The seed paper writes twists axis first, ``(w; v)``; convert with
  :func:`twist_from_paper` only where comparing with its matrices.

Unit invariance: with a characteristic length ``L`` [m], a twist is made
dimensionless as ``[v / L; w]`` and a wrench as ``[f * L; tau]``. The product is
unchanged, and a mechanism scaled by ``k`` with ``L`` scaled by ``k`` gives the
same dimensionless matrices, hence the same ranks. Every rank decision here is
taken on dimensionless matrices with a tolerance relative to the largest
singular value.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.linalg import eigh, lapack

Array = NDArray[np.float64]
#: Boolean array, e.g. which rows of a residual are lengths.
Mask = NDArray[np.bool_]

#: Default relative tolerance on singular values for rank decisions.
RTOL = 1e-6

AXIS_NAMES = ("x", "y", "z")


class MotionKind(StrEnum):
    """Type of a free motion of the platform."""

    TRANSLATION = "T"
    ROTATION = "R"
    SCREW = "H"


class WrenchKind(StrEnum):
    """Type of a constraint wrench (the dual of :class:`MotionKind`)."""

    COUPLE = "couple"
    FORCE = "force"
    WRENCH = "wrench"


# --------------------------------------------------------------------------- basics


def reciprocal_product(wrench: ArrayLike, twist: ArrayLike) -> float:
    """Power of a wrench on a twist: ``f . v + tau . w`` [W for SI units]."""
    return float(np.dot(np.asarray(wrench, float), np.asarray(twist, float)))


def twist_from_paper(s: ArrayLike) -> Array:
    """Convert the seed paper's axis-first twist ``(w; v)`` to ``[v; w]``; rows of 6 (shape (..., 6))."""
    s = np.asarray(s, float)
    return np.concatenate([s[..., 3:], s[..., :3]], axis=-1)


def twist_to_paper(t: ArrayLike) -> Array:
    """Convert twists ``[v; w]`` to the seed paper's axis-first ``(w; v)``; rows of 6 (the inverse swap)."""
    return twist_from_paper(t)


def shift_twists(twists: ArrayLike, r: ArrayLike) -> Array:
    """Express twists at a point displaced by ``r`` from their reference point.

    ``v' = v + w x r``, ``w' = w``.

    Args:
        twists: (6,) or (6, k) twists ``[v; w]``.
        r: (3,) displacement from the old to the new reference point [m].
    """
    t = np.array(twists, float)
    r = np.asarray(r, float)
    if t.ndim == 2 and r.ndim == 1:
        r = r[:, None]
    t[:3] = t[:3] + cross_columns(t[3:], r)
    return t


def shift_wrenches(wrenches: ArrayLike, r: ArrayLike) -> Array:
    """Express wrenches at a point displaced by ``r``: ``tau' = tau - r x f``."""
    f = np.array(wrenches, float)
    r = np.asarray(r, float)
    if f.ndim == 2 and r.ndim == 1:
        r = r[:, None]
    f[3:] = f[3:] - cross_columns(r, f[:3])
    return f


def rotate(screws: ArrayLike, rotation: ArrayLike) -> Array:
    """Rotate the axes of twists or wrenches (6,) or (6, k) by a (3, 3) rotation."""
    s = np.array(screws, float)
    rot = np.asarray(rotation, float)
    s[:3] = rot @ s[:3]
    s[3:] = rot @ s[3:]
    return s


def twist_scaling(length: float) -> Array:
    """Diagonal (6,) that makes twists dimensionless: ``[v / L; w]``."""
    return np.array([1 / length] * 3 + [1.0] * 3)


def wrench_scaling(length: float) -> Array:
    """Diagonal (6,) that makes wrenches dimensionless: ``[f * L; tau]``."""
    return np.array([length] * 3 + [1.0] * 3)


# --------------------------------------------------------------------------- rank


def svd(a: Array, full_matrices: bool = True) -> tuple[Array, Array, Array]:
    """``U, s, V^T`` of a small non-empty (m, n) matrix: LAPACK's ``dgesdd``, as ``np.linalg.svd`` calls it.

    Called straight through SciPy's LAPACK wrapper: the same routine and results, without
    ``np.linalg.svd``'s per-call overhead, which dominates for 6 x 6 matrices. Falls back to
    ``np.linalg.svd`` (which raises ``LinAlgError``) if LAPACK reports a failure.
    """
    u, s, vt, info = lapack.dgesdd(a, compute_uv=1, full_matrices=int(full_matrices))
    if info != 0:
        return tuple(np.linalg.svd(a, full_matrices=full_matrices))  # type: ignore[return-value]
    return u, s, vt


def cross_columns(a: Array, b: Array) -> Array:
    """Column-wise cross product of (3,) or (3, k) arrays, ``np.cross(a, b, axis=0)`` without its axis shuffling.

    Same formula, ``(a1 b2 - a2 b1, a2 b0 - a0 b2, a0 b1 - a1 b0)``, hence the same floating-point results.
    """
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]])


@dataclass(frozen=True)
class RankDecision:
    """Outcome of a unit-invariant rank decision.

    Attributes:
        rank: number of singular values above ``tolerance``.
        singular_values: all singular values, descending.
        tolerance: absolute threshold used, ``rtol * max(singular_values)``.
        row_space: (rank, n) orthonormal basis of the row space.
        null_space: (n - rank, n) orthonormal basis of the null space.
    """

    rank: int
    singular_values: Array
    tolerance: float
    row_space: Array
    null_space: Array


def decide_rank(matrix: ArrayLike, rtol: float = RTOL, n: int | None = None) -> RankDecision:
    """SVD of a dimensionless (m, n) matrix with a tolerance relative to sigma_max.

    An empty matrix (m = 0) has rank 0 and the whole space as null space.
    """
    a = np.asarray(matrix, float)
    if a.ndim != 2:
        raise ValueError(f"expected a 2-D matrix, got shape {a.shape}")
    cols = a.shape[1] if n is None else n
    if a.size == 0:
        return RankDecision(0, np.zeros(0), 0.0, np.zeros((0, cols)), np.eye(cols))
    _, s, vt = svd(a)
    smax = float(s[0]) if s.size else 0.0
    tol = rtol * smax
    rank = int(np.sum(s > tol)) if smax > 0 else 0
    return RankDecision(rank, s, tol, vt[:rank], vt[rank:])


def reciprocal_wrenches(twists: ArrayLike, length: float, rtol: float = RTOL) -> tuple[Array, RankDecision]:
    """Basis of the wrenches reciprocal to every twist given.

    Solves ``W^T T = 0`` on the dimensionless matrices: the null space of
    ``(D_t T)^T`` where ``D_t = diag(1/L, 1/L, 1/L, 1, 1, 1)``, mapped back by
    ``f = f_hat / L``.

    Args:
        twists: (6, k) twists ``[v; w]`` [m/s, rad/s per unit joint rate].
        length: characteristic length L [m].
        rtol: relative tolerance on the singular values.

    Returns:
        (6, 6 - rank) wrenches ``[f; tau]`` (orthonormal when dimensionless),
        and the rank decision on the twists.
    """
    t = np.asarray(twists, float).reshape(6, -1)
    dec = decide_rank((twist_scaling(length)[:, None] * t).T, rtol, n=6)
    w_hat = dec.null_space.T
    return w_hat / wrench_scaling(length)[:, None], dec


def reciprocal_twists(wrenches: ArrayLike, length: float, rtol: float = RTOL) -> tuple[Array, RankDecision]:
    """Basis of the twists reciprocal to every wrench given (dual of :func:`reciprocal_wrenches`).

    Returns:
        (6, 6 - rank) twists ``[v; w]`` and the rank decision on the wrenches.
    """
    w = np.asarray(wrenches, float).reshape(6, -1)
    dec = decide_rank((wrench_scaling(length)[:, None] * w).T, rtol, n=6)
    return dec.null_space.T / twist_scaling(length)[:, None], dec


def subspace_gap(a: ArrayLike, b: ArrayLike) -> float:
    """Largest sine of the principal angles between the column spans of a and b.

    0 when the spans are equal, 1 when one holds a direction orthogonal to the
    other. Spans of different dimension give 1. Scale the inputs first when they
    mix units.
    """
    a = np.asarray(a, float)
    b = np.asarray(b, float)
    if a.shape[1] != b.shape[1]:
        return 1.0
    if a.shape[1] == 0:
        return 0.0
    qa = np.linalg.qr(a)[0]
    qb = np.linalg.qr(b)[0]
    cos = np.linalg.svd(qa.T @ qb, compute_uv=False)
    return float(np.sqrt(max(0.0, 1.0 - float(np.min(cos)) ** 2)))


# --------------------------------------------------------------------------- canonical bases


def canonical_directions(basis: ArrayLike, tol: float = 1e-9) -> Array:
    """Canonical orthonormal basis of a subspace of R^3.

    Greedy: at each step, project the world axes x, y, z onto what is left of
    the subspace, take the axis with the largest projection (ties go to the
    earlier axis), normalise the projection and remove it. The result is sorted
    by that axis and each vector points along its axis, so the basis depends only
    on the subspace, not on the input basis.

    Args:
        basis: (3, k) spanning vectors, k <= 3 (need not be orthonormal).

    Returns:
        (3, r) orthonormal canonical basis, r the rank of ``basis`` (singular
        values above ``tol * max(1, sigma_max)``).
    """
    d = np.asarray(basis, float).reshape(3, -1)
    if d.shape[1] == 0:
        return np.zeros((3, 0))
    u, s, _ = svd(d, full_matrices=False)
    rest = u[:, s > tol * max(1.0, float(s[0]))]
    picked: list[tuple[int, Array]] = []
    proj = rest @ rest.T  # projector onto what is left of the subspace
    for _ in range(rest.shape[1]):
        norms = np.sqrt((proj * proj).sum(axis=0))
        axis = int(np.argmax(norms > norms.max() - tol))  # first axis within tol of the best
        vec = proj[:, axis] / norms[axis]
        picked.append((axis, vec))
        proj = proj - np.outer(vec, vec)  # vec lies in the subspace: P - vec vec^T projects onto the rest
    if not picked:
        return np.zeros((3, 0))
    picked.sort(key=lambda p: p[0])
    return np.column_stack([clean(v) for _, v in picked])


def axis_label(direction: ArrayLike, tol: float = 1e-9) -> str:
    """``'x'``, ``'-y'``, ... for a world axis, else the rounded vector."""
    u = np.asarray(direction, float)
    for i, name in enumerate(AXIS_NAMES):
        if abs(abs(u[i]) - 1.0) < tol:
            return name if u[i] > 0 else "-" + name
    return "[" + ", ".join(f"{c:.3g}" for c in u) + "]"


def clean(a: Array, scale: float = 1.0, tol: float = 1e-10) -> Array:
    """Zero the entries of ``a`` below ``tol * scale`` (numerical dust) and drop signed zeros."""
    a = np.where(np.abs(a) < tol * scale, 0.0, a)
    return a + 0.0


def _positive(u: Array, tol: float = 1e-9) -> Array:
    """Flip u so that its largest-magnitude component (first on ties) is positive."""
    i = int(np.argmax(np.abs(u) > np.abs(u).max() - tol))
    return u if u[i] >= 0 else -u


# --------------------------------------------------------------------------- classification


@dataclass(frozen=True)
class Screw:
    """One principal screw of a screw system, in SI units.

    For a twist system: ``direction`` is the unit angular (or, for a
    translation, linear) direction, ``point`` the axis point closest to the
    reference origin (``None`` for a translation), ``pitch`` [m/rad] (``None``
    for a translation), ``vector`` the unit twist ``[v; w]``. For a wrench system
    the same fields describe couples, forces and wrenches; ``vector`` is
    ``[f; tau]``.

    Attributes:
        kind: a :class:`MotionKind` in a twist system, a :class:`WrenchKind` in a wrench system.
    """

    kind: MotionKind | WrenchKind
    direction: Array
    point: Array | None
    pitch: float | None
    vector: Array


@dataclass(frozen=True)
class ScrewSystem:
    """Canonical description of a subspace of twists (or wrenches)."""

    free_vectors: tuple[Screw, ...]  # pure translations (or pure couples)
    lines: tuple[Screw, ...]  # zero-pitch screws: rotations (or forces)
    screws: tuple[Screw, ...]  # finite non-zero pitch

    @property
    def all(self) -> tuple[Screw, ...]:
        return self.free_vectors + self.lines + self.screws

    def basis(self) -> Array:
        """(6, k) matrix of the canonical vectors, in the order of :attr:`all`."""
        vecs = [s.vector for s in self.all]
        return np.column_stack(vecs) if vecs else np.zeros((6, 0))


def principal_screws(
    moment: ArrayLike, direction: ArrayLike, rtol: float = RTOL
) -> tuple[Array, list[tuple[Array, Array, float]]]:
    """Split a screw system into free vectors and principal screws.

    The system is given as matching columns of ``moment`` (v for twists, tau for
    wrenches) and ``direction`` (w for twists, f for wrenches), i.e. screws
    ``[moment; direction]``, dimensionless (moment already divided by L).

    1. Free vectors: the subspace with ``direction = 0``; their moments span
       the free translation (couple) directions T. Every other screw is only
       defined up to adding members of T to its moment.
    2. Directions w with a component along T can have their pitch cancelled
       by such an addition (``h = w.(v + T a) / w.w`` takes any value): they are
       zero-pitch screws (rotations, forces), one per direction of the
       orthogonal complement of ``W0 = span(w) ∩ T^perp`` in ``span(w)``.
    3. On W0 the pitch does not depend on the representative; its stationary
       values solve the generalised eigenproblem
       ``sym(W^T V) x = h (W^T W) x`` (restricted to W0): the principal
       pitches, independent of the basis and of the reference point.
    4. Each axis point is the one closest to the origin:
       ``min_a |P_u^perp (v + T a)|`` subject to ``u.(v + T a) = h``; the
       point is ``u x (v + T a)``. Equal pitches are made canonical with
       :func:`canonical_directions`.

    Returns:
        (3, p) canonical free-vector directions, and per principal screw the unit
        direction u, the axis point, and the pitch, both dimensionless (multiply
        by L for SI).
    """
    v = np.asarray(moment, float).reshape(3, -1)
    w = np.asarray(direction, float).reshape(3, -1)
    if v.shape[1] == 0:
        return np.zeros((3, 0)), []
    span = _orthonormal_span(np.vstack([v, w]), rtol)
    if span.shape[1] == 0:
        return np.zeros((3, 0)), []
    v, w = span[:3], span[3:]
    _, s_w, vt_w = svd(w)
    wr = int(np.sum(s_w > rtol * max(1.0, float(s_w[0]) if s_w.size else 0.0)))
    trans = canonical_directions(v @ vt_w[wr:].T) if wr < vt_w.shape[0] else np.zeros((3, 0))
    if wr == 0:
        return trans, []
    gv, gw = v @ vt_w[:wr].T, w @ vt_w[:wr].T  # complement: span(gw) has dimension wr
    pitch_tol = max(1e-9, 10 * rtol)
    # split span(gw) into W0 (perpendicular to T) and its orthogonal complement W1
    if trans.shape[1]:
        dec = decide_rank(trans.T @ gw, rtol, n=wr)
        x0, x1 = dec.null_space.T, dec.row_space.T
    else:
        x0, x1 = np.eye(wr), np.zeros((wr, 0))
    groups: list[tuple[Array, float]] = []
    if x1.shape[1]:
        # W1 directions, orthogonal to W0 in direction space, all with pitch 0
        w0 = gw @ x0
        u1 = canonical_directions(gw @ x1 - (w0 @ np.linalg.pinv(w0) @ (gw @ x1) if w0.size else 0))
        groups.append((np.asarray(np.linalg.lstsq(gw, u1, rcond=None)[0], dtype=np.float64), 0.0))
    if x0.shape[1]:
        a = x0.T @ (0.5 * (gw.T @ gv + gv.T @ gw)) @ x0
        b = x0.T @ gw.T @ gw @ x0
        pitches, y = eigh(a, b)
        i = 0
        while i < len(pitches):
            j = i
            while j + 1 < len(pitches) and abs(pitches[j + 1] - pitches[i]) <= pitch_tol:
                j += 1
            group = x0 @ y[:, i : j + 1]
            dirs = canonical_directions(gw @ group)
            groups.append(
                (group @ np.linalg.lstsq(gw @ group, dirs, rcond=None)[0], float(np.mean(pitches[i : j + 1])))
            )
            i = j + 1
    out: list[tuple[Array, Array, float]] = []
    for coeffs, pitch in groups:
        h = 0.0 if abs(pitch) <= pitch_tol else pitch
        for xc in coeffs.T:
            ww, vv = gw @ xc, gv @ xc
            nw = np.linalg.norm(ww)
            u = _positive(ww / nw)
            vv = vv / nw * (1.0 if u @ ww > 0 else -1.0)
            vv = _closest_moment(u, vv, trans, h)
            out.append((clean(u), clean(cross_columns(u, vv)), h))
    return trans, out


def _orthonormal_span(m: Array, rtol: float, tol: float = 1e-12) -> Array:
    """(6, r) orthonormal basis of the column span of ``m`` (6, k), by SVD (rank decided with ``rtol``).

    An unpivoted QR would drop directions when an early column depends on the ones
    before it. Columns that are already orthogonal with one common length (``m^T m = c I``
    to ``tol``: the bases :func:`reciprocal_twists` and :func:`reciprocal_wrenches` return)
    span with rank k whatever ``rtol`` is, and are returned rescaled instead of decomposed again.
    """
    gram = m.T @ m
    c = float(np.trace(gram)) / max(1, gram.shape[0])
    if c > 0 and np.all(np.abs(gram / c - np.eye(gram.shape[0])) <= tol):
        return np.asarray(m / np.sqrt(c), dtype=np.float64)
    return decide_rank(m.T, rtol, n=6).row_space.T


def _orthogonal_complement(c: Array) -> Array:
    """(k, k - 1) orthonormal basis of the vectors orthogonal to a non-zero c (k,): a Householder reflection.

    ``H = I - 2 h h^T / h.h`` with ``h = c + sign(c_0) |c| e_0`` maps c onto the first axis; its other
    columns are orthonormal and orthogonal to c (no SVD needed for one vector).
    """
    h = np.array(c, float)
    h[0] += np.copysign(np.linalg.norm(c), c[0])
    return (np.eye(c.size) - 2.0 * np.outer(h, h) / (h @ h))[:, 1:]


def _closest_moment(u: Array, v: Array, trans: Array, pitch: float) -> Array:
    """``v + T a`` minimising ``|P_u^perp (v + T a)|`` with ``u.(v + T a) = pitch`` where T allows it."""
    if not trans.shape[1]:
        return v
    perp = np.eye(3) - np.outer(u, u)
    c = trans.T @ u
    if np.linalg.norm(c) > 1e-9:
        a0 = c * (pitch - u @ v) / (c @ c)
        null = _orthogonal_complement(c)
    else:
        a0, null = np.zeros(trans.shape[1]), np.eye(trans.shape[1])
    base = v + trans @ a0
    if null.shape[1]:
        b = np.linalg.lstsq(perp @ trans @ null, -perp @ base, rcond=None)[0]
        base = base + trans @ null @ b
    return base


def classify_twists(twists: ArrayLike, length: float, rtol: float = RTOL) -> ScrewSystem:
    """Classify a twist system: translations, rotations (pitch ~ 0), screws.

    Args:
        twists: (6, k) basis ``[v; w]`` in SI units.
        length: characteristic length L [m]; pitches and points are computed on
            ``[v / L; w]`` and returned in metres.
        rtol: relative tolerance for ranks and for a zero pitch (pitch/L).
    """
    t = np.asarray(twists, float).reshape(6, -1)
    trans, prin = principal_screws(t[:3] / length, t[3:], rtol)
    ts = tuple(
        Screw(MotionKind.TRANSLATION, clean(d), None, None, np.concatenate([clean(d), np.zeros(3)])) for d in trans.T
    )
    rot: list[Screw] = []
    scr: list[Screw] = []
    for u, p, h in prin:
        point, pitch = p * length, h * length
        vec = clean(np.concatenate([pitch * u + cross_columns(point, u), u]), length)
        kind = MotionKind.ROTATION if h == 0.0 else MotionKind.SCREW
        (rot if h == 0.0 else scr).append(Screw(kind, u, point, pitch, vec))
    scr.sort(key=lambda s: s.pitch or 0.0)
    return ScrewSystem(ts, tuple(rot), tuple(scr))


def classify_wrenches(wrenches: ArrayLike, length: float, rtol: float = RTOL) -> ScrewSystem:
    """Classify a wrench system: couples, forces (pitch ~ 0) and wrenches.

    The dual of :func:`classify_twists`: a wrench ``[f; tau]`` is a screw of
    direction f and moment tau; a couple has f = 0. Dimensionless form
    ``[f L; tau]`` (moment divided by L relative to direction).
    """
    f = np.asarray(wrenches, float).reshape(6, -1)
    couples, prin = principal_screws(f[3:] / length, f[:3], rtol)
    cs = tuple(
        Screw(WrenchKind.COUPLE, clean(d), None, None, np.concatenate([np.zeros(3), clean(d)])) for d in couples.T
    )
    forces: list[Screw] = []
    screws: list[Screw] = []
    for u, p, h in prin:
        point, pitch = p * length, h * length
        vec = clean(np.concatenate([u, pitch * u + cross_columns(point, u)]), length)
        kind = WrenchKind.FORCE if h == 0.0 else WrenchKind.WRENCH
        (forces if h == 0.0 else screws).append(Screw(kind, u, point, pitch, vec))
    screws.sort(key=lambda s: s.pitch or 0.0)
    return ScrewSystem(cs, tuple(forces), tuple(screws))


def motion_type(system: ScrewSystem) -> str:
    """Label such as ``3T``, ``1T2R``, ``1T1R1H``; ``rigid`` for no motion."""
    counts = [(len(system.free_vectors), "T"), (len(system.lines), "R"), (len(system.screws), "H")]
    label = "".join(f"{n}{c}" for n, c in counts if n)
    return label or "rigid"
