"""The command line's progress bar: drawn by tqdm on a terminal once its step has lasted its delay, never before."""

from __future__ import annotations

import os
import pty
import select
import time
from pathlib import Path

from pinmob.cli.progress_bar import LateBar


def drained(fd: int) -> str:
    """Everything written to the terminal so far (waits at most 0.2 s for the first bytes)."""
    out = b""
    while select.select([fd], [], [], 0.2)[0]:
        chunk = os.read(fd, 4096)
        if not chunk:
            break
        out += chunk
    return out.decode(errors="replace")


def test_bar_opens_after_its_delay_with_what_was_done() -> None:
    master, slave = pty.openpty()
    try:
        with os.fdopen(slave, "w") as stream:
            bar = LateBar("testing", 4, delay=1.5, stream=stream)
            bar.update()
            bar.update()
            stream.flush()
            assert drained(master) == ""  # a short step draws nothing
            time.sleep(1.55)
            bar.set_postfix_str("third")  # opens the bar with the two units done and the note
            stream.flush()
            text = drained(master)
            assert "pinmob: testing" in text and "2/4" in text and "third" in text, text
            time.sleep(0.15)  # tqdm redraws at most every 0.1 s
            bar.update()
            stream.flush()
            assert "3/4" in drained(master)
            bar.close()
    finally:
        os.close(master)


def test_bar_never_drawn_off_a_terminal(tmp_path: Path) -> None:
    log = tmp_path / "stderr.txt"
    with log.open("w") as stream:
        bar = LateBar("testing", 2, delay=0.0, stream=stream)
        bar.update(2)
        bar.set_postfix_str("note")
        bar.close()
    assert log.read_text() == ""
