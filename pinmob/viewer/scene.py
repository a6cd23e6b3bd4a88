"""The meshcat scene of a mobility analysis, shown by :mod:`pinmob.viewer`, written by :mod:`pinmob.viewer.html`.

:func:`pinmob.viewer.prepared.prepare` does everything that can fail before
meshcat is touched (the closed configuration, its analysis, the followed
motions and, by default, each motion's finite-mobility verdict,
:mod:`pinmob.analysis.finite.finite_mobility`); :func:`build` sends
the scene (the mechanism once, one animation clip per free motion, glyphs,
wrenches, the world axes and grid, camera, lights, and pinmob's panel with the
motions' clips: :mod:`pinmob.viewer.panel`) to a live or recording meshcat
``Visualizer`` and returns a :class:`Scene`. See :mod:`pinmob.viewer` for the
scene's meshcat paths.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.analysis import Mobility, MotionPath
from pinmob.exceptions import ViewerError
from pinmob.viewer.commands import SetAnimation
from pinmob.viewer.glyphs import (
    INSTANTANEOUS_COLOR,
    INSTANTANEOUS_OPACITY,
    Glyph,
    arrow,
    constraint_glyph,
    free_vector_start,
    motion_glyph,
)
from pinmob.viewer.panel import PanelCommand, panel_document
from pinmob.viewer.prepared import Prepared
from pinmob.viewer.skeleton import visual_geometry
from pinmob.viewer.workspace import Workspace, send_workspace
from pinmob.viewer.world import AXIS_COLORS, GRID_COLOR, world_frame

Array = np.ndarray

ROOT = "pinmob"
FPS = 24
#: the camera looks at the mechanism from this direction (world, unit): 30 deg azimuth, 35 deg elevation
VIEW_DIRECTION = np.array([np.cos(0.61) * np.cos(0.52), np.cos(0.61) * np.sin(0.52), np.sin(0.61)])
CAMERA_FOV = 75.0  # meshcat's default camera, degrees (vertical)
#: meshcat's default point lights: position [m] (scene frame) and reach [m], made for a scene about 1 m across
POINT_LIGHTS = {"PointLightNegativeX": (1.5, 1.5, 2.0), "PointLightPositiveX": (-1.5, -1.5, 2.0)}
LIGHT_REACH = 10.0
#: glyphs are drawn after everything else (three.js renderOrder)
GLYPH_RENDER_ORDER = 10
#: how much the glyph of a motion that exists only to first order (grey, half transparent) pulses in its clip
PULSE = 0.35


@dataclass
class Scene:
    """What was put in the viewer.

    Attributes:
        clips: clip names, one per free motion, in the order of ``Mobility.motions``.
        visible: the clip shown (and playing) on opening, or None without motion.
        notes: where a motion could not be followed the whole amplitude, and why.
        generated_geometry: True when the mechanism is drawn as a generated stick figure.
        mobility: the analysis shown.
        paths: the followed motions, by clip name, each with its finite verdict (``MotionPath.finite``,
            ``MotionPath.verdict``) when it was analysed.
        center, distance: where the camera looks [m] and from how far [m].
        url: the live page (``show``) or None.
        zmq_url: the server's command URL (``show``) or None.
        html: the written file (``export_html``) or None.
        server: the server pinmob started (``show`` without ``zmq_url``); ``server.stop()`` ends it.
        shown_frame: for a mechanism without a platform, which output frame is shown and why ("" otherwise).
    """

    clips: tuple[str, ...]
    visible: str | None
    notes: tuple[str, ...]
    generated_geometry: bool
    mobility: Mobility
    paths: dict[str, MotionPath] = field(repr=False)
    center: Array = field(repr=False, default_factory=lambda: np.zeros(3))
    distance: float = 1.0
    url: str | None = None
    zmq_url: str | None = None
    html: Path | None = None
    server: Any = field(default=None, repr=False)
    panel: dict[str, Any] = field(default_factory=dict, repr=False)
    panel_shown: bool = True
    shown_frame: str = ""

    @property
    def verdicts(self) -> dict[str, str]:
        """Each clip's finite-mobility verdict in words (``finite``, ``blocked at order 2 (shaky)``, ...)."""
        return {label: self.paths[label].verdict for label in self.clips}


# --------------------------------------------------------------------------- meshcat plumbing


def require_meshcat() -> Any:
    """Import meshcat (and what the scene uses of it), or a :class:`ViewerError` saying how to install it."""
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", DeprecationWarning)  # meshcat imports zmq.eventloop.ioloop
            import meshcat
            import meshcat.animation  # noqa: F401
            import meshcat.geometry  # noqa: F401
            import meshcat.visualizer  # noqa: F401
            import umsgpack  # noqa: F401
    except ImportError as exc:
        raise ViewerError(
            f"the viewer needs meshcat, which cannot be imported ({exc}); install it with: pip install meshcat"
        ) from None
    return meshcat


def _mesh(glyph: Glyph, order: int = GLYPH_RENDER_ORDER, opacity: float = 1.0) -> Any:
    """A glyph's meshcat object, drawn after (``renderOrder`` ``order``) and over (no depth test) the mechanism."""
    import meshcat.geometry as mg

    class GlyphMesh(mg.Mesh):
        def lower(self) -> dict[str, Any]:
            data: dict[str, Any] = super().lower()
            data["object"]["renderOrder"] = order
            return data

    material = mg.MeshPhongMaterial(color=glyph.color, depthTest=False, transparent=True, opacity=opacity)
    return GlyphMesh(mg.TriangularMeshGeometry(glyph.vertices, glyph.faces), material)


def _lines(segments: Array, color: int) -> Any:
    """Line segments (k, 2, 3) [m] of one colour, as a meshcat object."""
    import meshcat.geometry as mg

    points = np.asarray(segments, float).reshape(-1, 3).T
    return mg.LineSegments(mg.PointsGeometry(points), mg.LineBasicMaterial(color=color))


# --------------------------------------------------------------------------- scene


def _frame_camera(vis: Any, points: Array) -> tuple[Array, float]:
    """Frame ``points`` (k, 3): shift the scene so that their centre is at the origin, then back the camera off.

    meshcat's orbit controls always look at the world origin, so the scene
    (everything under ``/pinmob``) is translated by ``-center`` rather than the
    camera moved; the camera stands far enough away to see every point.
    """
    lo, hi = points.min(axis=0), points.max(axis=0)
    center = 0.5 * (lo + hi)
    radius = max(float(np.linalg.norm(points - center, axis=1).max()), 1e-9)
    distance = 1.05 * radius / np.sin(np.radians(CAMERA_FOV) / 2)
    offset = distance * VIEW_DIRECTION
    vis[ROOT].set_transform(pin.SE3(np.eye(3), -center).homogeneous)
    vis["/Cameras/default"].set_transform(np.eye(4))
    camera = vis["/Cameras/default/rotated/<object>"]
    camera.set_property("near", distance / 100.0)
    camera.set_property("far", distance * 100.0)
    camera.set_property("position", [float(offset[0]), float(offset[2]), float(-offset[1])])  # y-up camera frame
    return center, distance


def _place_lights(vis: Any, distance: float) -> None:
    """Move meshcat's point lights with the scene's size (the scene is centred, :func:`_frame_camera`).

    The defaults suit a scene about 1 m across, seen from about 1.5 m.
    """
    scale = distance / 1.5
    for name, position in POINT_LIGHTS.items():
        light = vis[f"/Lights/{name}/<object>"]
        light.set_property("position", [float(c) * scale for c in position])
        light.set_property("distance", LIGHT_REACH * scale)


def build(vis: Any, prep: Prepared, *, workspace: Workspace | None = None) -> Scene:
    """Send the whole scene of ``prep`` to ``vis`` (a live or recording meshcat Visualizer); the panel last.

    ``workspace``: a scan's reachable set, drawn beside the mechanism (:mod:`pinmob.viewer.workspace`).
    """
    from meshcat.animation import Animation, AnimationClip, js_position, js_quaternion
    from pinocchio.visualize import MeshcatVisualizer

    mech, q, mob, paths, wrenches = prep.mechanism, prep.q, prep.mobility, prep.paths, prep.options.wrenches
    labels = [m.label for m in mob.motions]
    visible = prep.motion or (labels[0] if labels else None)
    geometry, generated = visual_geometry(mech, q)
    model = mech.model
    data, gdata = pin.Data(model), pin.GeometryData(geometry)

    vis[ROOT].delete()
    vis["/Background"].set_property("top_color", [0.97, 0.97, 0.98])
    vis["/Background"].set_property("bottom_color", [0.78, 0.8, 0.84])
    vis["/Grid"].set_property("visible", False)  # meshcat's own sit at the scene's centre, not at the world origin
    vis["/Axes"].set_property("visible", False)
    points: list[Array] = []
    # the mechanism once (each mesh defined once); each clip animates its geometry nodes' transforms
    viz = MeshcatVisualizer(model, None, geometry)
    viz.initViewer(viewer=vis)
    viz.loadViewerModel(rootNodeName=f"{ROOT}/mechanism")
    viz.display(q)
    nodes = [vis[viz.getViewerNodeName(obj, pin.GeometryType.VISUAL)].path for obj in geometry.geometryObjects]
    clips: dict[str, list[dict[str, Any]]] = {}
    clip_labels: list[str | None] = [*labels] or [None]
    for label in clip_labels:
        animation = Animation(default_framerate=FPS)
        still = label is not None and paths[label].finite is False  # only instantaneous: its glyph pulses
        frames = ([q] * FPS if still else paths[label].frames()) if label is not None else [q]
        for k, qk in enumerate(frames):
            pin.updateGeometryPlacements(model, data, geometry, gdata, qk)
            for i, node in enumerate(nodes):
                matrix = gdata.oMg[i].homogeneous
                points.append(matrix[:3, 3].copy())
                if label is None:
                    continue
                clip = animation.clips.setdefault(node, AnimationClip(fps=FPS, name=label))
                clip.set_property(k, "position", "vector3", [float(x) for x in js_position(matrix)])
                clip.set_property(k, "quaternion", "quaternion", [float(x) for x in js_quaternion(matrix)])
        if still:  # the glyph's node is placed at the glyph's centre (below), so it pulses in place
            pulse = animation.clips.setdefault(vis[f"{ROOT}/glyphs/{label}"].path, AnimationClip(fps=FPS, name=label))
            for k in range(FPS):
                size = 1.0 + PULSE * np.sin(2 * np.pi * k / (FPS - 1))
                pulse.set_property(k, "scale", "vector3", [size] * 3)
        if label is not None:
            clips[label] = animation.lower()

    origin, length = mob.platform_origin, mech.length_scale
    drawn: list[tuple[str, list[str], Glyph]] = []
    start = free_vector_start(mob.motions, origin, length)
    for m in mob.motions:
        glyph = motion_glyph(m, origin, length, start)
        node = vis[f"{ROOT}/glyphs/{glyph.name}"]
        if paths[m.label].finite is False:  # only instantaneous: grey, half transparent, centred on its node
            centre = glyph.vertices.mean(axis=0)
            shown = replace(glyph, vertices=glyph.vertices - centre, color=INSTANTANEOUS_COLOR)
            node.set_object(_mesh(shown, opacity=INSTANTANEOUS_OPACITY))
            node.set_transform(pin.SE3(np.eye(3), centre).homogeneous)
            glyph = replace(glyph, color=INSTANTANEOUS_COLOR)
        else:
            node.set_object(_mesh(glyph))
        drawn.append(("motion", ["meshcat", ROOT, "glyphs", glyph.name], glyph))
        points.extend(glyph.vertices)
    couples = free_vector_start(mob.motions, origin, length, side=-1.0)
    for i, c in enumerate(mob.constraints):
        glyph = constraint_glyph(c, i, origin, length, couples)
        vis[f"{ROOT}/wrenches/{glyph.name}"].set_object(_mesh(glyph))
        drawn.append(("wrench", ["meshcat", ROOT, "wrenches", glyph.name], glyph))
        if wrenches:
            points.extend(glyph.vertices)
    vis[f"{ROOT}/wrenches"].set_property("visible", bool(wrenches))
    if workspace is not None:
        points.extend(p for cloud in send_workspace(vis, workspace, ROOT) for p in cloud)
    world = world_frame(np.array(points), length)
    for name, axis, color in zip("xyz", world.axes, AXIS_COLORS):
        shaft = arrow(axis[0], axis[1], 0.008 * length)
        world_axis = Glyph(name, *shaft, color, axis[1])  # over the mechanism, under the glyphs
        vis[f"{ROOT}/world/axis {name}"].set_object(_mesh(world_axis, GLYPH_RENDER_ORDER // 2, opacity=0.85))
    vis[f"{ROOT}/world/grid"].set_object(_lines(world.grid, GRID_COLOR))
    points.append(np.zeros(3))  # the world origin, labelled, stays in view
    center, distance = _frame_camera(vis, np.array(points))
    _place_lights(vis, distance)
    # always replace the animation: a rigid scene on a reused server must not keep the previous scene's clip
    vis.window.send(SetAnimation(clips[visible] if visible is not None else []))
    document = panel_document(
        mech.name, mob, paths, singularity=prep.singularity, chain=prep.chain, glyphs=drawn, world=world,
        paths_of={"world": ["meshcat", ROOT, "world"], "wrenches": ["meshcat", ROOT, "wrenches"]},
        clips=clips, visible=visible, wrenches=wrenches, generated=generated,
        verdicts={label: path.verdict for label, path in paths.items() if path.verdict},
        branch_point=prep.branch_point, output_frame=prep.output_frame, minimal=prep.minimal,
    )  # fmt: skip
    if workspace is not None:
        document["workspace"] = workspace.legend()
    panel_shown = send_panel(vis, PanelCommand(document))
    notes = tuple(n for p in paths.values() for n in p.notes)
    return Scene(
        tuple(labels), visible, notes, generated, mob, paths, center, distance, panel=document,
        panel_shown=panel_shown, shown_frame=prep.note,
    )  # fmt: skip


def send_panel(vis: Any, command: PanelCommand) -> bool:
    """Send the panel; False when a live server refuses it (a meshcat server that is not pinmob's)."""
    socket = getattr(vis.window, "zmq_socket", None)
    if socket is None:  # recording for an HTML file
        vis.window.send(command)
        return True
    import umsgpack

    socket.send_multipart([command.lower()["type"].encode(), b"", umsgpack.packb(command.lower())])
    return bool(socket.recv() == b"ok")
