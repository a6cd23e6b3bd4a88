"""The web page of a scene: meshcat's viewer, pinmob's panel, and the scene's commands.

One page for both uses: :func:`static_page` holds everything (meshcat's viewer
script and the scene's recorded commands, gzip-compressed and base64-encoded,
replayed when it opens: :mod:`pinmob.viewer.html`); :func:`live_page` loads
meshcat's script from the server and receives the commands by websocket
(:mod:`pinmob.viewer.bridge`). Both load pinmob's panel
(``static/panel.js``, ``static/panel.css``), which makes the viewer understand
pinmob's ``pinmob_panel`` command before any command arrives.
"""

from __future__ import annotations

import base64
import gzip
import html
import json
from pathlib import Path

STATIC = Path(__file__).resolve().parent / "static"


def meshcat_script() -> Path:
    """The viewer script of meshcat (``main.min.js``), found through meshcat's public ``viewer_assets_path()``."""
    import meshcat

    return Path(meshcat.viewer_assets_path()) / "dist" / "main.min.js"


def _page(title: str, scripts: str, boot: str) -> str:
    css = (STATIC / "panel.css").read_text(encoding="utf-8")
    panel = (STATIC / "panel.js").read_text(encoding="utf-8")
    return f"""<!DOCTYPE html>
<html>
<head><meta charset="utf-8"><title>{html.escape(title)}</title>
<style>
body {{ margin: 0; }}
#meshcat-pane {{ width: 100vw; height: 100vh; overflow: hidden; }}
{css}
</style>
</head>
<body>
<div id="meshcat-pane"></div>
{scripts}
<script>
{panel}
</script>
<script>
var viewer = new MeshCat.Viewer(document.getElementById("meshcat-pane"));
pinmob.install(viewer);
{boot}
</script>
</body>
</html>
"""


def static_page(commands: list[bytes], title: str) -> str:
    """A self-contained page replaying ``commands`` (msgpack bytes of meshcat commands) when it opens.

    The commands are concatenated, gzip-compressed and base64-encoded once
    (URDF meshes are mostly text: the file is several times smaller); the page
    inflates them with the browser's ``DecompressionStream`` and replays them in order.
    """
    script = meshcat_script().read_text(encoding="utf-8")
    blob = base64.b64encode(gzip.compress(b"".join(commands), compresslevel=9, mtime=0)).decode()
    sizes = json.dumps([len(c) for c in commands])
    boot = f"""var pinmob_sizes = {sizes};
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
}})();"""
    return _page(title, f"<script>\n{script}\n</script>", boot)


def live_page(title: str = "pinmob") -> str:
    """The page a live server serves: meshcat's script from the server, the scene by websocket."""
    boot = """try {
  viewer.connect();
} catch (e) {
  console.info("Not connected to the meshcat websocket server: ", e);
}"""
    return _page(title, '<script src="main.min.js"></script>', boot)
