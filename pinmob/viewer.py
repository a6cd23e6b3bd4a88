"""The free motions of the platform, animated in meshcat with the whole mechanism following.

>>> import pinmob, pinmob.viewer
>>> mech = pinmob.load("3-PUU-flat")
>>> scene = pinmob.viewer.export_html(mech, "flat", "flat.html")   # doctest: +SKIP
>>> live = pinmob.viewer.show(mech, "flat")                          # doctest: +SKIP
>>> print(live.url)                                                   # doctest: +SKIP

What the scene holds (meshcat paths):

- ``/pinmob/motions/<label>``: one copy of the mechanism per free motion
  (``T1 x``, ``R1 z``... the labels of ``Mobility.motions``), each animated
  by a clip of that name: the platform goes a finite amount along the motion
  and back, then the other way and back, every frame a closed configuration
  (:func:`pinmob.animation.follow_motion`). Only the first (or the chosen)
  one is visible; pick another with the ``motion`` menu of the controls
  (pinmob's server and HTML export) or the visibility boxes under
  Scene > pinmob > motions. All clips loop.
- ``/pinmob/glyphs/<label>``: the free motions at the platform
  (:mod:`pinmob.glyphs`): arrows, axis + ring, axis + helix.
- ``/pinmob/wrenches/<kind i>``: the constraint wrenches, hidden unless asked for.
- ``/pinmob/mechanism``: the mechanism at rest, when it has no free motion.

The geometry is the URDF's visuals through Pinocchio's
``MeshcatVisualizer``, or a generated stick figure (:mod:`pinmob.skeleton`)
when the URDF has none. meshcat is imported here only, when a function runs.
"""

from __future__ import annotations

import base64
import contextlib
import io
import json
import os
import tempfile
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


def _meshcat() -> Any:
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


class _Recorder:
    """A meshcat window that records commands (msgpack bytes) instead of sending them."""

    web_url = None

    def __init__(self) -> None:
        self.commands: list[bytes] = []

    def send(self, command: Any) -> None:
        import umsgpack

        self.commands.append(umsgpack.packb(command.lower()))


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


def _prepare(
    mech: Mechanism,
    q: Array | str,
    mobility: Mobility | None,
    amplitude: float | None,
    steps: int,
    animate: bool,
) -> tuple[Array, Mobility, dict[str, MotionPath]]:
    """Closed q, its mobility and the followed motions (everything that can fail before meshcat)."""
    name = q if isinstance(q, str) else None
    q = mech.configuration(q) if isinstance(q, str) else mech.check_q(q)
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


def _build(
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


# --------------------------------------------------------------------------- static HTML


def _html(commands: list[bytes], title: str) -> str:
    """Self-contained page: meshcat's viewer script and the scene's commands, replayed in order."""
    import meshcat

    script = (Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js").read_text()
    blobs = ",\n".join(f'"{base64.b64encode(c).decode()}"' for c in commands)
    return f"""<!DOCTYPE html>
<html>
<head><meta charset="utf-8"><title>{title}</title></head>
<body>
<div id="meshcat-pane"></div>
<script>
{script}
</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
var pinmob_commands = [
{blobs}
];
for (const c of pinmob_commands) {{
  viewer.handle_command_bytearray(Uint8Array.from(atob(c), (ch) => ch.charCodeAt(0)));
}}
</script>
<style>
body {{ margin: 0; }}
#meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}
</style>
</body>
</html>
"""


def scene_html(
    mech: Mechanism,
    q: Array | str,
    mobility: Mobility | None = None,
    *,
    motion: str | None = None,
    wrenches: bool = False,
    amplitude: float | None = None,
    steps: int = 12,
    animate: bool = True,
) -> tuple[str, Scene]:
    """The scene as a self-contained HTML page (no server, no file); see :func:`export_html`."""
    q, mob, paths = _prepare(mech, q, mobility, amplitude, steps, animate)
    _meshcat()
    from meshcat.visualizer import Visualizer

    recorder = _Recorder()
    scene = _build(Visualizer(window=recorder), mech, q, mob, paths, motion=motion, wrenches=wrenches)
    title = f"pinmob: {mech.name}" + (f" at {mob.configuration}" if mob.configuration else "") + f" ({mob.motion_type})"
    return _html(recorder.commands, title), scene


def export_html(
    mech: Mechanism,
    q: Array | str,
    path: str | Path,
    mobility: Mobility | None = None,
    *,
    overwrite: bool = False,
    motion: str | None = None,
    wrenches: bool = False,
    amplitude: float | None = None,
    steps: int = 12,
    animate: bool = True,
) -> Scene:
    """Write the scene and its animations to a self-contained HTML file that opens without a server.

    The file holds meshcat's viewer script and the scene's commands (meshcat's
    static export, built without a server). It is written to a temporary file
    first and moved into place, so a failure leaves nothing half-written.

    Args:
        mech: the mechanism.
        q: (nq,) closed configuration or the name of one of ``mech.configurations``.
        path: the ``.html`` file to write.
        mobility: the analysis to show (default: ``analyze(mech, q)``).
        overwrite: replace an existing file; otherwise an existing file is an error.
        motion: label of the motion visible on opening (default: the first).
        wrenches: show the constraint wrenches (they are in the scene, hidden, otherwise).
        amplitude: distance of each motion [m for T, rad for R/H]; default 0.2 L or 0.35 rad.
        steps: continuation steps per direction.
        animate: follow the motions; False shows them as static glyphs only.

    Raises:
        ViewerError: the file exists and ``overwrite`` is False, or cannot be written.
        ClosureError: q does not close.
    """
    target = Path(path).expanduser()
    if target.exists() and not overwrite:
        raise ViewerError(f"{str(target)!r} exists already; choose another file name or allow overwriting (--force)")
    if target.is_dir():
        raise ViewerError(f"{str(target)!r} is a directory; give a file name ending in .html")
    html, scene = scene_html(
        mech, q, mobility, motion=motion, wrenches=wrenches, amplitude=amplitude, steps=steps, animate=animate
    )
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise ViewerError(f"cannot write {str(target)!r}: folder {str(parent)!r} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=".pinmob-", suffix=".html", dir=parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(html)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        if not overwrite and target.exists():
            raise ViewerError(f"{str(target)!r} appeared while writing; not overwritten")
        os.replace(tmp, target)
    except OSError as exc:
        raise ViewerError(f"cannot write {str(target)!r}: {exc.strerror or exc}") from None
    finally:
        if os.path.exists(tmp):
            os.unlink(tmp)
    scene.html = target
    return scene


# --------------------------------------------------------------------------- live


def show(
    mech: Mechanism,
    q: Array | str,
    mobility: Mobility | None = None,
    *,
    zmq_url: str | None = None,
    port: int | None = None,
    motion: str | None = None,
    wrenches: bool = False,
    amplitude: float | None = None,
    steps: int = 12,
    animate: bool = True,
    timeout: float = 20.0,
) -> Scene:
    """Show the mechanism and its animated free motions in a meshcat server.

    Everything that can fail (closure, analysis, following the motions) runs
    before any server is touched. Nothing waits for a browser: open
    ``scene.url`` whenever you like; the server keeps the scene.

    Args:
        zmq_url: a running meshcat server (``tcp://127.0.0.1:6000``); default:
            start one on 127.0.0.1 (``scene.server``; it lives until
            ``scene.server.stop()`` or until killed, not with this process).
        port: web port of the server pinmob starts (default: first free from 7000).
        timeout: seconds to wait for the server to start or answer.
        Others as in :func:`export_html`.

    Raises:
        ViewerError: meshcat missing, port in use, or no server answering.
        ClosureError: q does not close.
    """
    q, mob, paths = _prepare(mech, q, mobility, amplitude, steps, animate)
    _meshcat()
    import zmq
    from meshcat.visualizer import Visualizer

    from .meshcat_server import probe, start_server

    server = None
    if zmq_url is None:
        server = start_server(port=port, timeout=timeout)
        zmq_url = server.zmq_url
    elif port is not None:
        raise ConfigurationError("give either a port for a new server or the zmq URL of a running one, not both")
    try:
        probe(zmq_url, timeout=min(timeout, 5.0))
        with contextlib.redirect_stdout(io.StringIO()):
            vis = Visualizer(zmq_url=zmq_url)
        vis.window.zmq_socket.setsockopt(zmq.RCVTIMEO, int(timeout * 1000))
        vis.window.zmq_socket.setsockopt(zmq.LINGER, 0)
        scene = _build(vis, mech, q, mob, paths, motion=motion, wrenches=wrenches)
    except zmq.ZMQError as exc:
        if server is not None:
            server.stop()
        raise ViewerError(f"the meshcat server at {zmq_url} stopped answering ({exc})") from None
    except BaseException:
        if server is not None:
            server.stop()
        raise
    scene.url, scene.zmq_url, scene.server = vis.url(), zmq_url, server
    vis.window.zmq_socket.close(0)
    return scene
