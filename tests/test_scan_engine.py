"""The Dask engine under scans: real LocalClusters, workers killed (SIGKILL, SIGTERM), signals, output files.

Issue 14's classes 6 (a scan hung forever when a worker died) and 7 (outputs lost, truncated or left invalid
by an interruption; writing through symbolic links).
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest
import worker_plugins
from processes import alive, children, dask_workers
from worker_plugins import KillOnFirstChunk

import pinmob
from pinmob.cli import main
from pinmob.exceptions import ConfigurationError, EngineError
from pinmob.parallel import Engine
from pinmob.scan import grid_spec, path_spec, scan

PINMOB = [sys.executable, "-m", "pinmob"]
TESTS = Path(__file__).parent


def _norm(rows: list[dict]) -> list[dict]:
    return [{k: ("nan" if isinstance(v, float) and v != v else v) for k, v in r.items()} for r in rows]


def test_scan_on_a_cluster_gives_the_serial_rows(dask_cluster):
    """A 6-UPS path over three chunks crossing the Type II pose between samples, and a one-row 3-PUU grid running
    off the workspace on both sides, its line of 200 samples in two chunks (``LINE_CHUNK``): the chunks computed on
    two Dask workers give the rows of this process."""
    mech = pinmob.load("6-UPS")
    spec = path_spec(mech, "home", "0,0,0.4,0,0,2.0944", 70)
    serial = list(scan(mech, spec, progress=False))
    run = scan(mech, spec, progress=False, scheduler=dask_cluster.scheduler_address)
    assert _norm(list(run)) == _norm(serial) and "Dask cluster at" in run.where
    assert sum(r["refined"] for r in serial) == 1
    puu = pinmob.load("3-PUU")
    grid = grid_spec(puu, "generic", [("x", 0.0, 0.0, 1), ("y", -0.115, 0.115, 200)])
    assert len(grid.chunks()) == 2  # the second one on a worker, from its seed and with its left neighbour
    serial = list(scan(puu, grid, progress=False))
    assert _norm(list(scan(puu, grid, progress=False, scheduler=dask_cluster.scheduler_address))) == _norm(serial)
    assert any(not r["reachable"] for r in serial) and sum(r["refined"] for r in serial) == 2


def test_a_small_scan_stays_in_process():
    """Starting a LocalCluster costs seconds: a scan that takes less than that here is not sent to one."""
    mech = pinmob.load("3-UPU")
    run = scan(mech, path_spec(mech, "generic", "constraint-singular", 40), workers=2, progress=False)
    rows = list(run)
    assert len(rows) >= 40 and run.where == "1 worker (this process: too small to pay for 2 workers)"


def test_workers_must_be_a_positive_whole_number():
    mech = pinmob.load("3-UPU")
    spec = path_spec(mech, "generic", "constraint-singular", 3)
    for bad in (0, -2, 1.5, True):
        with pytest.raises(ConfigurationError, match="^workers must be a whole number"):
            scan(mech, spec, workers=bad)  # type: ignore[arg-type]


def _script(body: str, timeout: float = 180) -> subprocess.CompletedProcess[str]:
    """Run a Python script in a new process (its own LocalCluster), bounded in time: a hang fails the test."""
    code = f"import sys; sys.path.insert(0, {str(TESTS)!r})\n" + textwrap.dedent(body)
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=timeout)


@pytest.mark.parametrize("sig", ["SIGKILL", "SIGTERM"])
def test_a_killed_worker_costs_no_result_and_no_hang(sig, tmp_path):
    """A worker killed while it computes (as the out-of-memory killer would: the worker that starts the first task
    kills itself, a worker plugin, whatever the machine's speed) is replaced and its task computed again: every
    result comes back, in order, and the engine counts the lost worker."""
    out = _script(f"""
        import signal
        import cloudpickle
        import worker_plugins
        from pinmob.parallel import Engine
        from engine_tasks import slow_square
        from worker_plugins import KillOnFirstChunk
        cloudpickle.register_pickle_by_value(worker_plugins)
        if __name__ == "__main__":
            with Engine(workers=2) as engine:
                engine.start()
                plugin = KillOnFirstChunk({str(tmp_path / "killed")!r}, int(signal.{sig}))
                engine._client.register_plugin(plugin, name=KillOnFirstChunk.name)
                results = list(engine.map(slow_square, 0.3, range(16), window=4))
                print(results == [x * x for x in range(16)], engine.count_lost())
    """)
    assert (tmp_path / "killed").exists()
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", "1"], out.stdout + out.stderr
    assert "Traceback" not in out.stderr, out.stderr


def test_what_every_task_shares_goes_to_the_cluster_once():
    """``Engine.map(fn, shared, items)`` sends ``shared`` once (a task every task depends on), not with each task: it
    is unpickled at most once per worker for 40 tasks (it was 40 times, once per task)."""
    out = _script("""
        from pinmob.parallel import Engine
        from engine_tasks import Counted, size_plus, unpickled
        if __name__ == "__main__":
            with Engine(workers=2) as engine:
                results = list(engine.map(size_plus, Counted(b"x" * 100_000), range(40)))
                counts = engine._client.run(unpickled)
            print(results == [100_000 + x for x in range(40)], sum(counts.values()))
    """)
    assert out.returncode == 0, out.stderr
    ok, count = out.stdout.split()
    assert ok == "True" and 1 <= int(count) <= 2, out.stdout + out.stderr


def test_a_task_that_kills_every_worker_is_lost_not_hung(tmp_path):
    """A task whose workers die each time it runs comes back as Lost, the others as results: no hang, no crash.
    Dask tries it ``distributed.scheduler.allowed-failures`` + 1 times (its scheduler's rule: given up when more
    than allowed-failures workers died running it): 4 with Dask's default 3, counted by the task itself."""
    import dask
    import distributed  # noqa: F401  (its configuration defaults)

    tries = dask.config.get("distributed.scheduler.allowed-failures") + 1
    runs = tmp_path / "runs.txt"
    out = _script(f"""
        from pinmob.parallel import Engine, Lost
        from engine_tasks import exit_on_counting
        if __name__ == "__main__":
            with Engine(workers=2) as engine:
                results = list(engine.map(exit_on_counting, (3, {str(runs)!r}), range(6)))
            print([type(r).__name__ if isinstance(r, Lost) else r for r in results])
            print(results[3].reason)
    """)
    assert out.returncode == 0, out.stderr
    first, reason = out.stdout.splitlines()[:2]
    got = eval(first)  # noqa: S307  (the list the script printed)
    # the killer is Lost; Dask blames the tasks that were on a dying worker with it too, so under load an
    # innocent neighbour may be Lost as well (never a wrong value, never a hang)
    assert got[3] == "Lost" and all(g in (i, "Lost") for i, g in enumerate(got)) and got.count("Lost") <= 2
    assert "died each time" in reason and f"({tries} times" in reason
    assert tries == 4 and runs.read_text().count("ran") == tries


def test_an_unreachable_scheduler_is_one_clear_error():
    engine = Engine(scheduler="tcp://127.0.0.1:9")
    t0 = time.monotonic()
    with pytest.raises(EngineError, match="cannot use the Dask scheduler at 'tcp://127.0.0.1:9'"):
        engine.start()
    assert time.monotonic() - t0 < 60


@pytest.mark.parametrize("sig", [signal.SIGKILL, signal.SIGTERM])
def test_cli_scan_survives_a_killed_worker(dask_cluster, tmp_path, sig):
    """``pinmob scan --scheduler``: the worker computing the first chunk on the cluster is killed while it does;
    the scan finishes (Dask computes the chunk again) with the rows of the in-process scan."""
    import cloudpickle
    from dask.distributed import Client

    cloudpickle.register_pickle_by_value(worker_plugins)  # the workers cannot import the tests
    grid = ["--grid", "x:-0.08:0.08:12", "y:-0.08:0.08:24", "--no-progress"]
    serial, cluster = tmp_path / "serial.csv", tmp_path / "cluster.csv"
    assert main(["scan", "6-UPS", *grid, "--csv", str(serial)]) == 0
    flag = tmp_path / "killed"
    with Client(dask_cluster.scheduler_address) as client:
        client.register_plugin(KillOnFirstChunk(str(flag), int(sig)), name=KillOnFirstChunk.name)
        try:
            run = subprocess.run(
                [*PINMOB, "scan", "6-UPS", *grid, "--csv", str(cluster), "--scheduler", dask_cluster.scheduler_address],
                capture_output=True,
                text=True,
                timeout=240,
            )
        finally:
            client.unregister_worker_plugin(KillOnFirstChunk.name)
        client.wait_for_workers(2, timeout=60)
    assert flag.exists(), "no chunk ever ran on the cluster"
    assert run.returncode == 0, run.stderr
    assert "lost and replaced" in run.stdout and "Traceback" not in run.stderr
    assert cluster.read_text() == serial.read_text()


def test_outputs_are_never_written_through_symbolic_links(tmp_path, capsys):
    """A link (to a file, or dangling) is refused with and without --force: its target is neither changed nor
    created (it was: --csv wrote through links, and a dangling link created its target)."""
    target, link = tmp_path / "precious.txt", tmp_path / "s.csv"
    target.write_text("mine\n")
    link.symlink_to(target)
    dangling, nowhere = tmp_path / "s.json", tmp_path / "created.json"
    dangling.symlink_to(nowhere)
    for option, path in (("--csv", link), ("--json", dangling), ("--plot", tmp_path / "p.png")):
        if option == "--plot":
            path.symlink_to(tmp_path / "p-target.png")
        for force in ([], ["--force"]):
            assert main(["scan", "3-UPU", "-n", "3", "--no-progress", option, str(path), *force]) == 2
            err = capsys.readouterr().err
            assert err.count("\n") == 1 and "symbolic link" in err and option in err
    assert target.read_text() == "mine\n" and not nowhere.exists() and not (tmp_path / "p-target.png").exists()


def test_outputs_go_only_to_regular_files(tmp_path, capsys):
    """A device or a pipe is not an output file, even with --force (as root, /dev/null was replaced)."""
    fifo = tmp_path / "pipe.csv"
    os.mkfifo(fifo)
    assert main(["scan", "3-UPU", "-n", "3", "--csv", str(fifo), "--force"]) == 2
    assert "not a regular file" in capsys.readouterr().err
    assert main(["scan", "3-UPU", "-n", "3", "--json", "/dev/null", "--force"]) == 2
    assert "not a regular file" in capsys.readouterr().err


def _leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


@pytest.mark.parametrize(
    "sig,workers,group",
    [("SIGINT", 2, True), ("SIGTERM", 2, False), ("SIGHUP", 2, False), ("SIGTERM", 1, False)],
    ids=["ctrl-c-to-the-group", "sigterm", "sighup", "sigterm-in-process"],
)
def test_an_interrupted_scan_leaves_the_old_files_and_no_temporary(tmp_path, sig, workers, group):
    """Interrupted while it writes, thousands of samples before its end (with --force over an old CSV): exit 130 with one line, the old CSV as it was
    (it was truncated at the start), no new JSON (it was an invalid half document after SIGTERM), no temporary
    file, no traceback from a worker, and no worker process left."""
    old = tmp_path / "s.csv"
    old.write_text("index,s\nmine\n")
    # big enough that, at the first chunk's pace (100 to 400 us a sample), the rest would take far more than
    # CLUSTER_MIN_SECONDS in process, so the workers start (100 x 100, a 128-sample first chunk, could stay in
    # process on a fast machine); the scan is interrupted long before its end
    args = ["scan", "6-UPS", "--grid", "x:-0.1:0.1:500", "y:-0.1:0.1:500", "--csv", str(old)]
    args += ["--json", str(tmp_path / "s.json"), "--force", "--no-progress", "--workers", str(workers)]
    proc = subprocess.Popen([*PINMOB, *args], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                            start_new_session=True)  # fmt: skip
    workers_seen = dask_workers(proc.pid, 2) if workers > 1 else []
    send = os.killpg if group else os.kill
    deadline = time.monotonic() + 120  # a guard against a hang only
    while time.monotonic() < deadline and proc.poll() is None and not list(tmp_path.glob(".s.csv.*")):
        time.sleep(0.01)
    # the scan frozen while the test looks: rows left to compute, then the signal, pending until SIGCONT, is handled
    # before any of them (a signal sent after a sleep raced the scan's end on a fast machine)
    send(proc.pid, signal.SIGSTOP)
    try:
        (partial,) = tmp_path.glob(".s.csv.*")  # the CSV being written; a stopped process has not ended
        assert proc.poll() is None and len(partial.read_text().splitlines()) < 250_000 - 1000
        send(proc.pid, getattr(signal, sig))
    finally:
        send(proc.pid, signal.SIGCONT)
    out, err = proc.communicate(timeout=60)
    assert proc.returncode == 130, err
    assert err.strip() == "pinmob: interrupted", err
    assert old.read_text() == "index,s\nmine\n" and not (tmp_path / "s.json").exists()
    assert _leftovers(tmp_path) == []
    deadline = time.monotonic() + 20
    while any(alive(p) for p in workers_seen) and time.monotonic() < deadline:
        time.sleep(0.2)
    assert not any(alive(p) for p in workers_seen) and not children(proc.pid)


def test_a_finished_scan_replaces_the_old_file_in_one_step(tmp_path):
    """With --force the new CSV and JSON replace the old files only once complete (a rename in the same folder)."""
    old = tmp_path / "s.csv"
    old.write_text("mine\n")
    inode = old.stat().st_ino
    assert main(["scan", "3-UPU", "-n", "5", "--no-progress", "--csv", str(old), "--force",
                 "--json", str(tmp_path / "s.json")]) == 0  # fmt: skip
    assert old.stat().st_ino != inode and len(old.read_text().splitlines()) == 6
    assert len(json.loads((tmp_path / "s.json").read_text())["samples"]) == 5
    assert _leftovers(tmp_path) == []


def test_an_interruption_while_a_task_is_submitted_leaves_no_broken_future(dask_cluster):
    """Ctrl-C landing while Dask makes a task's Future (the race a CI run met once): the map stops with one
    KeyboardInterrupt and no finaliser prints a traceback. Before, the half-made Future had no ``_cleared`` and its
    ``__del__`` printed "Exception ignored ... AttributeError" on stderr after pinmob said it was interrupted.

    The race is made to happen: a trace function raises SIGINT on entering ``Future.__init__``, the first time."""
    import gc
    import operator

    from distributed import Future

    fired: list[bool] = []
    unraisable: list[object] = []

    def tracer(frame, event, arg):  # noqa: ANN001, ANN202
        if event == "call" and frame.f_code is Future.__init__.__code__ and not fired:
            fired.append(True)
            signal.raise_signal(signal.SIGINT)

    hook = sys.unraisablehook
    sys.unraisablehook = unraisable.append
    try:
        with Engine(scheduler=dask_cluster.scheduler_address) as engine:
            results = engine.map(operator.add, 1, range(20))
            sys.settrace(tracer)
            try:
                with pytest.raises(KeyboardInterrupt):
                    list(results)
            finally:
                sys.settrace(None)
        gc.collect()
    finally:
        sys.unraisablehook = hook
    assert fired and not unraisable, unraisable
