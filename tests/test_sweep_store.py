"""The sweep's Parquet file under hostile histories: another sweep's file, a non-sweep file, SIGKILL, --force, the lock,
interruption messages that must be true, output names that collide, the bound on the number of designs.
"""

from __future__ import annotations

import json
import os
import signal
import sys
import time
from pathlib import Path

import pyarrow as pa
import pyarrow.parquet as pq
import pytest
import sweep_specs
from held_runs import interrupted

import pinmob
from pinmob.cli import main
from pinmob.exceptions import ConfigurationError
from pinmob.signals import deferred_interrupts
from pinmob.sweeps.reading import journal_records
from pinmob.sweeps.store import META, Store, sweep_metadata

PINMOB = [sys.executable, "-m", "pinmob"]


#: 4 x 4 designs: link in [lo, hi], big_r in [0.25, 0.4]
SPEC = sweep_specs.SPEC.replace("{n}", "4")


def _spec(folder: Path, name: str, lo: float, hi: float, m: int = 5) -> Path:
    path = folder / f"{name}.toml"
    path.write_text(SPEC.format(title=name, lo=lo, hi=hi, m=m))
    return path


def _one_line(capsys, args: list[str], *words: str) -> None:
    assert main(args) == 2
    captured = capsys.readouterr()
    assert captured.err.count("\n") == 1 and captured.err.startswith("pinmob: error:"), captured.err
    assert all(w in captured.err for w in words), captured.err
    assert "Traceback" not in captured.err


def _dot_files(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith("."))


def _kill_after_first_record(scheduler: str, args: list[str], journal: Path, count: int) -> None:
    """Run ``pinmob`` with ``args`` on the test cluster; SIGKILL it once its journal holds a record but not all (read
    as the store reads it), the run held until then (:func:`held_runs.interrupted`)."""

    def ready() -> bool:
        return 0 < sum(1 for _ in journal_records(journal)) < count

    run = interrupted(scheduler, args, journal.parent / "gate", ready, signal.SIGKILL)
    assert run.returncode == -9 and journal.exists()


def test_a_forced_run_killed_then_forced_again_holds_only_its_own_records(tmp_path, capsys, dask_cluster):
    """Reviewer's repro: b's records in out.parquet; a (other link range) run with --force and SIGKILLed after its
    first journal flush; a again with --force: the file must hold a's records only (it said "16 of 16 designs
    already written, skipped", metadata name 'a', complete, rows of b)."""
    a, b = _spec(tmp_path, "a", 0.26, 0.32), _spec(tmp_path, "b", 0.3, 0.35)
    out, journal = tmp_path / "out.parquet", tmp_path / ".out.parquet.pinmob-journal"
    quiet = ["--no-progress", "--no-plots"]
    assert main(["sweep", str(b), "--out", str(out), *quiet]) == 0
    _kill_after_first_record(dask_cluster.scheduler_address, ["sweep", str(a), "--out", str(out), "--force", *quiet],
                             journal, 16)  # fmt: skip
    assert sweep_metadata(out)["name"] == "b"  # the killed run replaced nothing
    _one_line(capsys, ["sweep", str(a), "--out", str(out), *quiet], "another sweep ('b'", "--force")
    killed = [".out.parquet.pinmob-journal", ".out.parquet.pinmob-lock"]  # what SIGKILL leaves (the lock not held)
    assert _dot_files(tmp_path) == killed  # refused: the journal kept for its own sweep
    assert main(["sweep", str(a), "--out", str(out), "--force", *quiet]) == 0
    assert "already written" not in capsys.readouterr().out
    fresh = tmp_path / "fresh.parquet"
    assert main(["sweep", str(a), "--out", str(fresh), *quiet]) == 0
    meta = sweep_metadata(out)
    assert meta["name"] == "a" and meta["complete"] and meta["written"] == 16
    assert {r["link"] for r in pq.read_table(out).to_pylist()} == {0.26, 0.28, 0.3, 0.32}
    assert out.read_bytes() == fresh.read_bytes()
    assert _dot_files(tmp_path) == []


def test_a_file_that_is_not_a_sweep_file_is_never_read_as_one(tmp_path, capsys, dask_cluster):
    """`echo mine > out.parquet`, a --force run killed: the next runs are one-line refusals (they were tracebacks,
    every time), the file untouched and no lock left behind; --force then replaces it."""
    a = _spec(tmp_path, "a", 0.26, 0.32)
    out, journal = tmp_path / "out.parquet", tmp_path / ".out.parquet.pinmob-journal"
    out.write_text("mine\n")
    quiet = ["--no-progress", "--no-plots"]
    _kill_after_first_record(dask_cluster.scheduler_address, ["sweep", str(a), "--out", str(out), "--force", *quiet],
                             journal, 16)  # fmt: skip
    for _ in range(2):
        _one_line(capsys, ["sweep", str(a), "--out", str(out), *quiet], "not a pinmob sweep file", "--force")
    assert out.read_text() == "mine\n"
    assert _dot_files(tmp_path) == [".out.parquet.pinmob-journal", ".out.parquet.pinmob-lock"]  # as SIGKILL left them
    assert main(["sweep", str(a), "--out", str(out), "--force", *quiet]) == 0
    assert sweep_metadata(out)["complete"] and _dot_files(tmp_path) == []


def test_force_starts_this_sweeps_own_file_over(tmp_path, capsys):
    """--force recomputes every design of a finished sweep (it resumed it: nothing was recomputed); without it the
    run resumes. The file is the same either way (the same records)."""
    a = _spec(tmp_path, "a", 0.26, 0.32, m=3)
    out = tmp_path / "out.parquet"
    quiet = ["--no-progress", "--no-plots"]
    assert main(["sweep", str(a), "--out", str(out), *quiet]) == 0
    first = out.read_bytes()
    capsys.readouterr()
    assert main(["sweep", str(a), "--out", str(out), *quiet]) == 0
    assert "16 of 16 designs already written, skipped" in capsys.readouterr().out
    assert main(["sweep", str(a), "--out", str(out), "--force", *quiet]) == 0
    text = capsys.readouterr().out
    assert "starting over" in text and "16 designs computed" in text and "already written" not in text
    assert out.read_bytes() == first


def test_records_of_this_spec_by_another_pinmob_are_not_resumed(tmp_path, capsys):
    """The identity holds a digest of pinmob's code: a file of the same spec whose identity differs (another version,
    or changed code) is refused, saying so; --force starts over."""
    a = _spec(tmp_path, "a", 0.26, 0.32, m=3)
    out = tmp_path / "out.parquet"
    quiet = ["--no-progress", "--no-plots"]
    assert main(["sweep", str(a), "--out", str(out), *quiet]) == 0
    table = pq.read_table(out)
    meta = json.loads(table.schema.metadata[META])
    assert meta["spec"] == pinmob.load_spec(a).spec_digest() and meta["identity"] == pinmob.load_spec(a).identity()
    meta.update(identity="0" * 20, pinmob="0.0.9")
    pq.write_table(table.replace_schema_metadata({META: json.dumps(meta).encode()}), out)
    _one_line(capsys, ["sweep", str(a), "--out", str(out), *quiet], "another pinmob", "'0.0.9'", "--force")
    assert main(["sweep", str(a), "--out", str(out), "--force", *quiet]) == 0
    assert sweep_metadata(out)["identity"] == pinmob.load_spec(a).identity()


def test_a_store_interrupted_before_any_record_publishes_nothing(tmp_path):
    """An interruption before the first record: no file is created (the message said "0 of 16 designs are in
    out.parquet (marked incomplete)" of a file that did not exist), and an existing file is left as it was."""
    spec = pinmob.load_spec(_spec(tmp_path, "a", 0.26, 0.32))
    out = tmp_path / "out.parquet"
    store = Store(out, spec)
    with pytest.raises(KeyboardInterrupt), store:
        raise KeyboardInterrupt
    assert not out.exists() and store.in_file is None and store.state().endswith("not created")
    out.write_text("old\n")
    store = Store(out, spec, force=True)
    with pytest.raises(KeyboardInterrupt), store:
        raise KeyboardInterrupt
    assert out.read_text() == "old\n" and "left as it was" in store.state()
    assert _dot_files(tmp_path) == []


def test_the_interruption_message_is_true(tmp_path, dask_cluster):
    """SIGINT as soon as the journal exists (the first record may or may not have landed; the run held until then:
    :func:`held_runs.interrupted`): the message names exactly what the file holds, or says no file was created."""
    spec = _spec(tmp_path, "a", 0.26, 0.32, m=5)
    out, journal = tmp_path / "out.parquet", tmp_path / ".out.parquet.pinmob-journal"
    args = ["sweep", str(spec), "--out", str(out), "--no-progress", "--no-plots"]
    proc = interrupted(dask_cluster.scheduler_address, args, tmp_path / "gate", journal.exists, signal.SIGINT)
    text, err = proc.stdout, proc.stderr
    assert proc.returncode == 130 and "Traceback" not in err, err
    (line,) = [t for t in text.splitlines() if t.startswith("interrupted:")]
    if out.exists():
        meta = sweep_metadata(out)
        assert f"{meta['written']} of 16 designs are in {out}" in line and not meta["complete"]
        assert "run the same command to resume" in line
    else:
        assert line == f"interrupted: no record written; {out} not created"
    assert _dot_files(tmp_path) == []


def test_signals_during_a_deferred_step_are_raised_after_it():
    """A signal inside :func:`deferred_interrupts` does not cut the step: it is raised once the step is done."""
    steps = []
    with pytest.raises(KeyboardInterrupt), deferred_interrupts() as received:
        os.kill(os.getpid(), signal.SIGTERM)
        os.kill(os.getpid(), signal.SIGINT)
        time.sleep(0.05)  # the handlers have run by now
        steps.append("finished")
        assert received == [signal.SIGTERM, signal.SIGINT]
    assert steps == ["finished"]
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler  # restored


def test_a_store_publishes_whole_when_signals_come_during_its_last_steps(tmp_path):
    """A SIGINT delivered as the store's last journal flush starts, and another as its merge starts (sent from a
    profile hook at those calls: a real signal at a chosen point): the file is still published whole, then the
    interruption raised (a signal during the last flush or the journal's close skipped publishing)."""
    spec = pinmob.load_spec(_spec(tmp_path, "a", 0.26, 0.32))
    out = tmp_path / "out.parquet"
    store = Store(out, spec)
    store.__enter__()
    from pinmob.sweeps.record import empty_record

    job = spec.job()
    for i in range(spec.count):
        store.write(empty_record(job, i, spec.values(i)) | {"status": "failed", "reason": "test"})
    sent = []

    def at_call(frame, event, arg) -> None:
        if event == "call" and frame.f_code.co_name in ("_flush", "_publish") and "store" in frame.f_code.co_filename:
            sent.append(frame.f_code.co_name)
            os.kill(os.getpid(), signal.SIGINT)

    sys.setprofile(at_call)
    try:
        with pytest.raises(KeyboardInterrupt):
            store.__exit__(None, None, None)
    finally:
        sys.setprofile(None)
    assert sent == ["_flush", "_publish"]
    meta = sweep_metadata(out)
    assert meta is not None and meta["complete"] and meta["written"] == 16 and store.in_file == 16
    assert _dot_files(tmp_path) == []


def test_the_lock_is_released_when_opening_fails(tmp_path, capsys):
    """A journal of another sweep refuses the run after the lock was taken: the lock file goes too (it stayed)."""
    a, b = _spec(tmp_path, "a", 0.26, 0.32), _spec(tmp_path, "b", 0.3, 0.35)
    out = tmp_path / "out.parquet"
    journal = tmp_path / ".out.parquet.pinmob-journal"
    schema = pa.schema([pa.field("design", pa.int64())], metadata={META: json.dumps({"identity": "x"}).encode()})
    with pa.OSFile(str(journal), "wb") as sink, pa.ipc.new_stream(sink, schema):
        pass
    _one_line(capsys, ["sweep", str(a), "--out", str(out), "--no-progress"], "unfinished records of another sweep")
    assert _dot_files(tmp_path) == [".out.parquet.pinmob-journal"]
    del b


def test_one_run_at_a_time_writes_a_file(tmp_path):
    """While a store holds the file, another is refused; once released, another may open it."""
    spec = pinmob.load_spec(_spec(tmp_path, "a", 0.26, 0.32))
    out = tmp_path / "out.parquet"
    with Store(out, spec):
        with pytest.raises(ConfigurationError, match="another pinmob sweep is writing"), Store(out, spec):
            pass
        assert (tmp_path / ".out.parquet.pinmob-lock").exists()
    with Store(out, spec):
        pass
    assert _dot_files(tmp_path) == []


def test_outputs_must_name_different_files(tmp_path, capsys):
    """--out and --csv on one file lost the records; --atlas and --pareto on one file overwrote silently; a derived
    plot name counts too. One line, before any work, nothing written."""
    a = _spec(tmp_path, "a", 0.26, 0.32)
    out = str(tmp_path / "s.parquet")
    for extra in (["--csv", out], ["--atlas", str(tmp_path / "p.png"), "--pareto", str(tmp_path / "p.png")],
                  ["--pareto", str(tmp_path / "s_atlas.png")]):  # fmt: skip
        _one_line(capsys, ["sweep", str(a), "--out", out, *extra], "name the same file")
        assert capsys.readouterr().out == ""
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.toml"]


def test_the_number_of_designs_is_bounded(tmp_path, capsys):
    """A 1e5 x 1e5 grid allocated 9.3 GiB and died with a MemoryError: now one line naming the bound and how to
    raise it, at once; a grid whose count overflows 64 bits too; max_designs raises the bound."""
    for counts in ((100_000, 100_000), (10**10, 10**10)):
        text = SPEC.format(title="big", lo=0.26, hi=0.32, m=3).replace(", 4]", f", {counts[0]}]", 1)
        text = text.replace("0.4, 4]", f"0.4, {counts[1]}]")
        (tmp_path / "big.toml").write_text(text)
        _one_line(capsys, ["sweep", str(tmp_path / "big.toml")], f"{counts[0] * counts[1]:,} designs",
                  "bound of 1,000,000", "max_designs")  # fmt: skip
    text = (
        SPEC.format(title="big", lo=0.26, hi=0.32, m=3).replace(", 4]", ", 1500]", 1).replace("0.4, 4]", "0.4, 1000]")
    )
    (tmp_path / "big.toml").write_text(text.replace('method = "grid"', 'method = "grid"\nmax_designs = 2000000'))
    assert pinmob.load_spec(tmp_path / "big.toml").count == 1_500_000
    lhs = text.replace('method = "grid"', 'method = "latin-hypercube"\nsamples = 5000000')
    lhs = lhs.replace(", 1500]", "]").replace(", 1000]", "]")
    (tmp_path / "lhs.toml").write_text(lhs)
    _one_line(capsys, ["sweep", str(tmp_path / "lhs.toml")], "5,000,000 designs", "max_designs")


def test_the_code_digest_is_the_same_installed_and_in_the_checkout(tmp_path):
    """An installed pinmob holds the built-in models' folder (with its __init__.py) inside the package; the
    checkout has it beside: the digest of the code, which a resumed sweep must match, is the same for both (a
    sweep run by ``python -m pinmob`` in the checkout resumes the file of the installed ``pinmob``), and it
    still changes when a source file does."""
    import shutil

    from pinmob.sweeps.sweep_spec import package_digest

    checkout = tmp_path / "checkout" / "pinmob"
    shutil.copytree(Path(pinmob.__file__).resolve().parent, checkout, ignore=shutil.ignore_patterns("models"))
    installed = tmp_path / "installed" / "pinmob"
    shutil.copytree(checkout, installed)
    (installed / "models").mkdir()
    (installed / "models" / "__init__.py").write_text('"""The built-in models."""\n')
    (installed / "models" / "3puu.toml").write_text('name = "3-PUU"\n')
    assert package_digest(installed) == package_digest(checkout)
    (checkout / "sweeps" / "sweep_spec.py").write_text(
        (checkout / "sweeps" / "sweep_spec.py").read_text() + "\n# changed\n"
    )
    assert package_digest(installed) != package_digest(checkout)
