"""Classification of screw systems: translations, rotations and screws (couples, forces and wrenches).

Basis-independent and independent of the reference point: the free vectors
(pure translations, or pure couples) are the members with no direction part;
on the rest, the principal screws are the stationary values of the pitch
``h = w . v / w . w`` (:func:`principal_screws`). Each axis point is the one
closest to the reference origin, given the free vectors.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum

import numpy as np
from numpy.typing import ArrayLike

from pinmob.screw.algebra import Array, cross_columns
from pinmob.screw.bases import clean, positive
from pinmob.screw.rank import RTOL, decide_rank
from pinmob.screw.screw_groups import screw_groups


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
        """Every screw: free vectors, then lines, then screws."""
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
    if span.shape[1] == 6:  # every screw: the free vectors along x, y, z and the lines x, y, z through the origin
        return np.eye(3), [(np.eye(3)[i], np.zeros(3), 0.0) for i in range(3)]
    return principal_screws_of_span(span, rtol)


def principal_screws_of_span(span: Array, rtol: float = RTOL) -> tuple[Array, list[tuple[Array, Array, float]]]:
    """:func:`principal_screws` of an orthonormal basis ``span`` (6, r) of ``[moment; direction]`` (steps 1-4).

    :func:`principal_screws` answers the whole space (r = 6) in closed form; the tests compare it with these steps.
    """
    trans, gv, gw, found = screw_groups(span, rtol)
    tie, pitch_tol = max(1e-9, rtol), max(1e-9, 10 * rtol)
    groups = [
        (np.asarray(np.linalg.lstsq(gw, dirs, rcond=None)[0], dtype=np.float64) if basis is None
         else basis @ np.linalg.lstsq(gw @ basis, dirs, rcond=None)[0], pitch)
        for basis, dirs, pitch in found
    ]  # fmt: skip
    out: list[tuple[Array, Array, float]] = []
    for coeffs, pitch in groups:
        h = 0.0 if abs(pitch) <= pitch_tol else pitch
        for xc in coeffs.T:
            ww, vv = gw @ xc, gv @ xc
            nw = np.linalg.norm(ww)
            u = positive(ww / nw, tie)
            vv = vv / nw * (1.0 if u @ ww > 0 else -1.0)
            vv = _closest_moment(u, vv, trans, h, rtol)
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


def _closest_moment(u: Array, v: Array, trans: Array, pitch: float, rtol: float = RTOL) -> Array:
    """``v + T a`` minimising ``|P_u^perp (v + T a)|`` with ``u.(v + T a) = pitch`` where T allows it.

    The pitch constrains ``a`` only when u has a component ``c = T^T u`` along the free translations:
    above ``rtol`` (unit vectors, natural scale 1: the rank rule's threshold that put u among the
    directions with or without such a component). Round-off below it (a pencil of rotations beside a
    translation, closed to 1e-9) would divide by itself and throw the axis point far away.
    """
    if not trans.shape[1]:
        return v
    perp = np.eye(3) - np.outer(u, u)
    c = trans.T @ u
    if np.linalg.norm(c) > max(rtol, 1e-9):
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
