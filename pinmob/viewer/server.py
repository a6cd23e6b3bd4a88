"""A meshcat server on 127.0.0.1, started and probed without ever hanging.

``python -m pinmob.viewer.server [--port P] [--zmq-port Z]`` runs pinmob's
meshcat server (:class:`pinmob.viewer.bridge.Bridge`: meshcat's command
protocol, meshcat's viewer with pinmob's panel) bound to 127.0.0.1, prints
``zmq_url=...`` and ``web_url=...`` and serves until killed. Unlike
``meshcat-server`` it takes the web port to use, and fails with a one-line
message when that port is taken instead of silently moving on.
:func:`start_server` launches it as a child process and waits at most a few
seconds for those lines; :func:`probe` asks an existing server for its web URL
with a timeout. meshcat is imported only in the child process and in
:func:`probe`.
"""

from __future__ import annotations

import argparse
import os
import selectors
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass
from pathlib import Path

from pinmob.exceptions import ConfigurationError, ViewerError

HOST = "127.0.0.1"
#: valid TCP ports
PORTS = range(1, 65536)
#: seconds to wait for a server to start or answer
TIMEOUT = 20.0


@dataclass
class ServerProcess:
    """A meshcat server child process.

    Attributes:
        process: the child (``pid``; ``stop()`` ends it).
        zmq_url: where Python clients send commands.
        web_url: the page to open in a browser.
        log: file receiving the server's messages.
    """

    process: subprocess.Popen
    zmq_url: str
    web_url: str
    log: Path

    @property
    def pid(self) -> int:
        """Process id of the server."""
        return self.process.pid

    def stop(self, timeout: float = 5.0) -> None:
        """End the server (terminate, then kill after ``timeout`` s) and remove its log."""
        _end(self.process, self.log, timeout)


def _end(process: subprocess.Popen, log: Path, timeout: float = 5.0) -> None:
    """Terminate ``process`` (kill after ``timeout`` s), reap it, and remove its log file."""
    if process.poll() is None:
        process.terminate()
        try:
            process.wait(timeout)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait(timeout)
    log.unlink(missing_ok=True)


def _last_line(path: Path) -> str:
    try:
        lines = [ln.strip() for ln in path.read_text(errors="replace").splitlines() if ln.strip()]
    except OSError:
        return ""
    return lines[-1] if lines else ""


def check_port(port: object, what: str = "port") -> None:
    """A :class:`ConfigurationError` unless ``port`` is None or an integer in 1-65535."""
    if port is None:
        return
    if isinstance(port, bool) or not isinstance(port, int) or port not in PORTS:
        raise ConfigurationError(f"{what} must be an integer from {PORTS[0]} to {PORTS[-1]}, got {port!r}")


def start_server(
    port: int | None = None, zmq_port: int | None = None, timeout: float = TIMEOUT, tied: bool = False
) -> ServerProcess:
    """Start a meshcat server on 127.0.0.1 in its own session (it survives Ctrl-C of the parent).

    Args:
        port: web port; None takes the first free one from 7000.
        zmq_port: command port; None takes the first free one from 6000.
        timeout: seconds to wait for the server to report its URLs.
        tied: the server stops when this process ends, however it ends (``--parent``).

    Raises:
        ConfigurationError: a port is not an integer from 1 to 65535.
        ViewerError: the port is in use, meshcat is missing, or the server
            did not start within ``timeout``.
    """
    for what, value in (("port", port), ("zmq_port", zmq_port)):
        check_port(value, what)
    fd, name = tempfile.mkstemp(prefix="pinmob-meshcat-", suffix=".log")
    os.close(fd)
    log = Path(name)
    cmd = [sys.executable, "-u", "-m", "pinmob.viewer.server"]
    if port is not None:
        cmd += ["--port", str(int(port))]
    if zmq_port is not None:
        cmd += ["--zmq-port", str(int(zmq_port))]
    if tied:  # the server stops when this process ends, however it ends (SIGKILL included)
        cmd += ["--parent", str(os.getpid())]
    with log.open("wb") as err:
        proc = subprocess.Popen(
            cmd, stdout=subprocess.PIPE, stderr=err, stdin=subprocess.DEVNULL, start_new_session=True
        )
    assert proc.stdout is not None
    sel = selectors.DefaultSelector()
    sel.register(proc.stdout, selectors.EVENT_READ)
    try:
        found = _read_urls(proc, sel, log, timeout)
    except BaseException:  # no URLs, or interrupted (Ctrl-C, SIGTERM turned into KeyboardInterrupt): no orphan
        _end(proc, log)
        raise
    finally:
        sel.close()
        proc.stdout.close()
    return ServerProcess(proc, found["zmq_url"], found["web_url"], log)


def _read_urls(proc: subprocess.Popen, sel: selectors.BaseSelector, log: Path, timeout: float) -> dict[str, str]:
    """The ``zmq_url=`` and ``web_url=`` lines the server prints, within ``timeout`` s."""
    assert proc.stdout is not None
    found: dict[str, str] = {}
    deadline = time.monotonic() + timeout
    buffer = b""
    while len(found) < 2:
        left = deadline - time.monotonic()
        if left <= 0:
            proc.kill()
            proc.wait()
            raise ViewerError(f"the meshcat server did not start within {timeout:g} s")
        if sel.select(min(left, 0.2)):
            chunk = os.read(proc.stdout.fileno(), 4096)
            if not chunk:
                proc.wait()
                reason = _last_line(log) or f"exit status {proc.returncode}"
                raise ViewerError(f"the meshcat server could not start: {reason}")
            buffer += chunk
            *lines, buffer = buffer.split(b"\n")
            for line in lines:
                key, _, value = line.decode(errors="replace").strip().partition("=")
                if key in ("zmq_url", "web_url"):
                    found[key] = value
        elif proc.poll() is not None:
            raise ViewerError(
                f"the meshcat server could not start: {_last_line(log) or f'exit status {proc.returncode}'}"
            )
    return found


def probe(zmq_url: str, timeout: float = 3.0) -> str:
    """Ask the meshcat server at ``zmq_url`` for its web URL, waiting at most ``timeout`` s.

    Raises:
        ViewerError: nothing answers there.
    """
    import zmq

    ctx: zmq.Context[zmq.Socket[bytes]] = zmq.Context.instance()
    sock = ctx.socket(zmq.REQ)
    sock.setsockopt(zmq.LINGER, 0)
    sock.setsockopt(zmq.RCVTIMEO, int(timeout * 1000))
    sock.setsockopt(zmq.SNDTIMEO, int(timeout * 1000))
    try:
        sock.connect(zmq_url)
        sock.send(b"url")
        return sock.recv().decode("utf-8")
    except zmq.ZMQError as exc:
        raise ViewerError(
            f"no meshcat server answers at {zmq_url!r} (waited {timeout:g} s: {exc}); start one with "
            "'meshcat-server', or leave out the zmq URL so that pinmob starts its own"
        ) from None
    finally:
        sock.close(0)


def main(argv: list[str] | None = None) -> int:
    """``python -m pinmob.viewer.server``: run pinmob's meshcat server on 127.0.0.1 and print its URLs."""
    parser = argparse.ArgumentParser(prog="python -m pinmob.viewer.server", description=__doc__.splitlines()[0])
    parser.add_argument("--port", type=int, default=None, help="web port (default: first free from 7000)")
    parser.add_argument("--zmq-port", type=int, default=None, help="command port (default: first free from 6000)")
    parser.add_argument("--parent", type=int, default=None, help="stop when the process with this pid ends")
    args = parser.parse_args(argv)
    try:
        import zmq

        from pinmob.viewer.bridge import Bridge
    except ImportError as exc:
        print(f"meshcat is not installed ({exc}); install it with: pip install meshcat", file=sys.stderr)
        return 3
    try:
        bridge = Bridge(port=args.port, zmq_port=args.zmq_port)
    except OSError as exc:
        print(
            f"web port {args.port} on {HOST} is in use ({exc.strerror or exc}): "
            "choose another port, or none to take a free one",
            file=sys.stderr,
        )
        return 4
    except zmq.ZMQError as exc:
        print(f"command port {args.zmq_port} on {HOST} is in use ({exc}): choose another, or none", file=sys.stderr)
        return 4
    print(f"zmq_url={bridge.zmq_url}")
    print(f"web_url={bridge.web_url}")
    sys.stdout.flush()
    sys.stdout = sys.stderr  # nothing else goes to the (possibly closed) pipe
    if args.parent is not None:
        bridge.stop_with(args.parent)
    try:
        bridge.run()
    except KeyboardInterrupt:
        pass
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
