"""Viewer without a browser: HTML export, files never overwritten by surprise, clear errors, no hang."""

from __future__ import annotations

import selectors
import socket
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from processes import children

import pinmob
from pinmob import viewer
from pinmob.exceptions import ViewerError

PINMOB = [sys.executable, "-m", "pinmob"]


@pytest.fixture(scope="module")
def flat() -> pinmob.Mechanism:
    return pinmob.load("3-PUU-flat")


def run(*args: str, timeout: float = 60) -> subprocess.CompletedProcess:
    return subprocess.run([*PINMOB, *args], capture_output=True, text=True, timeout=timeout)


def test_import_pinmob_does_not_import_meshcat():
    code = "import sys, pinmob, pinmob.analysis.follow.motion_path, pinmob.viewer.skeleton, pinmob.viewer.glyphs; print('meshcat' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.stdout.strip() == "False", out.stderr


def test_export_html_holds_every_clip(flat, tmp_path):
    target = tmp_path / "flat.html"
    scene = viewer.export_html(flat, "flat", target)
    assert scene.clips == ("T1 z", "R1 z") and scene.visible == "T1 z"
    assert scene.generated_geometry and scene.html == target
    text = target.read_text()
    assert "MeshCat.Viewer" in text and "handle_command_bytearray" in text
    assert "ws://" not in text.split("pinmob_commands")[1]  # no server needed
    assert any("R1 z" in n for n in scene.notes)


def test_export_html_never_overwrites_without_permission(flat, tmp_path):
    target = tmp_path / "mine.html"
    target.write_text("user data")
    with pytest.raises(ViewerError, match="exists already"):
        viewer.export_html(flat, "flat", target)
    assert target.read_text() == "user data"
    out = run("show", "3-PUU-flat", "--config", "flat", "--html", str(target))
    assert out.returncode == 2 and "exists already" in out.stderr and "Traceback" not in out.stderr
    assert target.read_text() == "user data"
    assert list(tmp_path.iterdir()) == [target]  # no temporary file left behind
    out = run("show", "3-PUU-flat", "--config", "flat", "--html", str(target), "--force")
    assert out.returncode == 0, out.stderr
    assert "MeshCat.Viewer" in target.read_text()
    assert f"wrote {target}" in out.stdout and "clip 'T1 z'" in out.stdout


def test_unknown_motion_is_named(flat, tmp_path):
    with pytest.raises(pinmob.ConfigurationError, match="'R1 z', 'T1 z'"):
        viewer.export_html(flat, "flat", tmp_path / "x.html", motion="T9 q")
    assert not (tmp_path / "x.html").exists()


def test_mechanism_that_does_not_close(tmp_path):
    src = Path(pinmob.builtin_models()["3-PUU"])
    (tmp_path / "3puu.urdf").write_text((src.parent / "3puu.urdf").read_text())
    text = src.read_text() + "\n[configurations.broken]\njoints = { A_slider = 0.05 }\n"
    (tmp_path / "broken.toml").write_text(text)
    start = time.monotonic()
    out = run("show", str(tmp_path / "broken.toml"), "--config", "broken")
    assert out.returncode == 2 and "does not close" in out.stderr and "Traceback" not in out.stderr
    assert time.monotonic() - start < 30


def test_port_in_use_is_a_clear_error():
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        start = time.monotonic()
        out = run("show", "3-PUU", "--port", str(port))
    assert out.returncode == 2, out.stdout
    assert f"web port {port} on 127.0.0.1 is in use" in out.stderr and "Traceback" not in out.stderr
    assert time.monotonic() - start < 30


def test_no_server_at_zmq_url_is_a_clear_error():
    port = _free_port()  # nobody listens on it
    start = time.monotonic()
    out = run("show", "3-PUU", "--zmq-url", f"tcp://127.0.0.1:{port}")
    assert out.returncode == 2 and "no meshcat server answers" in out.stderr
    assert time.monotonic() - start < 30


def test_meshcat_missing_is_a_clear_error(tmp_path):
    code = (
        "import sys; sys.modules['meshcat'] = None\n"
        "from pinmob.cli import main\n"
        f"raise SystemExit(main(['show', '3-PUU', '--html', {str(tmp_path / 'x.html')!r}]))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert out.returncode == 2 and "needs meshcat" in out.stderr and "pip install meshcat" in out.stderr
    assert not (tmp_path / "x.html").exists()


def test_show_sends_to_a_running_server_and_returns():
    from pinmob.viewer.server import probe, start_server

    server = start_server()
    try:
        start = time.monotonic()
        out = run("show", "3-PUU", "--zmq-url", server.zmq_url, "--motion", "T2 y")
        assert out.returncode == 0, out.stderr
        assert f"open {server.web_url}" in out.stdout and "clip 'T2 y'" in out.stdout
        assert time.monotonic() - start < 30  # returns: the server is not ours to wait on
        assert probe(server.zmq_url) == server.web_url  # the server still runs
    finally:
        server.stop()
    assert server.process.poll() is not None


def _distance_to_line(points: np.ndarray, through: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Distance [m] of each point (k, 3) from the line through ``through`` along unit ``direction``."""
    rel = points - through
    return np.linalg.norm(rel - np.outer(rel @ direction, direction), axis=1)


@pytest.mark.parametrize(
    ("name", "config", "centre"),
    [
        # all nine revolute axes meet at O = (0, 0, 0) (the model's geometry): every free
        # rotation of the platform is about a line through O, whatever the platform origin
        ("3-RRR-spherical", "generic", None),
        # 3T3R: any line can be shifted by the free translations, so the axis point closest
        # to the platform origin is the origin itself, which is away from the world origin
        ("6-UPS", "generic", "platform"),
    ],
)
def test_rotation_glyph_axis_passes_through_the_world_point(name, config, centre):
    from pinmob.viewer.glyphs import motion_glyph

    mech = pinmob.load(name)
    mob = pinmob.analyze(mech, config)
    origin = mob.platform_origin
    assert np.linalg.norm(origin) > 0.2  # the platform origin is far from the world origin
    through = origin if centre == "platform" else np.zeros(3)
    rotations = [m for m in mob.motions if m.kind is pinmob.MotionKind.ROTATION]
    assert len(rotations) == 3
    tube = 0.6 * 0.02 * mech.length_scale  # radius of the axis line (glyphs.py: 0.6 r, r = 0.02 L)
    for m in rotations:
        glyph = motion_glyph(m, origin, mech.length_scale)
        on_axis = np.abs(_distance_to_line(glyph.vertices, through, m.direction) - tube) < 1e-9
        assert on_axis.sum() >= 24, f"{m.label}: the axis line is not through {through}"


def test_couples_and_translations_keep_clear_of_each_other_and_of_the_axes():
    # 3-PUU (paper eq. 38): 3T, constrained by three couples along the same x, y, z as the
    # translations; 3-UR5: 3T3R, three rotation axes through the platform origin along the same
    # x, y, z as the translations. Each arrow is a shaft with a cone of radius 2.2 r (r = 0.02 L for
    # motions, 0.015 L for wrenches): a couple arrow must keep clear of every translation arrow's
    # line, and a translation arrow of every rotation axis, by more than the cone radii.
    from pinmob.viewer.glyphs import constraint_glyph, free_vector_start, motion_glyph

    for name, config in (("3-PUU", "generic"), ("3-UR5", "generic")):
        mech = pinmob.load(name)
        mob = pinmob.analyze(mech, config)
        origin, length = mob.platform_origin, mech.length_scale
        start = free_vector_start(mob.motions, origin, length)
        couples = free_vector_start(mob.motions, origin, length, side=-1.0)
        clearance = 2.2 * 0.02 * length + 2.2 * 0.015 * length
        translations = [m for m in mob.motions if m.kind is pinmob.MotionKind.TRANSLATION]
        for i, c in enumerate(mob.constraints):
            couple = constraint_glyph(c, i, origin, length, couples)
            for m in translations:
                gap = _distance_to_line(couple.vertices, start, m.direction).min()
                assert gap > clearance, f"{name}: couple {i + 1} touches {m.label} ({gap / length:.3f} L)"
        for m in translations:
            arrow = motion_glyph(m, origin, length, start)
            for r in (r for r in mob.motions if r.point is not None):
                gap = _distance_to_line(arrow.vertices, origin + r.point, r.direction).min()
                assert gap > 2.2 * 0.02 * length, f"{name}: {m.label} lies on the axis of {r.label}"


@pytest.mark.parametrize("port", ["99999", "0", "-5", "65536"])
def test_port_outside_the_valid_range_is_a_clear_error(port):
    start = time.monotonic()
    out = run("show", "3-PUU", f"--port={port}")
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert out.stderr.strip() == f"pinmob: error: port must be an integer from 1 to 65535, got {int(port)}"
    assert time.monotonic() - start < 30


def test_unknown_motion_is_refused_before_any_server_starts():
    # with the web port taken, a server would fail to start: the motion error must come first
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        out = run("show", "3-PUU", "--port", str(port), "--motion", "T9 q")
    assert out.returncode == 2 and "no free motion 'T9 q'" in out.stderr and "'T1 x', 'T2 y', 'T3 z'" in out.stderr
    assert "in use" not in out.stderr


def test_server_listens_on_loopback_only():
    # 127.0.0.2 is a loopback address too: a server bound to every interface (0.0.0.0)
    # accepts connections there, one bound to 127.0.0.1 refuses them
    from pinmob.viewer.server import start_server

    server = start_server()
    try:
        port = int(server.web_url.rsplit(":", 1)[1].split("/")[0])
        with socket.create_connection(("127.0.0.1", port), timeout=5):
            pass
        with pytest.raises(ConnectionRefusedError), socket.create_connection(("127.0.0.2", port), timeout=5):
            pass
    finally:
        server.stop()


def test_three_ur5_html_defines_each_mesh_once(tmp_path):
    # 3-UR5: three UR5 arms with example-robot-data's meshes, 6 free motions (3T3R). Each of
    # the 21 visual meshes is sent once (not once per clip) and the page is compressed: the
    # file must stay below 3 times the size of the mesh files it draws.
    mech = pinmob.load("3-UR5")
    meshes = {g.meshPath for g in mech.visual_model.geometryObjects}
    mesh_bytes = sum(Path(m).stat().st_size for m in meshes)
    scene = viewer.export_html(mech, "generic", tmp_path / "ur5.html", steps=4)
    assert not scene.generated_geometry and len(scene.clips) == 6
    size = (tmp_path / "ur5.html").stat().st_size
    print(f"3-UR5 HTML: {size / 1e6:.2f} MB for {mesh_bytes / 1e6:.2f} MB of mesh files ({size / mesh_bytes:.2f}x)")
    assert size < 3 * mesh_bytes


def _messages_to_a_new_browser(web_url: str, quiet: float = 2.0) -> list[dict]:
    """The commands meshcat's server sends a browser that connects now (a real websocket client)."""
    import asyncio

    import umsgpack
    from tornado.websocket import websocket_connect

    port = int(web_url.rsplit(":", 1)[1].split("/")[0])

    async def read() -> list[dict]:
        ws = await websocket_connect(f"ws://127.0.0.1:{port}/")
        out = []
        while True:
            try:
                message = await asyncio.wait_for(ws.read_message(), quiet)
            except TimeoutError:
                break
            if message is None:
                break
            out.append(umsgpack.unpackb(message))
        ws.close()
        return out

    return asyncio.run(read())


def test_a_rigid_scene_replaces_the_previous_clips_and_panel_on_a_reused_server():
    # 3-PUU (3 motions) then the Delta with its arms stretched (rigid: no motion) on one server:
    # a browser that connects afterwards must get neither the 3-PUU's clip nor its panel
    from pinmob.viewer.server import start_server

    server = start_server()
    try:
        viewer.show(pinmob.load("3-PUU"), "generic", zmq_url=server.zmq_url, steps=2)
        before = _messages_to_a_new_browser(server.web_url)
        (panel,) = [m["document"] for m in before if m["type"] == "pinmob_panel"]
        assert [m["label"] for m in panel["motions"]] == ["T1 x", "T2 y", "T3 z"] and set(panel["clips"]) == {
            "T1 x",
            "T2 y",
            "T3 z",
        }
        assert before[-1]["type"] == "pinmob_panel"  # after the scene it describes
        assert any(m["type"] == "set_animation" and m["animations"] for m in before)
        scene = viewer.show(pinmob.load("Delta"), "arms-stretched", zmq_url=server.zmq_url, steps=2)
        assert scene.mobility.dof == 0 and scene.clips == () and scene.panel_shown
        after = _messages_to_a_new_browser(server.web_url)
        (panel,) = [m["document"] for m in after if m["type"] == "pinmob_panel"]
        assert panel["title"] == "Delta at 'arms-stretched'" and panel["motions"] == [] and panel["clips"] == {}
        assert [m["animations"] for m in after if m["type"] == "set_animation"] == [[]]
        assert any(m["type"] == "set_object" for m in after)  # the Delta itself is there
        assert not any("3-PUU" in str(m.get("path", "")) for m in after)
    finally:
        server.stop()


def test_a_plain_meshcat_server_shows_the_scene_without_the_panel_and_says_so(tmp_path):
    # meshcat's own server (what `meshcat-server` runs) keeps meshcat's commands only: the scene goes
    # there, the panel is refused, and pinmob says so instead of failing
    from pinmob.viewer.server import probe

    zmq_url = f"tcp://127.0.0.1:{_free_port()}"
    proc = subprocess.Popen(
        [sys.executable, "-m", "meshcat.servers.zmqserver", "--zmq-url", zmq_url],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 30
        while True:
            try:
                probe(zmq_url, timeout=1.0)
                break
            except ViewerError:
                assert time.monotonic() < deadline, "meshcat's server did not start"
        out = run("show", "3-PUU", "--zmq-url", zmq_url, "--steps", "2")
        assert out.returncode == 0, out.stderr
        assert f"note: the meshcat server at {zmq_url} is not pinmob's" in out.stdout
    finally:
        proc.terminate()
        proc.wait(10)


def test_the_installed_meshcat_is_in_the_declared_range():
    # pinmob's page drives meshcat's viewer script (handle_command, scene_tree, animator, camera): it is
    # declared for the meshcat versions it is written and tested against, and those are what runs here
    import importlib.metadata

    from packaging.requirements import Requirement

    (spec,) = [Requirement(r) for r in importlib.metadata.requires("pinmob") if r.startswith("meshcat")]
    assert str(spec.specifier) in ("<0.4,>=0.3.2", ">=0.3.2,<0.4")
    assert importlib.metadata.version("meshcat") in spec.specifier


def _free_port() -> int:
    """A TCP port on 127.0.0.1 that nobody listens on now."""
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _read_until(proc: subprocess.Popen, pattern: bytes, timeout: float = 90) -> bytes:
    """proc's stdout until a line matches ``pattern`` (raw reads: no buffering hides a line from select)."""
    import os
    import re

    assert proc.stdout is not None
    out, deadline = b"", time.monotonic() + timeout
    with selectors.DefaultSelector() as sel:
        sel.register(proc.stdout, selectors.EVENT_READ)
        while not re.search(pattern, out, re.M) and time.monotonic() < deadline:
            if sel.select(timeout=1):
                chunk = os.read(proc.stdout.fileno(), 4096)
                if not chunk:
                    break
                out += chunk
    assert re.search(pattern, out, re.M), f"no line matching {pattern!r} within {timeout} s: {out.decode()!r}"
    return out


@pytest.mark.parametrize(
    "model,when,status",
    [
        ("3-PUU", "serving", 0),  # stopped while serving: ends as after Ctrl-C, status 0
        ("3-UR5", "sending", 130),  # its meshes take a second or more to send: interrupted, status 130
    ],
)
def test_sigterm_stops_the_server_it_started(model, when, status):
    # `pinmob show` without --detach serves until stopped; a SIGTERM (a service manager, `timeout`, a
    # closed session), while it serves or while it still sends the scene, must end the meshcat server it
    # started, as Ctrl-C does, not leave it orphaned. The server is found in the process table; while
    # serving, pinmob's own line names that same pid.
    import os
    import signal

    proc = subprocess.Popen([*PINMOB, "show", model, "--port", str(_free_port())], stdout=subprocess.PIPE)
    servers: list[int] = []
    try:
        deadline = time.monotonic() + 90
        while not servers and time.monotonic() < deadline and proc.poll() is None:
            servers = children(proc.pid)
            time.sleep(0.02)
        assert len(servers) == 1, f"expected one meshcat server, found {servers}"
        if when == "serving":
            _read_until(proc, rb"^serving \(meshcat server pid %d\)" % servers[0])
        else:
            time.sleep(0.2)
        proc.send_signal(signal.SIGTERM)
        assert proc.wait(timeout=30) == status
        assert not Path(f"/proc/{servers[0]}").exists(), "the meshcat server was left running"
    finally:
        proc.kill()
        proc.wait()
        for pid in servers:
            try:
                os.kill(pid, signal.SIGKILL)
            except ProcessLookupError:
                pass


def test_panel_document_of_the_spherical_wrist(tmp_path):
    # 3-RRR-spherical at 'generic': three rotations about O = (0, 0, 0), each clip stopped by a limb
    # reaching the edge of its workspace; the panel says so in short, per direction, and names the centre
    scene = viewer.export_html(pinmob.load("3-RRR-spherical"), "generic", tmp_path / "s.html", steps=12)
    doc = scene.panel
    assert doc["answer"] == {"dof": 3, "motion_type": "3R", "words": "3 rotations"}
    assert "The 3 rotation axes meet at (0, 0, 0) m: the platform turns about that point." in doc["summary"]
    rows = {r["label"]: r for r in doc["motions"]}
    assert [r["status"] for r in rows.values()] == ["partial"] * 3
    assert rows["R1 x"]["why"][0].startswith("forwards, limb A reaches the edge of its workspace")
    assert rows["R1 x"]["why"][1].startswith("backwards, limb C reaches the edge of its workspace")
    assert len(rows["R3 z"]["why"]) == 1 and rows["R3 z"]["why"][0].startswith("forwards, limb A reaches")
    for r in rows.values():
        assert len(r["notes"]) == len(r["why"]) and all(note in " ".join(scene.notes) for note in r["notes"])
        assert r["point"] is not None and abs(np.cross(r["point"], r["direction"])).max() < 1e-9  # through O


def test_panel_names_the_branches_meeting_at_a_branch_point(tmp_path):
    """The 4-RUU at its parallel-axes configuration is kinematotropic (tests/test_finite.py follows each branch 0.3
    rad): its Schoenflies mode (4 DoF, 3T1R) and a 2-DoF mode (2R) meet. The panel's summary says so, as the text
    and the JSON do; a regular configuration's panel has no such line."""
    target = tmp_path / "ruu.html"
    scene = viewer.export_html(pinmob.load("4-RUU"), "parallel-axes", target, steps=2)
    line = "Motion branches meet here: a 4-DoF and a 2-DoF branch meet: 3T1R and 2R"
    assert any(s.startswith(line) for s in scene.panel["summary"]), scene.panel["summary"]
    regular = viewer.export_html(pinmob.load("4-RUU"), "generic", tmp_path / "g.html", steps=2)
    assert not any("branches meet" in s for s in regular.panel["summary"])


def test_sigkill_of_show_stops_the_server_it_started():
    """SIGKILL cannot be handled: the server notices that its parent is gone (issue 14) and ends within seconds;
    with --detach it is meant to outlive pinmob and does."""
    import os
    import signal

    for detach in (False, True):
        proc = subprocess.Popen(
            [*PINMOB, "show", "3-PUU", "--port", str(_free_port()), *(["--detach"] if detach else [])],
            stdout=subprocess.PIPE,
        )
        servers: list[int] = []
        try:
            out = _read_until(proc, rb"meshcat server (keeps running \()?pid \d+")
            servers = [int(x) for x in __import__("re").findall(rb"pid (\d+)", out)[:1]]
            assert servers and Path(f"/proc/{servers[0]}").exists()
            proc.kill()
            proc.wait()
            deadline = time.monotonic() + 10
            while Path(f"/proc/{servers[0]}").exists() and time.monotonic() < deadline:
                time.sleep(0.1)
                try:
                    os.waitpid(servers[0], os.WNOHANG)  # reaped here if it was re-parented to this test
                except ChildProcessError:
                    pass
            alive = (
                Path(f"/proc/{servers[0]}").exists() and "zombie" not in Path(f"/proc/{servers[0]}/status").read_text()
            )
            assert alive == detach, "the meshcat server was left running" if alive else "the detached server stopped"
        finally:
            for pid in servers:
                try:
                    os.kill(pid, signal.SIGKILL)
                except ProcessLookupError:
                    pass


def test_a_mechanism_without_platform_is_shown_by_its_output_frame_and_the_panel_says_so(tmp_path):
    """MJCF four-bar without a platform: the viewer itself shows its output frame (the rocker: the leaf body that
    turns with the one DoF) and every sentence of the panel names that frame, not "the platform" (issue 34)."""
    mech = pinmob.load(Path(__file__).parent / "data" / "fourbar_weld.xml")
    assert not mech.has_platform
    scene = viewer.export_html(mech, "reference", tmp_path / "f.html", steps=2)
    doc = scene.panel
    assert scene.shown_frame.startswith("'fourbar-weld' names no platform: showing the motions of its output frame")
    assert doc["subject"] == "the output frame 'rocker'" and doc["answer"]["dof"] == 1
    text = repr({k: doc[k] for k in ("summary", "singularity", "mechanism", "legend")})
    assert "platform" not in text.replace("names no platform", "")
    assert "the output frame 'rocker'" in doc["mechanism"]
    with_platform = viewer.export_html(pinmob.load("3-PUU"), "generic", tmp_path / "p.html", animate=False)
    assert with_platform.panel["subject"] == "the platform" and with_platform.shown_frame == ""


def test_viewer_options_are_declared_once_and_a_wrong_one_is_named(flat, tmp_path):
    """Every viewer function takes the options of ViewOptions as keywords, with its defaults; a misspelt option is
    one error naming it and the valid ones, before anything is computed."""
    import inspect

    for function in (viewer.show, viewer.export_html, viewer.scene_html, viewer.notebook):
        signature = inspect.signature(function)
        assert not set(viewer.VIEW_OPTIONS) & set(signature.parameters), function.__name__  # not declared again
    with pytest.raises(pinmob.ArgumentError, match=r"unknown viewer option 'step' \(did you mean 'steps'\?\); valid: "):
        viewer.export_html(flat, "flat", tmp_path / "x.html", step=3)
    assert not (tmp_path / "x.html").exists()
    assert viewer.ViewOptions().steps == 12 and viewer.ViewOptions().finite is True
