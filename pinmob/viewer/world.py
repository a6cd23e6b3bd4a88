"""The world frame drawn in the scene: axes at the world origin and a grid in the plane z = 0.

So that a designer can see where an axis is, the scene shows the world frame
itself (meshcat's own axes and grid would sit at the scene's centre, which
pinmob moves to frame the mechanism): thin lines from the world origin along x
(red), y (green) and z (blue), ``AXIS_LENGTH`` L long, and a grey grid of
squares of a round size (1, 2 or 5 times a power of ten metres, about L / 4)
covering the mechanism in the plane z = 0. Pure numpy: segments as
``(k, 2, 3)`` arrays of world points [m]; :mod:`pinmob.viewer.scene` draws them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from pinmob.screw import Array

#: world axis length, as a fraction of L
AXIS_LENGTH = 0.6
#: colours of the x, y, z axes and of the grid
AXIS_COLORS = (0xD32F2F, 0x388E3C, 0x1976D2)
GRID_COLOR = 0x9E9E9E


@dataclass(frozen=True)
class WorldFrame:
    """The world axes and grid.

    Attributes:
        axes: (3, 2, 3) the x, y and z axis segments [m].
        grid: (k, 2, 3) the grid lines [m], in the plane z = 0.
        spacing: the grid's square size [m].
        anchors: label -> world point [m] where it is written (``x``, ``y``, ``z``, ``world origin``).
    """

    axes: Array
    grid: Array
    spacing: float
    anchors: dict[str, Array]


def round_spacing(size: float) -> float:
    """The largest of 1, 2, 5 times a power of ten not above ``size`` [m] (``size`` > 0)."""
    power = 10.0 ** np.floor(np.log10(size))
    return float(max(m * power for m in (1.0, 2.0, 5.0) if m * power <= size * (1 + 1e-12)))


def world_frame(points: Array, length: float) -> WorldFrame:
    """The world axes, and a grid covering ``points`` (k, 3) [m] projected on z = 0 (with the origin).

    Args:
        points: (k, 3) world points the grid must cover [m].
        length: the mechanism's length scale L [m].
    """
    spacing = round_spacing(length / 4.0)
    xy = np.vstack([np.asarray(points, float)[:, :2], np.zeros((1, 2))])
    lo = np.floor(xy.min(axis=0) / spacing - 1) * spacing
    hi = np.ceil(xy.max(axis=0) / spacing + 1) * spacing
    xs = np.arange(lo[0], hi[0] + 0.5 * spacing, spacing)
    ys = np.arange(lo[1], hi[1] + 0.5 * spacing, spacing)
    lines = [[[x, lo[1], 0.0], [x, hi[1], 0.0]] for x in xs] + [[[lo[0], y, 0.0], [hi[0], y, 0.0]] for y in ys]
    ends = AXIS_LENGTH * length * np.eye(3)
    axes = np.stack([np.zeros((3, 3)), ends], axis=1)
    anchors = {name: 1.12 * end for name, end in zip("xyz", ends)}
    anchors["world origin"] = np.zeros(3)
    return WorldFrame(axes, np.array(lines, float), spacing, anchors)
