"""The viewer in a real browser: headless Chromium (Debian's package) driven by Playwright.

Against pinmob's live server page, the exported HTML file and a notebook cell's iframe: the mechanism
is drawn (enough pixels differ from the empty scene around the platform), two
animation times differ there (the motion is visible), every clip is in the
scene, and the panel's rows switch clips. The panel's text, read from the DOM,
says what the analysis says (DoF, motion type, each motion's direction, world
axis point and pitch, how far its clip went and why it stopped, the
singularity class, the whole mechanism's DoF); clicking a row plays that
motion, which moves the platform on screen, or the panel says why it cannot;
the glyphs' labels are drawn, apart, where their glyphs are. These tests never
skip: without Chromium they fail and say how to install it
(``.ci/browser-deps.sh``). They carry the ``browser`` marker: ``pytest -m "not
browser"`` leaves them out on purpose, ``pytest -m browser`` runs only them; CI
(``.ci/run``) runs them all.

Set ``PINMOB_DOCS_SCREENSHOTS=1`` to also write the screenshots of 3-PUU-flat
to ``docs/``.
"""

from __future__ import annotations

import io
import os
import re
import shutil
from pathlib import Path

import numpy as np
import pytest
from millimetres import in_millimetres
from numpy.testing import assert_allclose

import pinmob
from pinmob import viewer
from pinmob.viewer.scene import INSTANTANEOUS_OPACITY

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
WIDTH, HEIGHT = 1100, 700
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
    # the scene has arrived when the panel is there and a clip is loaded (the live page gets them by websocket)
    page.wait_for_function("window.pinmob && pinmob.state && viewer.animator.actions.length > 0", timeout=20000)
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

    # the panel has one row per motion of the analysis; clicking one loads and plays its clip
    rows = page.eval_on_selector_all("tr.pinmob-motion", "(rows) => rows.map((r) => r.dataset.label)")
    assert rows == [m.label for m in scene.mobility.motions] == list(scene.clips)
    for label in scene.clips[1:] + scene.clips[:1]:
        page.click(f'tr.pinmob-motion[data-label="{label}"]')
        page.wait_for_timeout(200)
        assert loaded_clips(page) == {label}
        assert page.evaluate("viewer.animator.playing")
    if name and os.environ.get("PINMOB_DOCS_SCREENSHOTS"):
        page.click(f'tr.pinmob-motion[data-label="{scene.clips[1]}"]')
        seek(page, 0.0)
        page.screenshot(path=str(DOCS / f"{name}_R1.png"))


def test_exported_html_in_chromium(browser, flat, tmp_path):
    scene = viewer.export_html(flat, "flat", tmp_path / "flat.html")
    page = open_page(browser, (tmp_path / "flat.html").as_uri())
    check_scene(page, scene, "3puu_flat")
    page.close()


def test_instantaneous_only_motion_is_drawn_as_such(browser, flat, tmp_path):
    """The flat 3-PUU's R1 z is blocked at order 2 (tests/test_finite.py): its row's verdict says so, its glyph is
    grey and half transparent, and its clip makes the glyph pulse while the mechanism stays still."""
    scene = viewer.export_html(flat, "flat", tmp_path / "flat.html", motion="R1 z")
    assert scene.verdicts == {"T1 z": "finite", "R1 z": "blocked at order 2 (shaky)"}
    assert (scene.paths["T1 z"].finite, scene.paths["R1 z"].finite) == (True, False)
    page = open_page(browser, (tmp_path / "flat.html").as_uri())
    verdicts = page.eval_on_selector_all(
        "tr.pinmob-motion", "(rows) => rows.map((r) => [r.dataset.label, r.querySelector('td.verdict').innerText])"
    )
    assert verdicts == [["T1 z", "finite"], ["R1 z", "blocked at order 2 (shaky)"]]
    still, moving = ["meshcat", "pinmob", "glyphs", "R1 z"], ["meshcat", "pinmob", "glyphs", "T1 z"]
    material = "(p) => { const m = viewer.scene_tree.find(p).object.material; return [m.color.getHex(), m.opacity]; }"
    assert page.evaluate(material, [*still, "<object>"]) == [0x9E9E9E, pytest.approx(INSTANTANEOUS_OPACITY)]
    assert page.evaluate(material, [*moving, "<object>"])[0] != 0x9E9E9E
    scale = "(p) => viewer.scene_tree.find(p).object.scale.x"
    seek(page, 0.0)
    start = page.evaluate(scale, still)
    seek(page, 0.25)
    assert page.evaluate(scale, still) > 1.1 * start  # the glyph pulses...
    seek(page, 0.0)
    box = platform_box(page, scene.mobility.platform_origin)
    before = image(page)
    seek(page, 0.5)
    assert (np.abs(image(page) - before).max(axis=2) > 40)[box].mean() > 0  # ...so the clip is not still
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


# --------------------------------------------------------------------------- the panel


NUMBER = re.compile(r"[-+−]?\d+(?:\.\d+)?(?:e[-+]?\d+)?")


def numbers(text: str) -> list[float]:
    """The numbers written in a panel cell ('(0.1, −0.02, 0)' -> [0.1, -0.02, 0.0])."""
    return [float(x.replace("−", "-")) for x in NUMBER.findall(text)]


def panel_rows(page) -> dict[str, dict[str, str]]:
    """Each motion row's cells (label, kind, direction, point, pitch, clip) and its explanation line, from the DOM."""
    return page.evaluate(
        """() => Object.fromEntries(Array.from(document.querySelectorAll('tr.pinmob-motion')).map((row) => {
             const cells = {};
             for (const td of row.querySelectorAll('td')) cells[td.className] = td.innerText.trim();
             const why = document.querySelector(`tr.pinmob-why[data-label="${row.dataset.label}"] .pinmob-reason`);
             cells.why = why.innerText.trim();
             return [row.dataset.label, cells];
           }))"""
    )


def check_panel(page, scene: viewer.Scene, mech: pinmob.Mechanism) -> None:
    """The panel's words, read from the DOM, against the analysis and the followed paths."""
    mob = scene.mobility
    report = pinmob.analyze(mech, mob.configuration)
    text = page.inner_text("#pinmob-panel")
    assert page.inner_text("#pinmob-panel h1") == f"{mech.name} at '{mob.configuration}'"
    assert page.inner_text(".pinmob-dof") == f"{report.dof} DoF"
    assert page.inner_text(".pinmob-type") == report.motion_type
    rows = panel_rows(page)
    assert list(rows) == [m.label for m in report.motions]
    for m in report.motions:
        row, path = rows[m.label], scene.paths[m.label]
        assert row["kind"] == {"T": "translation", "R": "rotation", "H": "screw"}[m.kind.value]
        assert_allclose(numbers(row["direction"]), m.direction, atol=1e-3)
        if m.point is None:
            assert row["point"] == "–"
        else:  # written in world coordinates: the platform origin plus the analysis' relative point
            assert_allclose(
                numbers(row["point"]), report.platform_origin + m.point, rtol=1e-3, atol=1e-3 * mech.length_scale
            )
            assert_allclose(numbers(row["pitch"]), [m.pitch], atol=1e-3 * mech.length_scale)
        if path.complete:
            assert numbers(row["clip"]) == pytest.approx([path.amplitude], rel=5e-3)  # 3 significant digits
            assert "moves the whole amplitude" in row["why"]
        elif path.reached == (0.0, 0.0):
            assert row["clip"] == "stays still" and "exists only to first order" in row["why"]
        else:
            assert [abs(x) for x in numbers(row["clip"])] == pytest.approx(list(path.reached), rel=5e-3)
        for note in path.notes:  # every stop reason of the clip is told, in short, in the row
            if "reaches the edge" in note or "already at the edge" in note:
                limbs = note.split("limb", 1)[1].split(" reach")[0].split(" are")[0].split(" is")[0]
                assert f"limb{limbs}" in row["why"], (note, row["why"])
    sing = report.singularity
    if sing is not None:
        singular = page.inner_text(".pinmob-singularity")
        assert singular.startswith(sing.label.replace("+", " + ") if sing.classes else "none here")
        for limb in sing.limbs:
            assert limb in singular
    chain = report.mechanism_mobility
    mechanism = page.inner_text(".pinmob-mechanism")
    assert mechanism.startswith(f"{chain.mechanism_dof} DoF")
    if chain.internal_dof:
        assert f"+ {chain.internal_dof} internal motion(s)" in mechanism
    assert "Legend" in text and "world axes" in text


def visible_labels(page) -> list[dict]:
    return page.evaluate(
        """() => Array.from(document.querySelectorAll('.pinmob-label')).filter((n) => n.style.display !== 'none')
             .map((n) => { const r = n.getBoundingClientRect();
                           return {text: n.innerText, left: r.left, top: r.top, right: r.right, bottom: r.bottom}; })"""
    )


def check_labels(page, scene: viewer.Scene) -> None:
    """Every motion and world label is drawn inside the view, none overlapping another, and they show on screen."""
    labels = visible_labels(page)
    texts = [b["text"] for b in labels]
    assert set(scene.clips) <= set(texts) and {"x", "y", "z", "world origin"} <= set(texts)
    for b in labels:
        assert 0 <= b["left"] and b["right"] <= WIDTH and 0 <= b["top"] and b["bottom"] <= HEIGHT, b
    for i, a in enumerate(labels):
        for b in labels[i + 1 :]:
            apart = (
                a["right"] <= b["left"] or b["right"] <= a["left"] or a["bottom"] <= b["top"] or b["bottom"] <= a["top"]
            )
            assert apart, (a, b)
    seek(page, 0.0)
    shown = image(page)
    page.click("#pinmob-label-toggle")
    page.wait_for_timeout(300)
    hidden = image(page)
    page.click("#pinmob-label-toggle")
    for b in labels:
        if b["text"] in scene.clips:
            box = (slice(int(b["top"]), int(b["bottom"])), slice(int(b["left"]), int(b["right"])))
            assert (np.abs(shown[box] - hidden[box]).max(axis=2) > 40).mean() > 0.05, f"label {b['text']} not drawn"


def check_rows_play(page, scene: viewer.Scene) -> None:
    """Clicking each row plays its clip and highlights its glyph: the platform moves on screen, or the panel says why not."""
    box = platform_box(page, scene.mobility.platform_origin)
    glyph = "(l) => viewer.scene_tree.find(['meshcat', 'pinmob', 'glyphs', l, '<object>']).object.material.opacity"
    for label in scene.clips:
        page.click(f'tr.pinmob-motion[data-label="{label}"]')
        page.wait_for_timeout(200)
        assert loaded_clips(page) == {label}
        base = INSTANTANEOUS_OPACITY if scene.paths[label].finite is False else 1.0
        assert page.evaluate(glyph, label) == pytest.approx(base)
        assert all(page.evaluate(glyph, other) < 0.3 for other in scene.clips if other != label)
        assert page.get_attribute(f'.pinmob-label.motion[data-label="{label}"]', "class").endswith("selected")
        path = scene.paths[label]
        set_visible(page, ["meshcat", "pinmob", "glyphs"], False)  # the mechanism alone (a still clip's glyph pulses)
        seek(page, 0.0)
        start = image(page)
        # the farther end of the clip (frames: q, +, q, -, q): +amplitude, or as far as it went either way
        f, b = len(path.forward) - 1, len(path.backward) - 1
        seek(page, (f if path.reached[0] >= path.reached[1] else 2 * f + b) / viewer.FPS)
        moved = (np.abs(image(page) - start).max(axis=2) > 40)[box].mean()
        set_visible(page, ["meshcat", "pinmob", "glyphs"], True)
        playing = page.inner_text(".pinmob-playing")
        assert playing.startswith(f"Playing {label}")
        if max(path.reached) > 0:
            assert moved > 0.01, f"{label}: the platform does not move on screen ({moved:.2%})"
        else:
            assert moved == 0.0, f"{label}: a clip that cannot be followed should stay still"
            assert "stays still" in playing and "exists only to first order" in playing


def test_panel_of_the_flat_3puu_says_what_the_analysis_says(browser, flat, tmp_path):
    scene = viewer.export_html(flat, "flat", tmp_path / "flat.html")
    page = open_page(browser, (tmp_path / "flat.html").as_uri())
    check_panel(page, scene, flat)
    rows = panel_rows(page)
    assert rows["R1 z"]["point"] == "(0, 0, 0)" and rows["R1 z"]["clip"] == "stays still"
    assert "limbs A, B, C are already at the edge of their workspace" in rows["R1 z"]["why"]
    check_rows_play(page, scene)
    check_labels(page, scene)
    page.close()


@pytest.mark.parametrize(
    ("name", "config"), [("Delta", "generic"), ("3-UR5", "generic"), ("3-RRR-spherical", "generic")]
)
def test_panel_clicks_and_labels_on_other_mechanisms(browser, tmp_path, name, config):
    # the Delta (loops in its limbs, 3T), three UR5 arms with their meshes (3T3R), and the spherical
    # wrist whose clips stop where a limb reaches the edge of its workspace
    mech = pinmob.load(name)
    scene = viewer.export_html(mech, config, tmp_path / "page.html", steps=6)
    page = open_page(browser, (tmp_path / "page.html").as_uri())
    check_panel(page, scene, mech)
    check_rows_play(page, scene)
    check_labels(page, scene)
    page.close()


def test_panel_on_the_live_page(browser, flat):
    scene = viewer.show(flat, "flat", wrenches=True)
    try:
        page = open_page(browser, scene.url)
        check_panel(page, scene, flat)
        # the constraint wrenches were asked for: their table is there, one row per wrench, lines in world coordinates
        wrenches = page.eval_on_selector_all("tr.pinmob-wrench", "(rows) => rows.map((r) => r.innerText)")
        assert len(wrenches) == len(scene.mobility.constraints) == 4
        assert page.is_visible(".pinmob-wrench-block")
        check_rows_play(page, scene)
        page.close()
    finally:
        scene.server.stop()


def test_world_axes_and_grid_toggle(browser, flat, tmp_path):
    viewer.export_html(flat, "flat", tmp_path / "flat.html", animate=False)
    page = open_page(browser, (tmp_path / "flat.html").as_uri())
    assert page.is_checked("#pinmob-world")
    with_world = image(page)
    page.click("#pinmob-world")
    page.wait_for_timeout(300)
    assert not page.evaluate("viewer.scene_tree.find(['meshcat', 'pinmob', 'world']).object.visible")
    without = image(page)
    assert (np.abs(with_world - without).max(axis=2) > 40).mean() > 0.01  # the grid covers much of the view
    assert not {"x", "y", "z", "world origin"} & {b["text"] for b in visible_labels(page)}
    page.close()


def test_mjcf_gripper_html_in_chromium(browser, tmp_path):
    """The Menagerie xArm7 gripper (MJCF, MuJoCo's meshes, no platform): the exported page draws its meshes
    and animates the frame pinmob shows (the viewer's choice, its most mobile output frame, which the panel names)."""
    mech = pinmob.load(Path(__file__).parent / "data" / "third_party" / "menagerie_xarm7_hand" / "hand.xml")
    viewed, _, note = viewer.viewed_frame(mech, "reference")
    assert "names no platform" in note and viewed.visual_model is not None and viewed.visual_model.ngeoms == 7
    scene = viewer.export_html(mech, "reference", tmp_path / "hand.html")  # the viewer picks the same frame itself
    assert scene.shown_frame == note and scene.mobility.platform == viewed.platform
    page = open_page(browser, (tmp_path / "hand.html").as_uri())
    assert page.inner_text(".pinmob-answer").startswith(f"The output frame '{viewed.platform}' has ")
    visuals = ["meshcat", "pinmob", "mechanism", "visuals"]
    assert page.evaluate("(p) => viewer.scene_tree.find(p).object.children.length", visuals) == 7  # the meshes
    seek(page, 0.0)
    drawn = image(page)
    set_visible(page, ["meshcat", "pinmob"], False)
    empty = image(page)
    set_visible(page, ["meshcat", "pinmob"], True)
    assert (np.abs(drawn - empty).max(axis=2) > 40).mean() > 0.02  # the gripper fills part of the view
    seek(page, (len(scene.paths[scene.visible].forward) - 1) / viewer.FPS)
    assert (np.abs(image(page) - drawn).max(axis=2) > 40).mean() > 0.001  # the fingers moved
    page.close()


def test_3puu_workspace_in_chromium(browser, tmp_path):
    """``pinmob scan 3-PUU --grid`` over x, y, z with ``--html``: the point cloud, colours, marks, legend, mechanism.

    Against the scan's own JSON rows: one point per assembled sample at its platform origin, coloured as
    matplotlib's viridis colours its distance on the log scale between the samples' extremes above rtol (the scale's
    nine stops, linear between: within 0.07), the three singular samples (limb A stretched at x = -0.1,
    y = 0) and the refined points marked; the legend gives units; the mechanism is drawn at ``--sample``.
    Set ``PINMOB_DOCS_SCREENSHOTS=1`` to write docs/img/3puu_workspace.png (the denser grid of docs/viewer.md).
    """
    import json
    import subprocess
    import sys

    from matplotlib import colormaps

    html, out = tmp_path / "workspace.html", tmp_path / "workspace.json"
    grid = ["z:0.22:0.34:3", "x:-0.1:0.1:5", "y:-0.1:0.1:5"]
    proc = subprocess.run(
        [sys.executable, "-m", "pinmob", "scan", "3-PUU", "--grid", *grid, "--sample", "37", "--json", str(out),
         "--html", str(html), "--no-progress"], capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    rows = json.loads(out.read_text())["samples"]
    reach = [r for r in rows if r["reachable"] and not r["refined"]]
    refined = [r for r in rows if r["reachable"] and r["refined"]]
    chosen = next(r for r in reach if r["index"] == 37)
    assert (chosen["grid_x"], chosen["grid_y"], chosen["grid_z"]) == (0.0, 0.0, 0.28)
    assert f"3D view: {len(reach)} assembled samples beside the mechanism at sample #37" in proc.stdout

    page = open_page(browser, html.as_uri())
    cloud = "(n) => { const g = viewer.scene_tree.find(['meshcat', 'pinmob', 'workspace', n, '<object>']).object" \
        ".geometry.attributes; return [Array.from(g.position.array), Array.from(g.color.array)]; }"  # fmt: skip
    position, color = (np.reshape(a, (-1, 3)) for a in page.evaluate(cloud, "samples"))
    # the points in the page's scene: the assembled samples, as many as the hand rule reaches (3-PUU: R = 0.3 m,
    # r = 0.15 m, links 0.25 m: a translation (x, y) assembles iff |(x, y) - 0.15 e_i| <= 0.25 for each limb i)
    guides = 0.15 * np.array([[np.cos(a), np.sin(a)] for a in (0.0, 2 * np.pi / 3, 4 * np.pi / 3)])
    xy = np.stack(np.meshgrid(np.linspace(-0.1, 0.1, 5), np.linspace(-0.1, 0.1, 5)), -1).reshape(-1, 1, 2)
    hand = 3 * int(np.all(np.linalg.norm(xy - guides, axis=2) <= 0.25 + 1e-9, axis=1).sum())
    assert len(position) == len(reach) == hand
    assert_allclose(position, [[r["x"], r["y"], r["z"]] for r in reach], atol=1e-6)
    d = np.array([r["distance"] for r in reach])
    lo, hi = d[d > 1e-6].min(), d.max()
    t = (np.log10(np.clip(d, lo, hi)) - np.log10(lo)) / (np.log10(hi) - np.log10(lo))
    assert_allclose(color, colormaps["viridis"](t)[:, :3], atol=0.07)
    singular = np.reshape(page.evaluate(cloud, "singular")[0], (-1, 3))
    assert_allclose(singular, [[r["x"], r["y"], r["z"]] for r in reach if r["distance"] <= 1e-6], atol=1e-6)
    assert len(singular) == 3 and np.allclose(singular[:, :2], [-0.1, 0.0], atol=1e-6)
    assert len(page.evaluate(cloud, "refined")[0]) == 3 * len(refined) > 0
    assert_allclose(page.evaluate(cloud, "chosen")[0], [chosen["x"], chosen["y"], chosen["z"]], atol=1e-6)

    legend = page.inner_text(".pinmob-workspace")
    for words in (f"{len(reach)} of 75 samples assembled", "grid x [m]: -0.1 to 0.1, 5 values",
                  "platform origin x, y, z [m]", "dimensionless", f"refined singular point: {len(refined)}",
                  "singular sample (distance <= rtol = 1e-06): 3", f"{lo:.3g}", f"{hi:.3g}"):  # fmt: skip
        assert words in legend, (words, legend)

    # the mechanism is drawn at the chosen sample: its platform's region changes when the mechanism is hidden
    seek(page, 0.0)
    box = platform_box(page, np.array([chosen["x"], chosen["y"], chosen["z"]]))
    workspace = ["meshcat", "pinmob", "workspace"]
    set_visible(page, workspace, False)
    drawn = image(page)
    set_visible(page, ["meshcat", "pinmob", "mechanism"], False)
    bare = image(page)
    assert (np.abs(drawn - bare).max(axis=2) > 40)[box].mean() > 0.08
    set_visible(page, workspace, True)  # and the cloud is drawn: with the mechanism hidden, it shows
    cloud_only = image(page)
    assert (np.abs(cloud_only - bare).max(axis=2) > 40).mean() > 0.002
    page.close()
    if os.environ.get("PINMOB_DOCS_SCREENSHOTS"):  # the denser grid of docs/viewer.md
        grid = ["z:0.2:0.36:5", "x:-0.12:0.14:14", "y:-0.14:0.14:15"]
        command = ["scan", "3-PUU", "--grid", *grid, "--sample", "517", "--html", str(tmp_path / "docs.html")]
        subprocess.run([sys.executable, "-m", "pinmob", *command], check=True, capture_output=True, timeout=300)
        page = open_page(browser, (tmp_path / "docs.html").as_uri())
        seek(page, 0.0)
        page.screenshot(path=str(DOCS / "img" / "3puu_workspace.png"))
        page.close()


def test_workspace_on_the_live_page(browser):
    """``viewer.show(..., workspace=...)`` (what ``pinmob scan --show`` sends): the live page draws the cloud.

    A 3 x 3 x 2 grid of the 3-PUU well inside its reach (|(x, y) - 0.15 e_i| <= 0.25 for every sample): all 18
    samples are points of the page's scene, and the panel's workspace section says so.
    """
    from pinmob.scan import grid_spec, scan

    mech = pinmob.load("3-PUU")
    spec = grid_spec(mech, "generic", [("x", -0.05, 0.05, 3), ("y", -0.05, 0.05, 3), ("z", 0.26, 0.3, 2)])
    ws = viewer.workspace_cloud(list(scan(mech, spec, progress=False)), spec.rtol)
    scene = viewer.show(mech, "generic", workspace=ws)
    try:
        page = open_page(browser, scene.url)
        samples = "viewer.scene_tree.find(['meshcat', 'pinmob', 'workspace', 'samples', '<object>'])"
        assert page.evaluate(samples + ".object.geometry.attributes.position.count") == 18
        assert "Workspace: 18 of 18 samples assembled" in page.inner_text(".pinmob-workspace")
        page.close()
    finally:
        scene.server.stop()


def test_viewer_in_a_notebook_cell_plays(browser, flat, tmp_path):
    """pinmob.viewer.notebook's iframe in a page with no charset (a cell's output): the scene loads and plays, the
    panel's text is read right (ASCII character references) and the mechanism is drawn; nothing is fetched."""
    from PIL import Image

    cell = viewer.notebook(pinmob.analyze(flat, "flat"), height=600)
    (tmp_path / "cell.html").write_bytes(
        b"<html><body><p>cell</p>" + cell._repr_html_().encode("ascii") + b"</body></html>"
    )
    page = browser.new_page(viewport={"width": WIDTH, "height": HEIGHT})
    errors: list[str] = []
    requests: list[str] = []
    page.on("pageerror", lambda e: errors.append(str(e)))
    page.on("request", lambda r: requests.append(r.url))
    page.goto((tmp_path / "cell.html").as_uri())
    frame = page.frames[1]
    frame.wait_for_function("window.pinmob && pinmob.state && viewer.animator.actions.length > 0", timeout=20000)
    frame.wait_for_timeout(500)
    assert errors == [] and requests == [(tmp_path / "cell.html").as_uri()], (errors, requests)
    assert loaded_clips(frame) == {"T1 z"} and frame.evaluate("viewer.animator.playing")
    rows = frame.eval_on_selector_all("tr.pinmob-motion", "(rows) => rows.map((r) => r.dataset.label)")
    assert rows == ["T1 z", "R1 z"]
    text = frame.inner_text("body")
    assert "±0.0424 m" in text and "â€" not in text, text  # UTF-8 read as such in a page of another encoding
    # the mechanism is drawn: hiding it changes the iframe's pixels
    shot = page.query_selector("iframe")
    assert shot is not None
    drawn = np.asarray(Image.open(io.BytesIO(shot.screenshot())).convert("RGB")).astype(int)
    frame.evaluate("viewer.scene_tree.find(['meshcat', 'pinmob']).set_property('visible', false); viewer.set_dirty();")
    frame.wait_for_timeout(300)
    empty = np.asarray(Image.open(io.BytesIO(shot.screenshot())).convert("RGB")).astype(int)
    assert (np.abs(drawn - empty).max(axis=2) > 40).mean() > 0.02
    page.close()
