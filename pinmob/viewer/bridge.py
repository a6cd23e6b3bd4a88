"""pinmob's meshcat server: meshcat's command protocol over ZeroMQ, pinmob's page and the scene over HTTP.

Built on tornado and pyzmq (meshcat's own dependencies) and meshcat's public
viewer assets (``meshcat.viewer_assets_path()``): no class of meshcat's server
is subclassed or patched. It speaks the protocol of meshcat's Python client
(``meshcat.Visualizer(zmq_url=...)``) on a ZeroMQ REP socket:

- ``url``: replies with the page's URL; ``wait``: replies ``ok`` once a browser is connected;
- ``[type, path, msgpack data]`` for meshcat's commands ``set_object``,
  ``set_transform``, ``set_property``, ``set_animation``, ``delete`` and
  pinmob's ``pinmob_panel``: forwarded to every connected browser and kept in a
  scene tree (:class:`SceneStore`) for the browsers that connect later; replies ``ok``;
- anything else: replies ``error: unrecognized command``.

Over HTTP, on 127.0.0.1 only: the page at ``/static/``
(:func:`pinmob.viewer.page.live_page`: meshcat's viewer with pinmob's panel),
meshcat's script at ``/static/main.min.js`` and the websocket at ``/`` (where
meshcat's viewer connects by default).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from typing import Any

import tornado.ioloop
import tornado.web
import tornado.websocket
import umsgpack
import zmq
from zmq.eventloop.zmqstream import ZMQStream

from pinmob.viewer.page import live_page, meshcat_script

HOST = "127.0.0.1"
#: commands kept for later browsers (meshcat's and pinmob's panel)
SCENE_COMMANDS = ("set_object", "set_transform", "set_property", "set_animation", "delete", "pinmob_panel")
#: the first ports tried when none is given, and how many after them
WEB_PORT, ZMQ_PORT, ATTEMPTS = 7000, 6000, 1000


@dataclass
class _Node:
    object: bytes | None = None
    transform: bytes | None = None
    properties: dict[str, bytes] = field(default_factory=dict)
    animation: bytes | None = None
    children: dict[str, _Node] = field(default_factory=dict)


class SceneStore:
    """The scene as the commands that rebuild it: a tree of paths, each with its object, transform and properties.

    Like meshcat's own server: a node keeps its last object, transform and
    animation and the last value of each property; ``delete`` drops a subtree
    (the root: everything, the panel too). The panel is replayed last, after the
    scene it describes.
    """

    def __init__(self) -> None:
        self.root = _Node()
        self.panel: bytes | None = None

    def _node(self, path: str) -> _Node:
        node = self.root
        for part in (p for p in path.split("/") if p):
            node = node.children.setdefault(part, _Node())
        return node

    def keep(self, kind: str, path: str, data: bytes) -> None:
        """Remember one command of ``SCENE_COMMANDS``."""
        if kind == "pinmob_panel":
            self.panel = data
        elif kind == "delete":
            parts = [p for p in path.split("/") if p]
            if not parts:
                self.root, self.panel = _Node(), None
            else:
                self._node("/".join(parts[:-1])).children.pop(parts[-1], None)
        elif kind == "set_object":
            node = self._node(path)
            node.object, node.properties = data, {}
        elif kind == "set_transform":
            self._node(path).transform = data
        elif kind == "set_animation":
            self._node(path).animation = data
        elif kind == "set_property":
            self._node(path).properties[str(umsgpack.unpackb(data).get("property"))] = data

    def commands(self) -> list[bytes]:
        """Every command that rebuilds the scene, parents first, the panel last."""
        out: list[bytes] = []
        stack = [self.root]
        while stack:
            node = stack.pop(0)
            out += [c for c in (node.object, *node.properties.values(), node.transform, node.animation) if c]
            stack = list(node.children.values()) + stack
        return out + ([self.panel] if self.panel else [])


class Bridge:
    """The server: a ZeroMQ socket for commands, a tornado application for browsers (see the module docstring).

    Raises:
        OSError: the web port is in use (``port`` given) or no port from 7000 is free.
        zmq.ZMQError: the command port is in use.
    """

    def __init__(self, port: int | None = None, zmq_port: int | None = None) -> None:
        self.store = SceneStore()
        self.browsers: set[tornado.websocket.WebSocketHandler] = set()
        self.waiting = False
        self.app = tornado.web.Application(
            [
                (r"/static/main\.min\.js", _Script),
                (r"/static/(?:index\.html)?", _Page),
                (r"/favicon\.ico", _NoContent),
                (r"/", _Socket, {"bridge": self}),
            ]
        )
        self.web_port = self._listen(port)
        self.zmq_socket: zmq.Socket[bytes] = zmq.Context.instance().socket(zmq.REP)
        self.zmq_port = self._bind(zmq_port)
        self.stream = ZMQStream(self.zmq_socket)
        self.stream.on_recv(self.handle)

    @property
    def zmq_url(self) -> str:
        """Where meshcat's Python client sends commands."""
        return f"tcp://{HOST}:{self.zmq_port}"

    @property
    def web_url(self) -> str:
        """The page to open in a browser."""
        return f"http://{HOST}:{self.web_port}/static/"

    def _listen(self, port: int | None) -> int:
        for candidate in [port] if port is not None else range(WEB_PORT, WEB_PORT + ATTEMPTS):
            try:
                self.app.listen(candidate, address=HOST)
                return int(candidate)
            except OSError:
                if port is not None:
                    raise
        raise OSError(f"no free web port from {WEB_PORT} to {WEB_PORT + ATTEMPTS - 1}")

    def _bind(self, port: int | None) -> int:
        for candidate in [port] if port is not None else range(ZMQ_PORT, ZMQ_PORT + ATTEMPTS):
            try:
                self.zmq_socket.bind(f"tcp://{HOST}:{candidate}")
                return int(candidate)
            except zmq.ZMQError:
                if port is not None:
                    raise
        raise zmq.ZMQError(msg=f"no free command port from {ZMQ_PORT} to {ZMQ_PORT + ATTEMPTS - 1}")

    def handle(self, frames: list[bytes]) -> None:
        """One request of meshcat's client (see the module docstring)."""
        kind = frames[0].decode(errors="replace")
        if kind == "url":
            self.zmq_socket.send(self.web_url.encode())
        elif kind == "wait":
            self._reply_when_connected()
        elif kind in SCENE_COMMANDS and len(frames) == 3:
            self.store.keep(kind, frames[1].decode(errors="replace"), frames[2])
            for browser in list(self.browsers):
                browser.write_message(frames[2], binary=True)
            self.zmq_socket.send(b"ok")
        else:
            self.zmq_socket.send(b"error: unrecognized command")

    def _reply_when_connected(self) -> None:
        if self.browsers:
            self.zmq_socket.send(b"ok")
        else:
            tornado.ioloop.IOLoop.current().call_later(0.1, self._reply_when_connected)

    def stop_with(self, parent: int) -> None:
        """Stop serving when process ``parent`` (this process's parent) has ended, checked twice a second.

        An ended parent leaves this process to another (``os.getppid()`` changes), whatever ended it.
        """

        def check() -> None:
            if os.getppid() != parent:
                tornado.ioloop.IOLoop.current().stop()

        tornado.ioloop.PeriodicCallback(check, 500).start()
        check()

    def run(self) -> None:
        """Serve until the process is stopped."""
        tornado.ioloop.IOLoop.current().start()


class _Page(tornado.web.RequestHandler):
    def get(self) -> None:
        self.set_header("Cache-Control", "no-store")
        self.write(live_page())


class _NoContent(tornado.web.RequestHandler):
    def get(self) -> None:
        self.set_status(204)


class _Script(tornado.web.RequestHandler):
    def get(self) -> None:
        self.set_header("Content-Type", "application/javascript")
        self.write(meshcat_script().read_bytes())


class _Socket(tornado.websocket.WebSocketHandler):
    def initialize(self, bridge: Bridge) -> None:
        self.bridge = bridge

    def open(self, *args: Any, **kwargs: Any) -> None:
        self.bridge.browsers.add(self)
        for data in self.bridge.store.commands():
            self.write_message(data, binary=True)

    def on_message(self, message: str | bytes) -> None:
        pass  # meshcat's viewer sends captured images only on request; none is requested

    def on_close(self) -> None:
        self.bridge.browsers.discard(self)
