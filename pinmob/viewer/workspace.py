"""A scan's reachable set in the 3D view: the assembled samples as a point cloud, coloured by distance to singularity.

:func:`workspace_cloud` turns the rows of a platform scan (:func:`pinmob.scan.scan`: a grid over one to
three coordinates, or a path) into a :class:`Workspace`: each assembled sample is a point at the platform
origin's world position (the rows' ``x``, ``y``, ``z`` [m]), coloured by its ``distance`` to singularity
(``sigma_r / sigma_1``, the smallest relative singular value of the rank tests, dimensionless: 0 singular,
1 best conditioned; docs/singularities.md) on a log scale from the smallest distance above ``rtol`` to the
largest of the samples (:func:`distance_colors`). Singular samples (distance at most ``rtol``: they take the
scale's first colour) and refined singular points are marked by larger points of their own colour, drawn
last; the clouds are drawn over the mechanism. Samples not assembled are not drawn.

:func:`send_workspace` puts it in a meshcat scene (``/pinmob/workspace/samples``, ``singular``,
``refined``, ``chosen``: meshcat point clouds with per-point colours), and :meth:`Workspace.legend` is the
panel's workspace section (:mod:`pinmob.viewer.panel`, ``static/panel.js``): the colour scale with its
figures, the marks, the grid's coordinates with their units. :func:`sample_configuration` is the closed
configuration of one row, to draw the mechanism at that sample.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from pinmob.analysis import Configuration
from pinmob.assembly import POSE_COORDS, assemble_pose, pose_from_vector
from pinmob.exceptions import ConfigurationError
from pinmob.model import CLOSURE_TOL, Mechanism, q_from_values
from pinmob.scan import value_joints
from pinmob.screw import RTOL, Array
from pinmob.viewer.panel import hex_color

#: the colour scale of the distance, from small (singular side) to large: viridis (as the 2D maps) at nine stops
SCALE = (0x440154, 0x472D7B, 0x3B528B, 0x2C728E, 0x21918C, 0x28AE80, 0x5EC962, 0xADDC30, 0xFDE725)
#: singular samples (distance at most rtol), refined singular points, the sample the mechanism is drawn at
SINGULAR_COLOR = 0xD62728
REFINED_COLOR = 0xE040FB
CHOSEN_COLOR = 0x111111
#: the points' size as a fraction of the samples' spacing; the marks' size as a multiple of the points'
POINT_SIZE = 0.5
MARK_SIZE = 1.5
#: the clouds are drawn after the mechanism, over it (three.js renderOrder; the glyphs' is 10)
RENDER_ORDER = 6
#: what the colour says (the legend's words)
DISTANCE_WORDS = (
    "distance to singularity sigma_r / sigma_1: the smallest relative singular value of the rank tests "
    "(dimensionless; 0 = singular, 1 = best conditioned), log scale"
)


def distance_colors(distance: Array, lo: float, hi: float) -> Array:
    """(k, 3) RGB in [0, 1] of distances: :data:`SCALE` interpolated in ``log10(distance)`` from ``lo`` to ``hi``.

    A distance at or below ``lo`` takes the first colour, at or above ``hi`` the last; ``lo == hi``: the last.
    """
    d = np.clip(np.asarray(distance, float), lo, hi)
    span = np.log10(hi) - np.log10(lo)
    t = (np.log10(d) - np.log10(lo)) / span if span > 0 else np.ones_like(d)
    stops = np.array([[(c >> 16) & 255, (c >> 8) & 255, c & 255] for c in SCALE], float) / 255.0
    where = np.linspace(0.0, 1.0, len(SCALE))
    return np.column_stack([np.interp(t, where, stops[:, k]) for k in range(3)])


@dataclass
class Workspace:
    """The points of a scan's reachable set and what the legend says of them.

    Attributes:
        positions: (k, 3) platform origins of the assembled samples [m] (world).
        distances: (k,) their distance to singularity; ``colors`` (k, 3) RGB in [0, 1] from :func:`distance_colors`.
        indices: (k,) their row indices.
        singular, refined: (m, 3) positions of the singular samples and of the refined singular points [m].
        chosen: (3,) position of the sample the mechanism is drawn at, or None.
        lo, hi: the colour scale's ends: the smallest distance above ``rtol`` of the samples, and the largest.
        spacing: the samples' spacing [m] (the points' size follows it).
        total: the rows that are samples (assembled or not, refined points left out).
        title: what was scanned; ``axes``: each gridded coordinate with its unit and range, in words.
    """

    positions: Array
    distances: Array
    colors: Array
    indices: Array
    singular: Array
    refined: Array
    chosen: Array | None
    lo: float
    hi: float
    spacing: float
    total: int
    rtol: float = RTOL
    title: str = ""
    axes: tuple[str, ...] = field(default_factory=tuple)

    def legend(self) -> dict[str, Any]:
        """The panel's workspace section (plain JSON): counts, the colour scale and its ends, the marks."""
        marks = [
            {"color": hex_color(SINGULAR_COLOR), "text": f"singular sample (distance <= rtol = {self.rtol:g}): "
             f"{len(self.singular)}"},
            {"color": hex_color(REFINED_COLOR), "text": f"refined singular point: {len(self.refined)}"},
        ]  # fmt: skip
        if self.chosen is not None:
            marks.append({"color": hex_color(CHOSEN_COLOR), "text": "the sample the mechanism is drawn at"})
        return {
            "title": self.title,
            "count": len(self.positions),
            "total": self.total,
            "points": "each point: the platform origin x, y, z [m] (world) of an assembled sample",
            "axes": list(self.axes),
            "scale": {"colors": [hex_color(c) for c in SCALE], "lo": self.lo, "hi": self.hi, "words": DISTANCE_WORDS},
            "marks": marks,
            "path": ["meshcat", "pinmob", "workspace"],
        }


def _spacing(positions: Array) -> float:
    """The smallest positive step between the samples' distinct values along x, y or z [m] (1 without any)."""
    steps = []
    for k in range(3):
        values = np.unique(np.round(positions[:, k], 12))
        gaps = np.diff(values)
        gaps = gaps[gaps > 1e-9 * max(1.0, float(np.abs(values).max(initial=0.0)))]
        if gaps.size:
            steps.append(float(gaps.min()))
    return min(steps) if steps else 1.0


def workspace_cloud(
    rows: Iterable[Mapping[str, Any]],
    rtol: float = RTOL,
    chosen: int | None = None,
    title: str = "",
    axes: tuple[str, ...] = (),
) -> Workspace:
    """The :class:`Workspace` of a platform scan's rows (``chosen``: the row index the mechanism is drawn at)."""
    rows = list(rows)
    if rows and "x" not in rows[0]:
        raise ConfigurationError("the 3D workspace draws the platform's positions; this scan has no platform")
    samples = [r for r in rows if not r["refined"]]
    reach = [r for r in samples if r["reachable"]]
    position = np.array([[float(r[c]) for c in POSE_COORDS[:3]] for r in reach], float).reshape(-1, 3)
    distances = np.array([float(r["distance"]) for r in reach], float)
    regular = distances[distances > rtol]  # the singular samples are marked, and take the scale's first colour
    lo = float(regular.min()) if regular.size else rtol
    hi = max(float(distances.max()), lo) if distances.size else 1.0
    marks = [r for r in reach if r["singularity"] != "none"]
    refined = [r for r in rows if r["refined"] and r["reachable"]]
    at = [r for r in reach if int(r["index"]) == chosen] if chosen is not None else []
    return Workspace(
        positions=position,
        distances=distances,
        colors=distance_colors(distances, lo, hi),
        indices=np.array([int(r["index"]) for r in reach], int),
        singular=np.array([[float(r[c]) for c in POSE_COORDS[:3]] for r in marks], float).reshape(-1, 3),
        refined=np.array([[float(r[c]) for c in POSE_COORDS[:3]] for r in refined], float).reshape(-1, 3),
        chosen=np.array([float(at[0][c]) for c in POSE_COORDS[:3]]) if at else None,
        lo=lo,
        hi=hi,
        spacing=_spacing(position),
        total=len(samples),
        rtol=rtol,
        title=title,
        axes=axes,
    )


def sample_configuration(
    mech: Mechanism, rows: Iterable[Mapping[str, Any]], index: int, seed: Array, closure_tol: float = CLOSURE_TOL
) -> Configuration:
    """The configuration of the assembled sample ``index`` (its row's joint values, else its pose).

    It is closed within ``closure_tol`` (the scan's). The rows hold every one-degree joint's value (``q_<name>``); a mechanism with other joints is assembled at
    the row's platform pose from ``seed`` set to those values.

    Raises:
        ConfigurationError: no row of that index, or one not assembled (the message lists the valid range).
    """
    samples = {int(r["index"]): r for r in rows if not r["refined"]}
    row = samples.get(index)
    if row is None or not row["reachable"]:
        what = "is not an index of the scan" if row is None else "was not assembled"
        good = sorted(k for k, r in samples.items() if r["reachable"])
        valid = (
            f"the index of an assembled sample ({len(good)} of them, from {good[0]} to {good[-1]})"
            if good
            else "none (no sample was assembled)"
        )
        raise ConfigurationError(f"`index={index}`: that sample {what}; valid: {valid}").naming("index")
    joints = value_joints(mech)
    q = q_from_values(mech.model, {n: float(row[f"q_{n}"]) for n in joints}, seed, mech.name)
    if sum(mech.model.joints[mech.model.getJointId(n)].nq for n in joints) != mech.model.nq:
        q = assemble_pose(mech, pose_from_vector(np.array([float(row[c]) for c in POSE_COORDS])), q, closure_tol)
    return Configuration(mech, q, closure_tol=closure_tol, name=f"sample #{index}")


def send_workspace(vis: Any, ws: Workspace, root: str) -> list[Array]:
    """Draw ``ws`` under ``<root>/workspace`` of a meshcat Visualizer; returns the points drawn (to frame them) [m]."""
    import meshcat.geometry as mg

    size = POINT_SIZE * ws.spacing
    node = vis[f"{root}/workspace"]
    node.delete()

    class OverPoints(mg.Points):  # drawn over the mechanism (whose platform would hide the cloud), marks last
        def __init__(self, points: Array, colors: Array, scale: float, order: int):
            super().__init__(mg.PointsGeometry(points.T, colors.T), mg.PointsMaterial(size=scale))
            self.order = order

        def lower(self) -> dict[str, Any]:
            data: dict[str, Any] = super().lower()
            data["object"]["renderOrder"] = self.order
            data["materials"][0].update(depthTest=False, transparent=True)  # after the (transparent) platform
            return data

    def cloud(name: str, points: Array, colors: Array, scale: float) -> None:
        if len(points):
            node[name].set_object(OverPoints(points, colors, scale, RENDER_ORDER + (name != "samples")))

    def plain(color: int, k: int) -> Array:
        return np.tile(np.array([(color >> 16) & 255, (color >> 8) & 255, color & 255], float) / 255.0, (k, 1))

    cloud("samples", ws.positions, ws.colors, size)
    cloud("singular", ws.singular, plain(SINGULAR_COLOR, len(ws.singular)), MARK_SIZE * size)
    cloud("refined", ws.refined, plain(REFINED_COLOR, len(ws.refined)), MARK_SIZE * size)
    if ws.chosen is not None:
        cloud("chosen", ws.chosen[None, :], plain(CHOSEN_COLOR, 1), 2.2 * MARK_SIZE * size)
    return [p for p in (ws.positions, ws.singular, ws.refined) if len(p)]
