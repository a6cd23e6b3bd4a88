"""No file from outside the model's folders reaches an HTML export (issue 14, class 1).

A URDF names mesh files by any path and a Collada mesh names texture images by any path; the
viewer embeds what it draws into the page. Each way out of the model's folder (absolute paths,
``..``, ``package://..``, a symbolic link inside pointing out, a texture of an inside mesh) is
tried; the secret file's bytes (raw and base64-encoded, as Pinocchio's visualizer embeds
textures) must not be in the page's decoded commands, and a warning names the left-out file.
A mesh and texture inside the folder are still drawn (the same bytes are found).
"""

from __future__ import annotations

import base64
import gzip
import re
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

import pinmob
from pinmob import viewer

MODELS = Path(pinmob.__file__).resolve().parent.parent / "models"
SECRET = b"TOPSECRET-not-for-the-page-0123456789"
TRIANGLE = "v 0 0 0\nv 0.01 0 0\nv 0 0.01 0\nf 1 2 3\n"


def dae(texture: str) -> str:
    """A one-triangle Collada file naming ``texture`` in its image library."""
    return f"""<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<library_images><image id="t"><init_from>{texture}</init_from></image></library_images>
<library_geometries><geometry id="g"><mesh><source id="p"><float_array id="pa" count="9">0 0 0 0.01 0 0 0 0.01 0
</float_array><technique_common><accessor source="#pa" count="3" stride="3"><param name="X" type="float"/>
<param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#p"/></vertices><triangles count="1">
<input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles></mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node></visual_scene>
</library_visual_scenes><scene><instance_visual_scene url="#s"/></scene></COLLADA>"""


def five_bar_with_mesh(tmp: Path, mesh: str) -> Path:
    """The built-in five-bar copied into ``tmp/model`` with ``mesh`` as the visual of link A_r1."""
    folder = tmp / "model"
    folder.mkdir(exist_ok=True)
    shutil.copy(MODELS / "five_bar.toml", folder)
    text = (MODELS / "five_bar.urdf").read_text()
    visual = f'<link name="A_r1_link"><visual><geometry><mesh filename="{mesh}"/></geometry></visual></link>'
    (folder / "five_bar.urdf").write_text(text.replace('<link name="A_r1_link"/>', visual, 1))
    return folder / "five_bar.toml"


def page_commands(html: Path) -> bytes:
    """The decoded meshcat commands a static page replays."""
    blob = re.search(r'pinmob_commands = "([^"]*)"', html.read_text())
    assert blob is not None
    return gzip.decompress(base64.b64decode(blob.group(1)))


def leaks(commands: bytes) -> bool:
    return SECRET in commands or base64.b64encode(SECRET)[:40] in commands


def outside_obj(tmp: Path) -> str:
    (tmp / "secret.obj").write_text(f"# {SECRET.decode()}\n{TRIANGLE}")
    return str(tmp / "secret.obj")


def secret_png(tmp: Path) -> Path:
    (tmp / "secret.png").write_bytes(SECRET)
    return tmp / "secret.png"


def symlink_inside(tmp: Path) -> str:
    (tmp / "model").mkdir(exist_ok=True)
    (tmp / "model" / "link.obj").symlink_to(outside_obj(tmp))
    return "link.obj"


def dae_inside(tmp: Path, texture: str) -> str:
    (tmp / "model").mkdir(exist_ok=True)
    (tmp / "model" / "part.dae").write_text(dae(texture))
    return "part.dae"


WAYS_OUT = {
    "absolute obj": outside_obj,
    "obj up with ..": lambda tmp: (outside_obj(tmp), "../secret.obj")[1],
    "obj package://..": lambda tmp: (outside_obj(tmp), "package://../secret.obj")[1],
    "symlink inside to outside": symlink_inside,
    "dae texture absolute": lambda tmp: dae_inside(tmp, str(secret_png(tmp))),
    "dae texture up with ..": lambda tmp: (secret_png(tmp), dae_inside(tmp, "../secret.png"))[1],
    "dae texture via symlink": lambda tmp: (
        secret_png(tmp),
        (tmp / "model").mkdir(exist_ok=True),
        (tmp / "model" / "tex.png").symlink_to(tmp / "secret.png"),
        dae_inside(tmp, "tex.png"),
    )[3],
}


@pytest.mark.parametrize("way", WAYS_OUT)
def test_no_file_from_outside_the_model_reaches_the_export(way, tmp_path):
    toml = five_bar_with_mesh(tmp_path, WAYS_OUT[way](tmp_path))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mech = pinmob.load(toml)
        viewer.export_html(mech, "generic", tmp_path / "out.html")
    assert not leaks(page_commands(tmp_path / "out.html"))
    said = [str(w.message) for w in caught if "left out of the drawing" in str(w.message)]
    assert len(said) == 1 and "'A_r1_link_0'" in said[0] and "ROS_PACKAGE_PATH" in said[0], said


def test_mesh_and_texture_inside_the_model_are_drawn(tmp_path):
    folder = tmp_path / "model"
    (folder / "textures").mkdir(parents=True)
    (folder / "textures" / "skin.png").write_bytes(SECRET)  # inside: allowed, so its bytes are in the page
    toml = five_bar_with_mesh(tmp_path, dae_inside(tmp_path, "textures/skin.png"))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # nothing is left out
        viewer.export_html(pinmob.load(toml), "generic", tmp_path / "out.html")
    assert base64.b64encode(SECRET)[:40] in page_commands(tmp_path / "out.html")


def test_the_cli_warns_and_exports_without_the_outside_mesh(tmp_path):
    toml = five_bar_with_mesh(tmp_path, outside_obj(tmp_path))
    out = subprocess.run(
        [sys.executable, "-m", "pinmob", "show", str(toml), "--html", str(tmp_path / "out.html")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
    assert "left out of the drawing" in out.stderr and str(tmp_path / "secret.obj") in out.stderr
    assert "Traceback" not in out.stderr
    assert not leaks(page_commands(tmp_path / "out.html"))
