"""Glyphs of free motions and constraint wrenches, as triangle meshes in world coordinates, laid out apart.

- translation: an arrow along its direction. A translation is a free vector
  (it has no position), so the translation arrows start together from a point
  beside the platform origin (:func:`free_vector_start`), off every rotation
  and screw axis, so that an arrow along an axis is never hidden inside it;
- rotation: its axis as a line through the axis point, and a ring around the
  axis with an arrow head giving the positive sense (right hand), set along
  the axis past the axis point so that the rings of axes meeting at one point
  do not cross;
- screw: its axis and a helix whose advance per turn shows the pitch's sign,
  coloured by the pitch (blue negative, grey zero, red positive, saturating at
  ``|h| = L``);
- force: a line along its line of action with an arrow head;
- couple: a double-headed arrow; the couples, also free vectors, start
  together from a point on the other side of the platform origin.

Every glyph has an ``anchor``: the world point its label is drawn at (the
viewer's panel script writes the label there). Axis points
(``Motion.point``, ``Constraint.point``) are relative to the platform origin
(world axes): a glyph's axis passes through the world point
``platform_origin + point`` (:func:`world_point`).

Sizes are fractions of the length scale L [m]. Pure numpy: the geometry is
``(vertices (n, 3), faces (m, 3))``; :mod:`pinmob.viewer.scene` wraps it in meshcat
objects drawn on top of the mechanism (no depth test), so that the platform
never hides them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from pinmob.analysis import Constraint, Motion
from pinmob.screw import MotionKind, WrenchKind

Array = np.ndarray

TRANSLATION_COLOR = 0x1565C0
ROTATION_COLOR = 0xE65100
FORCE_COLOR = 0xC62828
COUPLE_COLOR = 0x6A1B9A
#: glyph of a motion that exists only to first order: grey and half transparent (it pulses in its clip)
INSTANTANEOUS_COLOR, INSTANTANEOUS_OPACITY = 0x9E9E9E, 0.45
#: distance [L] from the platform origin to the common start of the translation arrows (and of the couples)
FREE_VECTOR_OFFSET = 0.3
#: smallest distance [L] from that start to any motion's axis
AXIS_CLEARANCE = 0.12


@dataclass(frozen=True)
class Glyph:
    """A coloured triangle mesh in world coordinates [m], and the world point its label goes at."""

    name: str
    vertices: Array
    faces: Array
    color: int
    anchor: Array


def _frame(axis: Array) -> tuple[Array, Array]:
    """Two unit vectors completing ``axis`` to an orthonormal basis."""
    a = axis / np.linalg.norm(axis)
    helper = np.array([1.0, 0, 0]) if abs(a[0]) < 0.9 else np.array([0, 1.0, 0])
    u = np.cross(a, helper)
    u /= np.linalg.norm(u)
    return u, np.cross(a, u)


def tube(points: ArrayLike, radius: float, sides: int = 12) -> tuple[Array, Array]:
    """A tube of ``radius`` around the polyline ``points`` (k, 3), k >= 2."""
    pts = np.asarray(points, float)
    verts, faces = [], []
    for i, p in enumerate(pts):
        t = pts[min(i + 1, len(pts) - 1)] - pts[max(i - 1, 0)]
        u, v = _frame(t)
        ang = np.linspace(0, 2 * np.pi, sides, endpoint=False)
        verts.append(p + radius * (np.cos(ang)[:, None] * u + np.sin(ang)[:, None] * v))
    for i in range(len(pts) - 1):
        for k in range(sides):
            a, b = i * sides + k, i * sides + (k + 1) % sides
            c, d = a + sides, b + sides
            faces += [(a, b, d), (a, d, c)]
    return np.vstack(verts), np.array(faces)


def cone(base: Array, tip: Array, radius: float, sides: int = 16) -> tuple[Array, Array]:
    """A closed cone from a disc of ``radius`` at ``base`` to ``tip``."""
    base, tip = np.asarray(base, float), np.asarray(tip, float)
    u, v = _frame(tip - base)
    ang = np.linspace(0, 2 * np.pi, sides, endpoint=False)
    rim = base + radius * (np.cos(ang)[:, None] * u + np.sin(ang)[:, None] * v)
    verts = np.vstack([rim, tip, base])
    faces = [(k, (k + 1) % sides, sides) for k in range(sides)] + [
        ((k + 1) % sides, k, sides + 1) for k in range(sides)
    ]
    return verts, np.array(faces)


def merge(*parts: tuple[Array, Array]) -> tuple[Array, Array]:
    """Concatenate meshes."""
    verts, faces, offset = [], [], 0
    for v, f in parts:
        verts.append(v)
        faces.append(f + offset)
        offset += len(v)
    return np.vstack(verts), np.vstack(faces)


def arrow(start: Array, end: Array, radius: float, heads: int = 1) -> tuple[Array, Array]:
    """Shaft from start to end with ``heads`` stacked cones at the end."""
    start, end = np.asarray(start, float), np.asarray(end, float)
    d = end - start
    n = d / np.linalg.norm(d)
    head = 4.0 * radius
    parts = [tube([start, end - heads * head * n], radius)]
    for k in range(heads):
        base = end - (heads - k) * head * n
        parts.append(cone(base, base + head * n, 2.2 * radius))
    return merge(*parts)


def pitch_color(pitch: float, length: float) -> int:
    """Diverging colour of a pitch [m/rad]: blue (negative), grey (0), red (positive)."""
    s = float(np.tanh(pitch / length))
    grey = np.array([0.6, 0.6, 0.6])
    end = np.array([0.85, 0.1, 0.1]) if s > 0 else np.array([0.1, 0.3, 0.9])
    rgb = (1 - abs(s)) * grey + abs(s) * end
    r, g, b = (int(round(255 * c)) for c in rgb)
    return (r << 16) + (g << 8) + b


def _ring(
    centre: Array, axis: Array, radius: float, tube_r: float, advance: float = 0.0, turns: float = 0.85
) -> tuple[Array, Array]:
    """Arc (or helix with ``advance`` [m] per turn) about ``axis`` with an arrow head at its end."""
    a = axis / np.linalg.norm(axis)
    u, v = _frame(a)
    ang = np.linspace(0, 2 * np.pi * turns, max(24, int(48 * turns)))
    pts = (
        centre
        + radius * (np.cos(ang)[:, None] * u + np.sin(ang)[:, None] * v)
        + (advance * ang / (2 * np.pi))[:, None] * a
    )
    tangent = pts[-1] - pts[-2]
    tangent /= np.linalg.norm(tangent)
    head = 4.0 * tube_r
    return merge(tube(pts, tube_r), cone(pts[-1], pts[-1] + head * tangent, 2.2 * tube_r))


def world_point(point: ArrayLike | None, origin: ArrayLike) -> Array:
    """World point [m] of an axis point given relative to the platform origin: ``origin + point``.

    ``point`` None (a translation or a couple) gives the platform origin itself.
    """
    o = np.asarray(origin, float)
    return o.copy() if point is None else o + np.asarray(point, float)


def _distance_to_line(p: Array, a: Array, d: Array) -> float:
    """Distance [m] from p to the line through a along the unit vector d."""
    r = p - a
    return float(np.linalg.norm(r - (r @ d) * d))


def free_vector_start(motions: tuple[Motion, ...], origin: Array, length: float, side: float = 1.0) -> Array:
    """Where the free vectors' arrows start: ``FREE_VECTOR_OFFSET`` L from the platform origin, off every axis.

    The first of a few fixed directions (``side`` -1 takes the opposite ones, for the couples) whose point
    is at least ``AXIS_CLEARANCE`` L from every rotation and screw axis of ``motions``.
    """
    axes = [(world_point(m.point, origin), np.asarray(m.direction, float)) for m in motions if m.point is not None]
    candidates = [np.array(c, float) for c in ((1, 1, 1), (1, -1, 1), (-1, 1, 1), (1, 1, -1), (1, -1, -1))]
    for c in candidates:
        start = np.asarray(origin, float) + side * FREE_VECTOR_OFFSET * length * c / np.linalg.norm(c)
        if all(_distance_to_line(start, a, d) >= AXIS_CLEARANCE * length for a, d in axes):
            return start
    return np.asarray(origin, float) + side * FREE_VECTOR_OFFSET * length * candidates[0] / np.sqrt(3.0)


def motion_glyph(motion: Motion, origin: Array, length: float, start: Array | None = None) -> Glyph:
    """Glyph of one free motion; ``origin`` (3,) is the platform origin [m] (world).

    Args:
        motion: the motion.
        origin: (3,) the platform origin [m], world coordinates.
        length: the length scale L [m].
        start: (3,) where a translation's arrow starts (default: :func:`free_vector_start` of this motion alone).
    """
    d = np.asarray(motion.direction, float)
    r = 0.02 * length
    if motion.kind is MotionKind.TRANSLATION:
        begin = free_vector_start((motion,), origin, length) if start is None else np.asarray(start, float)
        tip = begin + 0.7 * length * d
        v, f = arrow(begin, tip, r)
        return Glyph(motion.label, v, f, TRANSLATION_COLOR, tip + 0.08 * length * d)
    point = world_point(motion.point, origin)
    end = point + 0.9 * length * d
    axis = tube([point - 0.6 * length * d, end], 0.6 * r)
    if motion.kind is MotionKind.ROTATION:
        v, f = merge(axis, _ring(point + 0.45 * length * d, d, 0.18 * length, r))
        return Glyph(motion.label, v, f, ROTATION_COLOR, end + 0.08 * length * d)
    pitch = float(motion.pitch or 0.0)
    advance = float(np.clip(2 * np.pi * pitch, -0.2 * length, 0.2 * length))
    if abs(advance) < 0.05 * length:
        advance = 0.05 * length * np.sign(pitch or 1.0)
    v, f = merge(axis, _ring(point + 0.3 * length * d, d, 0.18 * length, r, advance=advance, turns=2.0))
    return Glyph(motion.label, v, f, pitch_color(pitch, length), end + 0.08 * length * d)


def constraint_glyph(
    constraint: Constraint, index: int, origin: Array, length: float, start: Array | None = None
) -> Glyph:
    """Glyph of one constraint wrench: a force as a line with an arrow head, a couple as a double-headed arrow.

    Args:
        constraint: the constraint wrench.
        index: its number (0-based); the glyph is named ``<kind> <index + 1>``.
        origin: (3,) the platform origin [m], world coordinates.
        length: the length scale L [m].
        start: (3,) where a couple's arrow starts (default: beside the platform origin, opposite the translations).
    """
    d = np.asarray(constraint.direction, float)
    r = 0.015 * length
    kind = str(getattr(constraint.kind, "value", constraint.kind))
    name = f"{kind} {index + 1}"
    if kind == WrenchKind.COUPLE.value:
        begin = free_vector_start((), origin, length, side=-1.0) if start is None else np.asarray(start, float)
        tip = begin + 0.6 * length * d
        v, f = arrow(begin, tip, r, heads=2)
        return Glyph(name, v, f, COUPLE_COLOR, tip + 0.08 * length * d)
    point = world_point(constraint.point, origin)
    tip = point + 0.6 * length * d
    v, f = arrow(point - 0.6 * length * d, tip, r)
    if kind == WrenchKind.WRENCH.value:
        v, f = merge((v, f), _ring(point, d, 0.15 * length, 0.6 * r))
    return Glyph(name, v, f, FORCE_COLOR, tip + 0.08 * length * d)
