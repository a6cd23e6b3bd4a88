"""The garbage collector's automatic passes paused while a scan's group runs, and the user's setting kept."""

from __future__ import annotations

import gc
import subprocess
import sys
import textwrap
import threading

import pytest

import pinmob
from pinmob.collector import collector_paused
from pinmob.scan import ScanSpec, grid_spec, with_finite
from pinmob.scan.scan_run import scan_table


@pytest.fixture
def enabled():
    """The collector enabled for the test, and the process's setting restored after it."""
    was = gc.isenabled()
    gc.enable()
    yield
    if not was:
        gc.disable()


def test_paused_inside_restored_after(enabled):
    with collector_paused:
        assert not gc.isenabled() and collector_paused.active
        with collector_paused:  # nested: still paused, and the inner exit does not enable it
            assert not gc.isenabled()
        assert not gc.isenabled()
    assert gc.isenabled() and not collector_paused.active


def test_restored_after_an_error(enabled):
    with pytest.raises(RuntimeError), collector_paused:
        raise RuntimeError("inside the block")
    assert gc.isenabled()


def test_a_collector_the_user_disabled_stays_disabled(enabled):
    gc.disable()
    with collector_paused:
        assert not gc.isenabled()
    assert not gc.isenabled()


def test_concurrent_blocks_keep_it_paused_until_the_last_leaves(enabled):
    inside, leave, states = threading.Event(), threading.Event(), []

    def other() -> None:
        with collector_paused:
            inside.set()
            leave.wait(10)
            states.append(gc.isenabled())

    thread = threading.Thread(target=other)
    thread.start()
    assert inside.wait(10)
    with collector_paused:
        pass  # this thread's block ends first: the other one's still holds the pause
    assert not gc.isenabled()
    leave.set()
    thread.join(10)
    assert states == [False] and gc.isenabled()


def collections_during_groups(mech: pinmob.Mechanism, spec: ScanSpec) -> list[bool]:
    """Per automatic collection of a scan with the collector's threshold at 5: was a group running?"""
    during: list[bool] = []  # run_group on the stack

    def record(phase: str, info: dict[str, int]) -> None:
        if phase == "start":
            frame = sys._getframe(1)
            while frame is not None and frame.f_code.co_name != "run_group":
                frame = frame.f_back
            during.append(frame is not None)

    threshold = gc.get_threshold()
    gc.callbacks.append(record)
    gc.set_threshold(5)
    try:
        table = scan_table(mech, spec)
    finally:
        gc.set_threshold(*threshold)
        gc.callbacks.remove(record)
    assert len(table) >= spec.size and table["reachable"].all()
    return during


def test_a_scan_group_runs_without_automatic_collections(enabled):
    """With a tiny threshold the collector runs all the time, except while a group assembles and analyses."""
    mech = pinmob.load("3-PUU")
    during = collections_during_groups(mech, grid_spec(mech, "generic", [("x", -0.06, 0.06, 9), ("y", -0.06, 0.06, 9)]))
    assert during.count(False) > 10  # the walk, the tables: collected as usual
    assert True not in during, f"{during.count(True)} collections while a group ran"
    assert gc.isenabled()


def test_a_scan_with_finite_dof_keeps_collecting(enabled):
    """Each sample's finite analysis refers back to its configuration: only the collector frees those cycles."""
    mech = pinmob.load("3-PUU")
    spec = with_finite(mech, grid_spec(mech, "generic", [("x", -0.06, 0.06, 5), ("y", -0.06, 0.06, 5)]))
    assert collections_during_groups(mech, spec).count(True) > 10
    assert gc.isenabled()


@pytest.mark.parametrize(
    "robot, at, axes",
    [
        ("3-PUU", "generic", [("x", -0.06, 0.06, 9), ("y", -0.06, 0.06, 9)]),
        ("3-PUU", "generic", [("x", -0.3, 0.3, 9), ("y", -0.3, 0.3, 9)]),  # out of reach, refined edges
        ("3-PUU", "generic", [("A_slider", -0.2, 0.2, 9), ("B_slider", -0.2, 0.2, 9)]),  # motors, refined
        ("3-RPS", "home", [("roll", -0.2, 0.2, 9), ("pitch", -0.2, 0.2, 9)]),  # x, y, yaw following
    ],
)
def test_paused_scans_leave_no_cycle_a_sample(robot, at, axes):
    """What the paused groups make is freed by reference counting: a cycle a sample would pile up until they end.

    The fewer of two scans' counts: what happens once in a process (an import during the scan, after which
    ``one_blas_thread`` looks for the BLAS libraries again, and threadpoolctl's controllers hold cycles) is not the
    scan's, and a cycle a sample is in both. Counted in a process of its own: the test session's Dask cluster
    (``tests/conftest.py``) runs its IO loop in a thread of this one, which makes cyclic garbage of its own at any
    time (a run without numba, whose file list runs the cluster's tests first, counted 42 and 21 here).
    """
    code = textwrap.dedent(f"""
        import gc
        import pinmob
        from pinmob.scan import grid_spec
        from pinmob.scan.scan_run import scan_table

        mech = pinmob.load({robot!r})
        spec = grid_spec(mech, {at!r}, {axes!r})
        scan_table(mech, spec)  # the kernels, caches and generic states made once
        counts = []
        gc.enable()
        for _ in range(2):
            gc.collect()
            gc.disable()
            try:
                scan_table(mech, spec)
            finally:
                counts.append(gc.collect())
                gc.enable()
        print(spec.size, *counts)
    """)
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    size, *counts = map(int, run.stdout.split())
    cyclic = min(counts)
    assert cyclic < size // 4, f"{counts} objects in reference cycles after scans of {size} samples"
