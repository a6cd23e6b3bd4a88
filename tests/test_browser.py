"""The viewer in a real browser: headless Chromium (Debian's package) driven by Playwright.

Against the live meshcat server page and the exported HTML file: the mechanism
is drawn (enough pixels differ from the empty scene around the platform), two
animation times differ there (the motion is visible), every clip is in the
scene, and the motion menu switches clips. These tests never skip: without
Chromium they fail and say how to install it (``.ci/browser-deps.sh``). They
carry the ``browser`` marker: ``pytest -m "not browser"`` leaves them out on
purpose, ``pytest -m browser`` runs only them; CI (``.ci/run``) runs them all.

Set ``PINMOB_DOCS_SCREENSHOTS=1`` to also write the screenshots of 3-PUU-flat
to ``docs/``.
"""

from __future__ import annotations

import io
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from millimetres import in_millimetres

import pinmob
from pinmob import viewer

CHROMIUM = os.environ.get("PINMOB_CHROMIUM", "/usr/bin/chromium")
FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    # software WebGL (SwiftShader through ANGLE)
    "--use-gl=angle",
    "--use-angle=swiftshader",
    "--enable-unsafe-swiftshader",
]
WIDTH, HEIGHT = 900, 650
DOCS = Path(__file__).resolve().parent.parent / "docs"

pytestmark = pytest.mark.browser  # every test here: select with -m browser, leave out with -m "not browser"


@pytest.fixture(scope="module")
def browser():
    if not (Path(CHROMIUM).exists() or shutil.which(CHROMIUM)):
        pytest.fail(
            f"Chromium not found at {CHROMIUM}: install Debian's package with .ci/browser-deps.sh "
            "(apt-get install chromium)"
        )
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        pytest.fail(
            "Playwright for Python is missing: pip install -e '.[test]' "
            "(never 'playwright install'; Debian's chromium is used)"
        )
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=CHROMIUM, args=FLAGS, headless=True)
        yield b
        b.close()


@pytest.fixture(scope="module")
def flat() -> pinmob.Mechanism:
    return pinmob.load("3-PUU-flat")


def open_page(browser, url: str):
    page = browser.new_page(viewport={"width": WIDTH, "height": HEIGHT})
    errors: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.goto(url)
    # the scene has arrived when the animation clips are loaded (the live page gets them by websocket)
    page.wait_for_function("window.viewer && viewer.animator.actions.length > 0", timeout=20000)
    page.wait_for_timeout(500)
    assert errors == [], errors
    return page


def image(page) -> np.ndarray:
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(page.screenshot())).convert("RGB")).astype(int)


def platform_box(page, point: np.ndarray, half: int = 90) -> tuple[slice, slice]:
    """Pixel box (rows, cols) around the screen projection of a point of pinmob's world (under /pinmob)."""
    x, y = page.evaluate(
        "([x, y, z]) => { const v = viewer.camera.position.clone().set(x, y, z);"
        " const root = viewer.scene_tree.find(['meshcat', 'pinmob']).object; root.updateMatrixWorld(true);"
        " v.applyMatrix4(root.matrixWorld); viewer.camera.updateMatrixWorld(); v.project(viewer.camera);"
        " return [(v.x + 1) / 2 * window.innerWidth, (1 - v.y) / 2 * window.innerHeight]; }",
        [float(c) for c in point],
    )
    assert 0 <= x < WIDTH and 0 <= y < HEIGHT, (x, y)
    r, c = int(y), int(x)
    return slice(max(r - half, 0), r + half), slice(max(c - half, 0), c + half)


def set_visible(page, path: list[str], visible: bool) -> None:
    page.evaluate(
        "([p, v]) => { viewer.scene_tree.find(p).set_property('visible', v); viewer.set_dirty(); }", [path, visible]
    )
    page.wait_for_timeout(300)


def seek(page, t: float) -> None:
    page.evaluate("(t) => { viewer.animator.pause(); viewer.animator.seek(t); }", t)
    page.wait_for_timeout(300)


def loaded_clips(page) -> set[str]:
    return set(page.evaluate("viewer.animator.actions.map((a) => a.getClip().name)"))


def check_scene(page, scene: viewer.Scene, name: str | None = None) -> None:
    """The checks shared by the live page and the HTML file (screenshots to docs/ when ``name`` is given)."""
    # one mechanism (each mesh defined once), moved by the clip playing: the visible one first
    assert page.evaluate("viewer.scene_tree.find(['meshcat', 'pinmob', 'mechanism', 'visuals']).object.children.length")
    assert loaded_clips(page) == {scene.visible}
    assert page.evaluate("viewer.animator.playing"), "the first clip should play on opening"
    assert page.evaluate("viewer.animator.actions.every((a) => a.repetitions === Infinity)")
    # glyphs drawn over the mechanism (the platform never hides them)
    glyph = ["meshcat", "pinmob", "glyphs", scene.clips[0], "<object>"]
    assert page.evaluate("(p) => viewer.scene_tree.find(p).object.material.depthTest", glyph) is False
    assert page.evaluate("(p) => viewer.scene_tree.find(p).object.renderOrder", glyph) > 0

    box = platform_box(page, scene.mobility.platform_origin)
    seek(page, 0.0)
    drawn = image(page)
    set_visible(page, ["meshcat", "pinmob"], False)
    empty = image(page)
    set_visible(page, ["meshcat", "pinmob"], True)
    mechanism = np.abs(drawn - empty).max(axis=2) > 40
    share = mechanism[box].mean()
    assert share > 0.08, f"only {share:.1%} of the platform region shows the mechanism"
    assert mechanism.mean() > 0.02

    # the first clip reaches +amplitude a quarter of the way through: the platform moved on screen
    quarter = (len(scene.paths[scene.visible].forward) - 1) / viewer.FPS
    seek(page, quarter)
    moved = image(page)
    changed = (np.abs(moved - drawn).max(axis=2) > 40)[box].mean()
    assert changed > 0.01, f"animation times 0 and {quarter:.2f} s look the same ({changed:.2%} of pixels differ)"
    if name and os.environ.get("PINMOB_DOCS_SCREENSHOTS"):
        page.screenshot(path=str(DOCS / f"{name}_T1.png"))

    # the motion menu offers every clip of the analysis and loads the chosen one
    options = page.evaluate(
        "Array.from(viewer.gui_controllers['motion'].domElement.querySelectorAll('option')).map((o) => o.value)"
    )
    assert options == [m.label for m in scene.mobility.motions] == list(scene.clips)
    for label in scene.clips[1:] + scene.clips[:1]:
        page.evaluate("(l) => viewer.gui_controllers['motion'].setValue(l)", label)
        page.wait_for_timeout(200)
        assert loaded_clips(page) == {label}
        assert page.evaluate("viewer.animator.playing")
    if name and os.environ.get("PINMOB_DOCS_SCREENSHOTS"):
        page.evaluate("(l) => viewer.gui_controllers['motion'].setValue(l)", scene.clips[1])
        seek(page, 0.0)
        page.screenshot(path=str(DOCS / f"{name}_R1.png"))


def test_exported_html_in_chromium(browser, flat, tmp_path):
    scene = viewer.export_html(flat, "flat", tmp_path / "flat.html")
    page = open_page(browser, (tmp_path / "flat.html").as_uri())
    check_scene(page, scene, "3puu_flat")
    page.close()


def test_live_server_page_in_chromium(browser, flat):
    scene = viewer.show(flat, "flat")
    try:
        assert scene.url.startswith("http://127.0.0.1:")
        page = open_page(browser, scene.url)
        check_scene(page, scene)
        page.close()
    finally:
        scene.server.stop()


def test_delta_html_in_chromium(browser, tmp_path):
    # a mechanism with loops inside its limbs (the parallelograms) and three translations
    mech = pinmob.load("Delta")
    scene = viewer.export_html(mech, "generic", tmp_path / "delta.html")
    assert scene.clips == ("T1 x", "T2 y", "T3 z")
    page = open_page(browser, (tmp_path / "delta.html").as_uri())
    check_scene(page, scene)
    page.close()


def test_camera_and_lights_frame_a_model_in_millimetres(browser, tmp_path):
    # the same 3-PUU in millimetres fills the view the same way, and is lit the same way
    # (meshcat's point lights sit about 2 m from the origin and reach 10 m: inside a model
    # 500 mm across they would light it from within, or not at all)
    mech = pinmob.load("3-PUU")
    q = pinmob.closed_configuration(mech, "generic")
    mm = in_millimetres(mech)
    shares, brightness = [], []
    for m, name in ((mech, "m"), (mm, "mm")):
        scene = viewer.export_html(m, q, tmp_path / f"{name}.html", animate=False)
        page = open_page(browser, (tmp_path / f"{name}.html").as_uri())
        seek(page, 0.0)
        drawn = image(page)
        set_visible(page, ["meshcat", "pinmob"], False)
        mask = np.abs(drawn - image(page)).max(axis=2) > 40
        shares.append(mask.mean())
        brightness.append(drawn[mask].mean())
        platform_box(page, scene.mobility.platform_origin)  # on screen
        page.close()
    assert shares[0] > 0.03
    assert abs(shares[0] - shares[1]) < 0.25 * shares[0]
    assert abs(brightness[0] - brightness[1]) < 0.05 * brightness[0], brightness
