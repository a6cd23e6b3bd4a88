"""A ``pinmob`` run interrupted while it is running, whatever the machine's speed.

The run computes on the test's Dask cluster, where a worker plugin (:class:`worker_plugins.HoldAfter`) holds every
task past the first six until the signal has been sent: the run cannot end first (a signal sent on seeing a file
written raced the run's end on a fast machine).
"""

from __future__ import annotations

import os
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import cloudpickle
import worker_plugins
from dask.distributed import Client
from worker_plugins import HoldAfter

PINMOB = [sys.executable, "-m", "pinmob"]


def interrupted(
    scheduler: str, args: list[str], gate: Path, ready: Callable[[], bool], sig: int
) -> subprocess.CompletedProcess[str]:
    """Run ``pinmob args --scheduler scheduler``; once ``ready()`` (polled), send it ``sig`` (the run still held).

    Args:
        scheduler: the address of the test cluster's scheduler.
        args: pinmob's arguments.
        gate: an empty folder for the plugin's files.
        ready: when to send the signal (for instance: the journal holds a record); it must come true while the
            run is held.
        sig: the signal.

    Returns:
        the run, its output and exit status.
    """
    cloudpickle.register_pickle_by_value(worker_plugins)  # the workers cannot import the tests
    gate.mkdir(exist_ok=True)
    with Client(scheduler) as client:
        client.register_plugin(HoldAfter(str(gate), free=6), name=HoldAfter.name)
        try:
            proc = subprocess.Popen([*PINMOB, *args, "--scheduler", scheduler], stdout=subprocess.PIPE,
                                    stderr=subprocess.PIPE, text=True)  # fmt: skip
            deadline = time.monotonic() + 120  # a guard against a hang only: ready() comes true while held
            while time.monotonic() < deadline and proc.poll() is None and not ready():
                time.sleep(0.01)
            assert proc.poll() is None and ready(), proc.communicate()  # held: still running
            os.kill(proc.pid, sig)
            out, err = proc.communicate(timeout=60)
        finally:
            (gate / "release").touch()
            client.unregister_worker_plugin(HoldAfter.name)
    return subprocess.CompletedProcess(proc.args, proc.returncode, out, err)
