"""Free motions and constraint wrenches as results: one canonical screw each, and their text lines."""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from typing import Any

import numpy as np

from pinmob.analysis.configuration import Configuration
from pinmob.frozen import ReadOnlyArrays
from pinmob.screw import Array, MotionKind, ScrewSystem, WrenchKind, axis_label, classify_twists, clean, twist_scaling

#: Two orthonormal bases span the same space when each column of one is the other's within this (dimensionless).
SAME_SPAN = 1e-12

#: Words for the motion kinds in text reports.
KIND_WORDS = {MotionKind.TRANSLATION: "translation", MotionKind.ROTATION: "rotation", MotionKind.SCREW: "screw"}


class View(StrEnum):
    """Where a platform mobility's constraint wrenches come from."""

    CONFIGURATION = "configuration"  # the limbs' wrenches at the configuration itself
    PAPER = "paper"  # the limbs' generic wrenches carried to the configuration (the seed paper's procedure)


class Method(StrEnum):
    """How the platform's constraint space was obtained."""

    LIMB_WISE = "limb-wise"  # stacked limb wrenches (the seed paper's method)
    CLOSURE_JACOBIAN = "closure Jacobian"  # image of the whole closed chain's motions


def vector(a: Array | None) -> list[float] | None:
    """A plain list of floats for JSON (None stays None)."""
    return None if a is None else np.asarray(a, dtype=np.float64).tolist()


def numbers(a: Array, digits: int = 4) -> str:
    """``[ 1,  0.5, ...]`` with ``digits`` significant digits (signed zeros dropped)."""
    return "[" + ", ".join(f"{x: .{digits}g}" for x in np.asarray(a) + 0.0) + "]"


def world_point(point: Array | None, origin: Array, length: float = 1.0) -> Array | None:
    """``origin + point`` [m]: a point given relative to an origin, in world coordinates (None stays None).

    Entries below ``1e-10`` times ``length`` or the origin's largest coordinate [m] are zeroed: round-off
    of the sum (a spherical mechanism's centre 10 m away comes out 1e-15 m off its true coordinates).
    """
    if point is None:
        return None
    origin = np.asarray(origin, float)
    return clean(origin + point, point_scale(length, origin))


def point_scale(length: float, origin: Array) -> float:
    """The length [m] a world point's round-off is relative to: L, or the origin's largest coordinate if larger.

    A coordinate below ``1e-10`` times it is round-off (:func:`pinmob.screw.bases.clean`).
    """
    return max(length, float(np.abs(np.asarray(origin, float)).max(initial=0.0)))


def with_world_point(out: dict[str, Any], point: Array | None, origin: Array | None, length: float) -> dict[str, Any]:
    """``out`` with ``world_point`` (see :func:`world_point`) added when ``origin`` is given."""
    if origin is not None:
        out["world_point"] = vector(world_point(point, origin, length))
    return out


@dataclass(frozen=True)
class Motion(ReadOnlyArrays):
    """One free motion of the platform (SI units, Pinocchio order).

    Attributes:
        kind: T (translation), R (rotation) or H (screw).
        direction: (3,) unit direction (of translation, or of the axis); arrays are read-only.
        point: (3,) axis point closest to the platform origin [m], relative to it (None for T).
        pitch: [m/rad] (None for T, 0 for R).
        twist: (6,) unit twist ``[v; w]`` at the platform origin.
        label: short name such as ``T1 x`` or ``R1 z``.
    """

    kind: MotionKind
    direction: Array
    point: Array | None
    pitch: float | None
    twist: Array
    label: str

    def world_point(self, origin: Array, length: float = 1.0) -> Array | None:
        """The axis point in world coordinates [m], ``origin + point`` (see :func:`world_point`)."""
        return world_point(self.point, origin, length)

    def to_dict(self, origin: Array | None = None, length: float = 1.0) -> dict[str, Any]:
        """``{kind, label, direction, point, pitch}`` (plain JSON); ``world_point`` too when ``origin`` (3,) [m] is given (:func:`with_world_point`)."""
        out = {
            "kind": self.kind.value,
            "label": self.label,
            "direction": vector(self.direction),
            "point": vector(self.point),
            "pitch": self.pitch,
        }
        return with_world_point(out, self.point, origin, length)

    def words(self, origin: Array, length: float = 1.0) -> tuple[str, str, str, str, str]:
        """(label, kind, direction, world axis point [m], pitch [m/rad]) as printed; ``""`` where there is none.

        The one source of a motion's words: :meth:`line` writes them, the notebook's table shows them.

        Args:
            origin: (3,) world position [m] of the origin the axis point is relative to.
            length: the mechanism's length scale L [m] (entries below 1e-10 L, or 1e-10 times the origin's
                largest coordinate, print as 0: :func:`world_point`).
        """
        point = self.world_point(origin, length)
        return (
            self.label,
            KIND_WORDS[self.kind],
            numbers(self.direction),
            "" if point is None else numbers(point),
            f"{self.pitch:.4g}" if self.kind is MotionKind.SCREW else "",
        )

    def line(self, origin: Array, length: float = 1.0) -> str:
        """``  R1 z     rotation    direction [...], axis through [...] m (world)`` (+ ``pitch ... m/rad``): :meth:`words`."""
        label, kind, direction, point, pitch = self.words(origin, length)
        text = f"  {label:<8} {kind:<11} direction {direction}"
        text += f", axis through {point} m (world)" if point else ""
        return text + (f", pitch {pitch} m/rad" if pitch else "")


@dataclass(frozen=True)
class Constraint(ReadOnlyArrays):
    """One canonical constraint wrench: a couple, a force (pitch 0) or a wrench (SI units, Pinocchio order).

    Attributes:
        kind: couple, force or wrench.
        direction: (3,) unit direction (of the couple's moment, or of the force).
        point: (3,) point of the force's line closest to the platform origin [m] (None for a couple).
        pitch: [m/rad] (None for a couple, 0 for a force).
        wrench: (6,) unit wrench ``[f; tau]`` at the platform origin.
    """

    kind: WrenchKind
    direction: Array
    point: Array | None
    pitch: float | None
    wrench: Array

    def world_point(self, origin: Array, length: float = 1.0) -> Array | None:
        """The point of the line of action in world coordinates [m], ``origin + point`` (see :func:`world_point`)."""
        return world_point(self.point, origin, length)

    def to_dict(self, origin: Array | None = None, length: float = 1.0) -> dict[str, Any]:
        """``{kind, direction, point, pitch, wrench}`` (plain JSON); ``world_point`` too when ``origin`` (3,) [m] is given (:func:`with_world_point`)."""
        out = {
            "kind": self.kind.value,
            "direction": vector(self.direction),
            "point": vector(self.point),
            "pitch": self.pitch,
            "wrench": vector(self.wrench),
        }
        return with_world_point(out, self.point, origin, length)

    def line(self, origin: Array, length: float = 1.0) -> str:
        """``  force   direction [...], line through [...] m (world)`` (+ ``pitch ... m/rad``); a couple has no line.

        Args:
            origin: (3,) world position [m] of the origin the point is relative to.
            length: the mechanism's length scale L [m] (entries below 1e-10 L, or 1e-10 times the origin's
                largest coordinate, print as 0: :func:`world_point`).
        """
        text = f"  {self.kind.value:<7} direction {numbers(self.direction)}"
        point = self.world_point(origin, length)
        if point is not None:
            text += f", line through {numbers(point)} m (world)"
        if self.kind is WrenchKind.WRENCH:
            text += f", pitch {self.pitch:.4g} m/rad"
        return text


def motions_of(system: ScrewSystem) -> tuple[Motion, ...]:
    """The motions of a classified twist system, labelled ``T1 x``, ``R1 z``, ``H1 [..]`` in order.

    Their arrays are the screws' own, made read-only by :class:`Motion` (results are frozen for real).
    """
    out = []
    counters = dict.fromkeys(MotionKind, 0)
    for s in system.all:
        kind = MotionKind(s.kind)
        counters[kind] += 1
        label = f"{kind.value}{counters[kind]} {axis_label(s.direction)}"
        out.append(Motion(kind, s.direction, s.point, s.pitch, s.vector, label))
    return tuple(out)


def classified_motions(
    conf: Configuration, span: Array, rtol: float, *, keep: bool = False
) -> tuple[ScrewSystem, tuple[Motion, ...]]:
    """The classified twist system of ``span`` and its motions, shared by the analyses of one configuration.

    ``span`` (6, k) is an orthonormal basis of dimensionless twists ``[v / L; w]``. The platform mobility
    and the platform frame's motion on the closed chain classify the same space: a classification made with
    ``keep`` (the platform mobility's, :func:`~pinmob.screw.classify.classify_twists` and
    :func:`motions_of`) is kept on the configuration, per tolerance, and given to a later span whose columns
    it spans to :data:`SAME_SPAN` (``|S - Q Q^T S| <= SAME_SPAN``, Q the kept basis): the classification
    depends on the space only, not on its basis (up to round-off dust below 1e-10). Other spans are
    classified and not kept, so a frame's answer does not depend on which other frames were asked for.
    """
    kept: list[tuple[Array, ScrewSystem, tuple[Motion, ...]]] = conf.memo(("classified twists", rtol), list)
    for basis, system, motions in kept:
        if basis.shape == span.shape and np.all(np.abs(span - basis @ (basis.T @ span)) <= SAME_SPAN):
            return system, motions
    length = conf.mechanism.length_scale
    system = classify_twists(span / twist_scaling(length)[:, None], length, rtol)
    motions = motions_of(system)
    if keep:
        frozen = np.array(span, dtype=np.float64)
        frozen.flags.writeable = False
        kept.append((frozen, system, motions))
    return system, motions


def constraints_of(system: ScrewSystem) -> tuple[Constraint, ...]:
    """The constraints of a classified wrench system (their arrays made read-only by :class:`Constraint`)."""
    return tuple(Constraint(WrenchKind(s.kind), s.direction, s.point, s.pitch, s.vector) for s in system.all)


def columns(vectors: list[Array] | tuple[Array, ...], rows: int = 6) -> Array:
    """The vectors (rows,) as the columns of a (rows, k) array (read-only; (rows, 0) when there are none)."""
    out = np.array(vectors).T.copy() if len(vectors) else np.zeros((rows, 0))
    out.flags.writeable = False
    return out
