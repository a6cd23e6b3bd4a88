"""The meshcat scene of a mobility analysis, shown by :mod:`pinmob.viewer`, written by :mod:`pinmob.html_export`.

:func:`prepare` does everything that can fail before meshcat is touched (the
closed configuration, its mobility, the followed motions); :func:`build` sends
the scene (mechanism copies animated per free motion, glyphs, wrenches, camera,
motion menu) to a live or recording meshcat ``Visualizer`` and returns a
:class:`Scene`. See :mod:`pinmob.viewer` for the scene's meshcat paths.
"""

from __future__ import annotations

import json
import warnings
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from .animation import MotionPath, follow_motion
from .exceptions import ConfigurationError, ViewerError, choices
from .glyphs import Glyph, constraint_glyph, motion_glyph
from .mechanism import Mechanism
from .mobility import Mobility, analyze
from .skeleton import visual_geometry

Array = np.ndarray

ROOT = "pinmob"
FPS = 24
#: the camera looks at the mechanism from this direction (world, unit): 30 deg azimuth, 35 deg elevation
VIEW_DIRECTION = np.array([np.cos(0.61) * np.cos(0.52), np.cos(0.61) * np.sin(0.52), np.sin(0.61)])
CAMERA_FOV = 75.0  # meshcat's default camera, degrees (vertical)


@dataclass
class Scene:
    """What was put in the viewer.

    Attributes:
        clips: clip names, one per free motion, in the order of ``Mobility.motions``.
        visible: the clip shown (and playing) on opening, or None without motion.
        notes: where a motion could not be followed the whole amplitude, and why.
        generated_geometry: True when the mechanism is drawn as a generated stick figure.
        mobility: the analysis shown.
        paths: the followed motions, by clip name.
        center, distance: where the camera looks [m] and from how far [m].
        url: the live page (``show``) or None.
        zmq_url: the server's command URL (``show``) or None.
        html: the written file (``export_html``) or None.
        server: the server pinmob started (``show`` without ``zmq_url``); ``server.stop()`` ends it.
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


class _SetControl:
    """meshcat's ``set_control`` command: a GUI control calling ``callback`` (JavaScript)."""

    def __init__(self, name: str, callback: str, value: str, options: list[str]):
        self.name, self.callback, self.value, self.options = name, callback, value, options

    def lower(self) -> dict[str, Any]:
        return {
            "type": "set_control",
            "name": self.name,
            "callback": self.callback,
            "value": self.value,
            "min": self.options,
            "path": "",
        }


def _selector_callback(motions_path: list[str], labels: list[str]) -> str:
    """JavaScript run by the motion menu: show the chosen copy only and restart the clips."""
    return (
        "(value) => { for (const n of " + json.dumps(labels) + ") { "
        "viewer.scene_tree.find(" + json.dumps(motions_path) + '.concat([n])).set_property("visible", n === value); } '
        "viewer.animator.reset(); viewer.animator.play(); viewer.set_dirty(); }"
    )


def _mesh(glyph: Glyph) -> Any:
    import meshcat.geometry as mg

    return mg.Mesh(mg.TriangularMeshGeometry(glyph.vertices, glyph.faces), mg.MeshPhongMaterial(color=glyph.color))


# --------------------------------------------------------------------------- scene


def prepare(
    mech: Mechanism,
    q: Array | str,
    mobility: Mobility | None,
    amplitude: float | None,
    steps: int,
    animate: bool,
) -> tuple[Array, Mobility, dict[str, MotionPath]]:
    """Closed q, its mobility and the followed motions (everything that can fail before meshcat)."""
    q, name = mech.resolve(q)
    mob = mobility if mobility is not None else analyze(mech, q, configuration=name)
    paths = {}
    for motion in mob.motions:
        if animate:
            paths[motion.label] = follow_motion(mech, q, motion, amplitude=amplitude, steps=steps)
        else:
            paths[motion.label] = MotionPath(motion.label, (q,), (q,), (0.0, 0.0), 0.0)
    return q, mob, paths


def _frame_camera(vis: Any, points: Array) -> tuple[Array, float]:
    """Point the camera at the centre of ``points`` (k, 3) from far enough to see them all."""
    lo, hi = points.min(axis=0), points.max(axis=0)
    center = 0.5 * (lo + hi)
    radius = max(float(np.linalg.norm(points - center, axis=1).max()), 1e-9)
    distance = 1.05 * radius / np.sin(np.radians(CAMERA_FOV) / 2)
    offset = distance * VIEW_DIRECTION
    vis["/Cameras/default"].set_transform(pin.SE3(np.eye(3), center).homogeneous)
    camera = vis["/Cameras/default/rotated/<object>"]
    camera.set_property("near", distance / 100.0)
    camera.set_property("far", distance * 100.0)
    camera.set_property("position", [float(offset[0]), float(offset[2]), float(-offset[1])])  # y-up camera frame
    return center, distance


def build(
    vis: Any,
    mech: Mechanism,
    q: Array,
    mob: Mobility,
    paths: dict[str, MotionPath],
    *,
    motion: str | None,
    wrenches: bool,
) -> Scene:
    """Send the whole scene to ``vis`` (a live or recording meshcat Visualizer)."""
    from meshcat.animation import Animation, AnimationClip, js_position, js_quaternion
    from pinocchio.visualize import MeshcatVisualizer

    labels = [m.label for m in mob.motions]
    if motion is not None and motion not in labels:
        raise ConfigurationError(f"no free motion {motion!r} at this configuration; valid: {choices(labels)}")
    visible = motion or (labels[0] if labels else None)
    geometry, generated = visual_geometry(mech, q)
    model = mech.model
    data, gdata = model.createData(), pin.GeometryData(geometry)

    vis[ROOT].delete()
    vis["/Background"].set_property("top_color", [0.97, 0.97, 0.98])
    vis["/Background"].set_property("bottom_color", [0.78, 0.8, 0.84])
    vis["/Grid"].set_property("visible", False)
    vis["/Axes"].set_property("visible", False)
    points: list[Array] = []
    animation = Animation(default_framerate=FPS)
    copies = labels or ["mechanism"]
    for label in copies:
        root = f"{ROOT}/motions/{label}" if labels else f"{ROOT}/mechanism"
        viz = MeshcatVisualizer(model, None, geometry)
        viz.initViewer(viewer=vis)
        viz.loadViewerModel(rootNodeName=root)
        viz.display(q)
        frames = paths[label].frames() if labels else [q]
        for k, qk in enumerate(frames):
            pin.updateGeometryPlacements(model, data, geometry, gdata, qk)
            for i, obj in enumerate(geometry.geometryObjects):
                placement = gdata.oMg[i]
                points.append(placement.translation.copy())
                if not labels:
                    continue
                path = vis[viz.getViewerNodeName(obj, pin.GeometryType.VISUAL)].path
                clip = animation.clips.setdefault(path, AnimationClip(fps=FPS, name=label))
                matrix = placement.homogeneous
                clip.set_property(k, "position", "vector3", js_position(matrix))
                clip.set_property(k, "quaternion", "quaternion", js_quaternion(matrix))
        if labels and label != visible:
            vis[root].set_property("visible", False)

    origin = mob.platform_origin
    length = mech.length_scale
    for m in mob.motions:
        glyph = motion_glyph(m, origin, length)
        vis[f"{ROOT}/glyphs/{glyph.name}"].set_object(_mesh(glyph))
        points.extend(glyph.vertices)
    for i, c in enumerate(mob.constraints):
        glyph = constraint_glyph(c, i, origin, length)
        vis[f"{ROOT}/wrenches/{glyph.name}"].set_object(_mesh(glyph))
        if not wrenches:
            vis[f"{ROOT}/wrenches/{glyph.name}"].set_property("visible", False)
        else:
            points.extend(glyph.vertices)
    center, distance = _frame_camera(vis, np.array(points))
    if visible is not None:  # there are motions to choose from
        vis.window.send(
            _SetControl(
                "motion", _selector_callback(list(vis[f"{ROOT}/motions"].path.entries), labels), visible, labels
            )
        )
        vis.set_animation(animation, play=True, repetitions=float("inf"))
    notes = tuple(n for p in paths.values() for n in p.notes)
    return Scene(tuple(labels), visible, notes, generated, mob, paths, center, distance)
