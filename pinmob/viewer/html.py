"""Static HTML export: a scene replayed from recorded meshcat commands in one self-contained file.

meshcat's ``Visualizer`` is given a window (:class:`_Recorder`) that records
every command (msgpack bytes) instead of sending it to a server; the page
holds meshcat's viewer script and those commands, base64-encoded, replayed in
order when it opens. No server is needed to build or to open it.
"""

from __future__ import annotations

import base64
import gzip
import html
import json
import os
import tempfile
from pathlib import Path
from typing import Any

from pinmob.analysis.mobility import Mobility
from pinmob.exceptions import ViewerError
from pinmob.model.mechanism import Mechanism
from pinmob.viewer.scene import Array, Scene, build, prepare, require_meshcat


class _Recorder:
    """A meshcat window that records commands (msgpack bytes) instead of sending them."""

    web_url = None

    def __init__(self) -> None:
        self.commands: list[bytes] = []

    def send(self, command: Any) -> None:
        import umsgpack

        self.commands.append(umsgpack.packb(command.lower()))


def _html(commands: list[bytes], title: str) -> str:
    """Self-contained page: meshcat's viewer script and the scene's commands, replayed in order.

    The commands are concatenated, gzip-compressed and base64-encoded once
    (URDF meshes are mostly text: the file is several times smaller); the page
    inflates them with the browser's ``DecompressionStream`` and replays them.
    """
    import meshcat

    script = (Path(meshcat.__file__).parent / "viewer" / "dist" / "main.min.js").read_text()
    blob = base64.b64encode(gzip.compress(b"".join(commands), compresslevel=9, mtime=0)).decode()
    sizes = json.dumps([len(c) for c in commands])
    return f"""<!DOCTYPE html>
<html>
<head><meta charset="utf-8"><title>{html.escape(title)}</title></head>
<body>
<div id="meshcat-pane"></div>
<script>
{script}
</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
var pinmob_sizes = {sizes};
var pinmob_commands = "{blob}";
(async () => {{
  const packed = Uint8Array.from(atob(pinmob_commands), (ch) => ch.charCodeAt(0));
  const stream = new Blob([packed]).stream().pipeThrough(new DecompressionStream("gzip"));
  const bytes = new Uint8Array(await new Response(stream).arrayBuffer());
  let offset = 0;
  for (const size of pinmob_sizes) {{
    viewer.handle_command_bytearray(bytes.slice(offset, offset + size));
    offset += size;
  }}
}})();
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
    finite: bool = True,
) -> tuple[str, Scene]:
    """The scene as a self-contained HTML page (no server, no file); see :func:`export_html`."""
    q, mob, paths = prepare(mech, q, mobility, amplitude, steps, animate, motion, finite)
    require_meshcat()
    from meshcat.visualizer import Visualizer

    recorder = _Recorder()
    scene = build(Visualizer(window=recorder), mech, q, mob, paths, motion=motion, wrenches=wrenches)
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
    finite: bool = True,
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
        finite: tell each motion's finite verdict (:mod:`pinmob.analysis.finite`); a motion that exists
            only to first order is drawn as such (grey glyph pulsing in its clip, the menu says so).

    Raises:
        ViewerError: the file exists and ``overwrite`` is False, or cannot be written.
        ClosureError: q does not close.
    """
    target = Path(path).expanduser()
    if target.exists() and not overwrite:
        raise ViewerError(f"{str(target)!r} exists already; choose another file name or allow overwriting (--force)")
    if target.is_dir():
        raise ViewerError(f"{str(target)!r} is a directory; give a file name ending in .html")
    page, scene = scene_html(
        mech,
        q,
        mobility,
        motion=motion,
        wrenches=wrenches,
        amplitude=amplitude,
        steps=steps,
        animate=animate,
        finite=finite,
    )
    parent = target.parent if str(target.parent) else Path(".")
    if not parent.is_dir():
        raise ViewerError(f"cannot write {str(target)!r}: folder {str(parent)!r} does not exist")
    fd, tmp = tempfile.mkstemp(prefix=".pinmob-", suffix=".html", dir=parent)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(page)
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
