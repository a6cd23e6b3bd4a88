"""Progress of long steps: reported by the core to a listener, drawn by the CLI on a terminal only."""

from __future__ import annotations

import fcntl
import os
import pty
import re
import select
import struct
import subprocess
import sys
import termios
import time
from pathlib import Path

import pinmob
from pinmob.assembly.relaxation import unclosable
from pinmob.progress import reporting, step

DATA = Path(__file__).parent / "data"
KANGAROO = DATA / "example-parallel-robots" / "kangaroo_like" / "robot.yaml"
# closing the kangaroo's loops as declared fails after 21 attempts, then each closure is tried alone:
# the restarts alone take 5-15 s here, well over the bar's two-second delay
SLOW = [sys.executable, "-m", "pinmob", "analyze", str(KANGAROO)]


class Entry:
    """One step as a listener sees it: description, total, units done, closed."""

    def __init__(self, description: str, total: int | None) -> None:
        self.row = [description, total, 0, False]

    def update(self, n: int = 1) -> None:
        self.row[2] += n

    def set_postfix_str(self, s: str = "", refresh: bool = True) -> None:
        pass

    def close(self) -> None:
        self.row[3] = True


class Recorder:
    """A listener recording every step (nested ones too) and how many units each reported."""

    def __init__(self) -> None:
        self.entries: list[Entry] = []

    def __call__(self, description: str, total: int | None) -> Entry:
        self.entries.append(Entry(description, total))
        return self.entries[-1]

    @property
    def steps(self) -> list[list]:
        return [e.row for e in self.entries]


def test_nothing_is_reported_without_a_listener():
    with step("anything", total=3) as bar:
        bar.update()  # a silent bar: no error, no output


def test_steps_report_to_the_listener():
    mech = pinmob.load(str(DATA / "fourbar.toml"))
    recorder = Recorder()
    with reporting(recorder):
        assert unclosable(mech) == ()
    described = [s for s in recorder.steps if s[0].startswith("testing each closure of")]
    assert described == [[f"testing each closure of {mech.name} alone", len(mech.closures), len(mech.closures), True]]
    with reporting(None):
        unclosable(mech)  # silenced again inside


def run_in_terminal(cmd: list[str], timeout: float = 120.0, env: dict[str, str] | None = None) -> tuple[int, str]:
    """Run cmd with stderr on a pseudo-terminal (stdout a pipe); its exit status and everything it wrote there."""
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 24, 160, 0, 0))  # a new pty is 0 columns wide
    proc = subprocess.Popen(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=slave, env=env)
    os.close(slave)
    chunks, deadline = [], time.monotonic() + timeout
    while time.monotonic() < deadline:
        ready, _, _ = select.select([master], [], [], 0.2)
        if ready:
            try:
                data = os.read(master, 4096)
            except OSError:  # the child closed the terminal
                break
            if not data:
                break
            chunks.append(data)
        elif proc.poll() is not None:
            break
    os.close(master)
    return proc.wait(timeout=10), b"".join(chunks).decode(errors="replace")


def test_a_long_step_shows_a_bar_on_a_terminal_only():
    # the restarts, then each closure tried alone: well under a second now, so the bars are asked for at once
    # (PINMOB_PROGRESS_DELAY=0; the two-second delay itself: tests/test_cli_progress.py)
    now = os.environ | {"PINMOB_PROGRESS_DELAY": "0"}
    status, terminal = run_in_terminal(SLOW, env=now)
    assert status == 2, terminal[-2000:]
    assert re.search(r"pinmob: (closing the loops|testing each closure) of kangaroo_like", terminal), terminal[-2000:]
    assert "pinmob: error: 'kangaroo_like' (as declared) could not be closed" in terminal
    piped = subprocess.run(SLOW, capture_output=True, text=True, timeout=120, env=now)
    assert piped.returncode == 2
    assert not re.search(r"closing the loops|testing each closure", piped.stderr) and "\r" not in piped.stderr
    assert piped.stderr.splitlines()[-1].startswith("pinmob: error: 'kangaroo_like' (as declared)")


def test_a_wrong_progress_delay_is_one_line():
    status, terminal = run_in_terminal(SLOW, env=os.environ | {"PINMOB_PROGRESS_DELAY": "soon"})
    assert status == 2
    last = terminal.strip().splitlines()[-1]
    assert last == "pinmob: error: PINMOB_PROGRESS_DELAY must be a number of seconds >= 0 (e.g. 2), got 'soon'", last
    assert "Traceback" not in terminal
