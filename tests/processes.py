"""Process-table helpers for the tests that kill workers or send signals (Linux /proc)."""

from __future__ import annotations

import time
from pathlib import Path


def children(pid: int) -> list[int]:
    """Processes whose parent is ``pid``."""
    out = []
    for entry in Path("/proc").iterdir():
        if entry.name.isdigit():
            try:
                stat = (entry / "stat").read_text()
            except OSError:
                continue
            if int(stat.rsplit(")", 1)[1].split()[1]) == pid:
                out.append(int(entry.name))
    return out


def command(pid: int) -> str:
    """The command line of a process ('' when it is gone)."""
    try:
        return (Path("/proc") / str(pid) / "cmdline").read_bytes().replace(b"\0", b" ").decode()
    except OSError:
        return ""


def alive(pid: int) -> bool:
    """The process exists and is not a zombie."""
    try:
        stat = (Path("/proc") / str(pid) / "stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def dask_workers(pid: int, count: int, timeout: float = 90.0) -> list[int]:
    """The Dask worker processes started by process ``pid`` (waits until ``count`` are there)."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        found = [c for c in children(pid) if "multiprocessing" in command(c) and "resource_tracker" not in command(c)]
        if len(found) >= count:
            return found
        time.sleep(0.2)
    raise AssertionError(f"process {pid} did not start {count} Dask workers within {timeout} s")
