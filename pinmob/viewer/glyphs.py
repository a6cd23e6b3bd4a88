"""Glyphs of free motions and constraint wrenches, as triangle meshes in world coordinates.

- translation: an arrow from the platform origin along its direction;
- rotation: its axis as a line through the axis point, and a ring around the
  axis with an arrow head giving the positive sense (right hand);
- screw: its axis and a helix whose advance per turn shows the pitch's sign,
  coloured by the pitch (blue negative, grey zero, red positive, saturating at
  ``|h| = L``);
- force: a line along its line of action with an arrow head;
- couple: a double-headed arrow beside the platform origin (offset sideways by
  ``COUPLE_OFFSET`` L, off the axes of the translation arrows, so that a
  translation arrow along the same direction does not hide it).

Axis points (``Motion.point``, ``Constraint.point``) are relative to the
platform origin (world axes): a glyph's axis passes through the world point
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

from pinmob.analysis.mobility import Constraint, Motion
from pinmob.screw.classify import MotionKind, WrenchKind

Array = np.ndarray

TRANSLATION_COLOR = 0x1565C0
ROTATION_COLOR = 0xE65100
FORCE_COLOR = 0xC62828
COUPLE_COLOR = 0x6A1B9A
#: sideways offset of a couple's arrow from the platform origin, as a fraction of L
COUPLE_OFFSET = 0.15


@dataclass(frozen=True)
class Glyph:
    """A coloured triangle mesh in world coordinates [m]."""

    name: str
    vertices: Array
    faces: Array
    color: int


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


def motion_glyph(motion: Motion, origin: Array, length: float) -> Glyph:
    """Glyph of one free motion; ``origin`` (3,) is the platform origin [m] (world)."""
    d = np.asarray(motion.direction, float)
    r = 0.02 * length
    if motion.kind is MotionKind.TRANSLATION:
        v, f = arrow(origin, origin + 0.7 * length * d, r)
        return Glyph(motion.label, v, f, TRANSLATION_COLOR)
    point = world_point(motion.point, origin)
    axis = tube([point - 0.8 * length * d, point + 0.8 * length * d], 0.6 * r)
    if motion.kind is MotionKind.ROTATION:
        v, f = merge(axis, _ring(point + 0.3 * length * d, d, 0.3 * length, r))
        return Glyph(motion.label, v, f, ROTATION_COLOR)
    pitch = float(motion.pitch or 0.0)
    advance = float(np.clip(2 * np.pi * pitch, -0.25 * length, 0.25 * length))
    if abs(advance) < 0.05 * length:
        advance = 0.05 * length * np.sign(pitch or 1.0)
    v, f = merge(axis, _ring(point - 0.25 * length * d, d, 0.25 * length, r, advance=advance, turns=2.0))
    return Glyph(motion.label, v, f, pitch_color(pitch, length))


def constraint_glyph(constraint: Constraint, index: int, origin: Array, length: float) -> Glyph:
    """Glyph of one constraint wrench: a force as a line with an arrow head, a couple as a double-headed arrow."""
    d = np.asarray(constraint.direction, float)
    r = 0.015 * length
    kind = str(getattr(constraint.kind, "value", constraint.kind))
    name = f"{kind} {index + 1}"
    if kind == WrenchKind.COUPLE.value:
        u, w = _frame(d)
        start = np.asarray(origin, float) + COUPLE_OFFSET * length * (u + w) / np.sqrt(2.0)
        v, f = arrow(start, start + 0.6 * length * d, r, heads=2)
        return Glyph(name, v, f, COUPLE_COLOR)
    point = world_point(constraint.point, origin)
    v, f = arrow(point - 0.6 * length * d, point + 0.6 * length * d, r)
    if kind == WrenchKind.WRENCH.value:
        v, f = merge((v, f), _ring(point, d, 0.15 * length, 0.6 * r))
    return Glyph(name, v, f, FORCE_COLOR)
