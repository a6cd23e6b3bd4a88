"""The length scale L of a mechanism: its default from the geometry, and the range a declared one may take.

Every rank decision divides lengths by L (twists ``[v / L; w]``, wrenches ``[f L; tau]``, prismatic
rates per L), so L must be a length of the mechanism itself: :func:`characteristic_length` takes
it from the link offsets (a rigid move of the whole mechanism leaves it as it is) and
:func:`check_length_scale` refuses a declared L so far from it that round-off decides.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmob.exceptions import ConfigurationError

#: A declared length scale's range, times the geometry's own (built-ins' answers change at 1/1000 and 10000).
LENGTH_RANGE = (1e-2, 1e2)

#: An offset below this fraction of the largest coordinate it is computed from is round-off, not a length.
ROUND_OFF = 1e-12

#: An offset below this [m] is no length of a machine (a hundredth of an atom): round-off of a file at the origin.
SHORTEST = 1e-12

#: L [m] of a mechanism without any length (every joint and frame at one point, e.g. a spherical one drawn at its centre).
NO_LENGTH = 1.0


def characteristic_length(model: pin.Model, frame_ids: list[int]) -> float:
    """Default L [m]: root mean square of the model's link offsets that are lengths, not round-off.

    The joint placements and the given frames' placements; it scales with the units and does not
    depend on the configuration. Those on the fixed base (parent: the world) are positions, not
    links: they count from their centroid, so that a rigid move of the whole mechanism leaves L as
    it is (a base 3 m up is no 3 m link).

    An offset is zero when it is round-off of the coordinates it comes from: below
    :data:`ROUND_OFF` times the largest of them (the largest offset and the largest base position:
    a spherical mechanism 10 m away whose joint frames all sit at its centre has base offsets of
    1e-15 m from their centroid), or below :data:`SHORTEST` (the same mechanism at the world origin
    has only its file's or the parser's round-off). A mechanism with no offset left has no length
    of its own: L is :data:`NO_LENGTH` (1 m), so closure tolerances and printed points keep a scale.
    """
    joints = [(model.parents[j], model.jointPlacements[j].translation) for j in range(1, model.njoints)]
    frames = [(model.frames[f].parentJoint, model.frames[f].placement.translation) for f in dict.fromkeys(frame_ids)]
    based = np.array([t for parent, t in joints + frames if parent == 0]).reshape(-1, 3)
    links = [t for parent, t in joints + frames if parent != 0] + list(based - based.mean(axis=0) if len(based) else [])
    norms = np.linalg.norm(np.array(links).reshape(-1, 3), axis=1)
    coordinates = np.concatenate([norms, np.linalg.norm(based, axis=1)])
    top = float(coordinates.max()) if coordinates.size else 0.0
    if not np.isfinite(top):
        return NO_LENGTH
    lengths = norms[(norms > ROUND_OFF * top) & (norms > SHORTEST)]
    return float(np.sqrt(np.mean(lengths**2))) if lengths.size else NO_LENGTH


def check_length_scale(length_scale: float | None, own: float) -> float:
    """The length scale [m]: ``length_scale`` if declared (checked), else ``own`` (:func:`characteristic_length`).

    Raises:
        ConfigurationError: not a positive finite number, or outside :data:`LENGTH_RANGE` times ``own``.
    """
    scale = float(length_scale) if length_scale else own
    if not np.isfinite(scale) or scale <= 0:
        raise ConfigurationError(f"length_scale must be a positive number of metres, got {length_scale!r}")
    if not LENGTH_RANGE[0] * own <= scale <= LENGTH_RANGE[1] * own:  # else round-off decides the ranks
        raise ConfigurationError(
            f"length_scale {scale:g} m is outside [{LENGTH_RANGE[0] * own:.3g}, {LENGTH_RANGE[1] * own:.3g}] m "
            f"(1/100 to 100 times the mechanism's own size, {own:.3g} m): ranks would be decided by round-off; "
            "give a length in that range, or none"
        )
    return scale
