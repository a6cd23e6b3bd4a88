"""The free motions of the platform, animated in meshcat with the whole mechanism following.

>>> import pinmob, pinmob.viewer
>>> mech = pinmob.load("3-PUU-flat")
>>> scene = pinmob.viewer.export_html(mech, "flat", "flat.html")   # doctest: +SKIP
>>> live = pinmob.viewer.show(mech, "flat")                          # doctest: +SKIP
>>> print(live.url)                                                   # doctest: +SKIP
>>> pinmob.viewer.notebook(pinmob.analyze(mech, "flat"))              # doctest: +SKIP

The last line, the last expression of a Jupyter cell, shows the animated scene in the cell
(:mod:`pinmob.viewer.notebook`: the exported page in an iframe, no server).

What the scene holds (meshcat paths):

- ``/pinmob/mechanism``: the mechanism, once (each mesh defined once). Each
  free motion (``T1 x``, ``R1 z``... the labels of ``Mobility.motions``) is an
  animation clip of that name moving its geometry: the platform goes a finite
  amount along the motion and back, then the other way and back, every frame
  a closed configuration (:func:`pinmob.analysis.follow.motion_path.follow_motion`). The first
  (or the chosen) clip plays in a loop; a row of the panel loads another. A motion that exists
  only to first order (:mod:`pinmob.analysis.finite.finite_mobility`: blocked at some order, or only a combination
  of motion branches) is drawn as such: its glyph grey and half transparent, pulsing in its clip
  while the mechanism stays still, and its row's verdict says so.
- ``/pinmob/glyphs/<label>``: the free motions at the platform
  (:mod:`pinmob.viewer.glyphs`): arrows, axis + ring, axis + helix.
- ``/pinmob/wrenches/<kind i>``: the constraint wrenches, hidden unless asked for.
- ``/pinmob/workspace/samples``, ``singular``, ``refined``, ``chosen``: with a scan's ``workspace``
  (``pinmob scan --show`` or ``--html``), its reachable set as point clouds coloured by distance to
  singularity, beside the mechanism (:mod:`pinmob.viewer.workspace`).
- ``/pinmob/world``: the world axes at the world origin and a grid in z = 0
  (:mod:`pinmob.viewer.world`).

Over the 3D view, pinmob's panel (plain HTML: :mod:`pinmob.viewer.panel`,
``static/panel.js``) says what the scene shows: the mechanism, the DoF and
motion type, one row per motion (direction, world axis point, pitch, how far
its clip went and why it stopped) that plays the motion when clicked, the
singularity class, the whole mechanism's DoF, the constraint wrenches, a
legend, toggles; labels name the glyphs in the scene. The exported page and
pinmob's own server (:mod:`pinmob.viewer.bridge`) show it; a plain meshcat
server shows the scene without it.

Everything under ``/pinmob`` is shifted by ``-Scene.center`` (meshcat's orbit
controls look at the origin). The scene is built by :mod:`pinmob.viewer.scene`; :func:`export_html` (from
:mod:`pinmob.viewer.html`) writes it to a file, :func:`show` sends it to a
meshcat server. The geometry is the URDF's visuals through Pinocchio's
``MeshcatVisualizer``, or a generated stick figure (:mod:`pinmob.viewer.skeleton`)
when the URDF has none. meshcat is imported here only, when a function runs.
"""

from __future__ import annotations

import contextlib
import io
from typing import Any

from pinmob.analysis import Configuration, Mobility, Report
from pinmob.exceptions import ConfigurationError, ViewerError
from pinmob.model import Mechanism
from pinmob.viewer.html import export_html, scene_html
from pinmob.viewer.notebook import NotebookScene, notebook
from pinmob.viewer.options import VIEW_OPTIONS, ViewOptions, view_options
from pinmob.viewer.prepared import prepare, viewed_frame
from pinmob.viewer.scene import FPS, ROOT, Array, Scene, build, require_meshcat
from pinmob.viewer.workspace import Workspace, sample_configuration, workspace_cloud


def show(
    mech: Mechanism,
    q: Array | str | Configuration,
    mobility: Mobility | Report | None = None,
    *,
    zmq_url: str | None = None,
    port: int | None = None,
    timeout: float = 20.0,
    tied: bool = False,
    workspace: Workspace | None = None,
    **options: Any,
) -> Scene:
    """Show the mechanism and its animated free motions in a meshcat server.

    Everything that can fail (closure, analysis, following the motions) runs
    before any server is touched. Nothing waits for a browser: open
    ``scene.url`` whenever you like; the server keeps the scene.

    Args:
        mech: the mechanism.
        q: configuration (nq,), the name of one of ``mech.configurations``, or a :class:`Configuration`.
        mobility: its platform mobility (or its whole Report), if already computed.
        zmq_url: a running meshcat server (``tcp://127.0.0.1:6000``); default:
            start one on 127.0.0.1 (``scene.server``; it lives until
            ``scene.server.stop()`` or until killed, not with this process, unless ``tied``).
        port: web port of the server pinmob starts (default: first free from 7000).
        timeout: seconds to wait for the server to start or answer.
        tied: the server pinmob starts stops when this process ends, however it ends (even by SIGKILL);
            ``pinmob show`` ties it unless ``--detach``.
        workspace: a scan's reachable set drawn beside the mechanism, with its legend in the panel
            (:func:`pinmob.viewer.workspace.workspace_cloud`; ``pinmob scan --show``).
        **options: the scene's options (:class:`ViewOptions`: ``motion``, ``wrenches``, ``amplitude``, ``steps``,
            ``animate``, ``finite``).

    A mechanism without a platform shows its output frame that moves most (``scene.shown_frame`` says which).

    Raises:
        ConfigurationError: a port outside 1-65535, both a port and a zmq URL, an unknown option or ``motion``
            (all checked before any server is started).
        ViewerError: meshcat missing, port in use, or no server answering.
        ClosureError: q does not close.
    """
    from pinmob.viewer.server import check_port, probe, start_server

    check_port(port)
    if zmq_url is not None and port is not None:
        raise ConfigurationError("give either a port for a new server or the zmq URL of a running one, not both")
    prep = prepare(mech, q, mobility, view_options(**options))
    require_meshcat()
    import zmq
    from meshcat.visualizer import Visualizer

    server = None
    if zmq_url is None:
        server = start_server(port=port, timeout=timeout, tied=tied)
        zmq_url = server.zmq_url
    try:
        probe(zmq_url, timeout=min(timeout, 5.0))
        with contextlib.redirect_stdout(io.StringIO()):
            vis = Visualizer(zmq_url=zmq_url)
        vis.window.zmq_socket.setsockopt(zmq.RCVTIMEO, int(timeout * 1000))
        vis.window.zmq_socket.setsockopt(zmq.LINGER, 0)
        scene = build(vis, prep, workspace=workspace)
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


__all__ = [
    "FPS",
    "NotebookScene",
    "ROOT",
    "Scene",
    "VIEW_OPTIONS",
    "ViewOptions",
    "Workspace",
    "export_html",
    "notebook",
    "sample_configuration",
    "scene_html",
    "show",
    "viewed_frame",
    "workspace_cloud",
]
