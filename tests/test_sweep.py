"""Design-space sweeps: serial == Dask records, a killed worker, interrupted and resumed files, bad specs."""

from __future__ import annotations

import dataclasses
import itertools
import pickle
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest
import sweep_specs
import worker_plugins
from held_runs import interrupted
from worker_plugins import KillOnFirstChunk

import pinmob
from pinmob.cli import main
from pinmob.exceptions import ConfigurationError
from pinmob.sweeps.designs import DesignSet, latin_hypercube
from pinmob.sweeps.reading import journal_records
from pinmob.sweeps.store import sweep_metadata
from pinmob.sweeps.sweep_plot import pareto_front, written_by

PINMOB = [sys.executable, "-m", "pinmob"]
ROOT = Path(__file__).parent.parent


#: n x n designs: link in [0.2, 0.35], big_r in [0.25, 0.4]
SPEC = sweep_specs.SPEC.replace("{title}", "s").replace("{lo}", "0.2").replace("{hi}", "0.35")


def _spec(folder: Path, n: int = 3, m: int = 5, name: str = "s.toml") -> Path:
    path = folder / name
    path.write_text(SPEC.format(n=n, m=m))
    return path


def _same_records(a: list[dict], b: list[dict]) -> bool:
    return a == b  # no NaN in records: missing values are None


def test_distributed_records_equal_the_serial_ones(tmp_path, dask_cluster):
    spec = pinmob.load_spec(_spec(tmp_path))
    serial = list(pinmob.sweep(spec))
    run = pinmob.sweep(spec, scheduler=dask_cluster.scheduler_address)
    assert _same_records(list(run), serial) and "Dask cluster at" in run.where
    assert [r["design"] for r in serial] == list(range(9))
    statuses = {r["status"] for r in serial}
    assert statuses == {"ok", "failed"}  # link 0.2 < R - r = 0.25 cannot hang the platform: a record, no crash
    bad = [r for r in serial if r["status"] == "failed"]
    assert all(r["link"] <= abs(r["big_r"] - 0.15) and "longer than" in r["reason"] for r in bad)
    good = [r for r in serial if r["status"] == "ok"]
    assert all(r["dof"] == 3 and r["motion_type"] == "3T" and r["samples"] == 25 for r in good)
    assert all(0 <= r["assembled"] <= 1 and r["min_distance"] >= 0 for r in good)


def test_a_design_record_agrees_with_pinmob_scan(tmp_path):
    """The default family design is the built-in 3-PUU: its record's counts are those of `pinmob scan` there."""
    (tmp_path / "one.toml").write_text(
        'family = "3-PUU"\n[design]\nmethod = "table"\nrows = [{link = 0.25}]\n'
        '[scan]\ngrid = ["x:-0.12:0.14:9", "y:-0.14:0.14:9"]\nat = "generic"\n'
    )
    (record,) = list(pinmob.sweep(tmp_path / "one.toml"))
    from pinmob.scan import grid_spec, scan

    mech = pinmob.load("3-PUU")
    rows = list(scan(mech, grid_spec(mech, "generic", [("x", -0.12, 0.14, 9), ("y", -0.14, 0.14, 9)])))
    samples = [r for r in rows if not r["refined"]]
    reach = [r for r in samples if r["reachable"]]
    assert record["samples"] == 81 and record["assembled"] == len(reach) / 81
    assert record["singularity_free"] == sum(r["singularity"] == "none" for r in reach) / len(reach)
    assert record["min_distance"] == min(r["distance"] for r in rows if r["reachable"])
    assert record["refined_points"] == sum(r["refined"] for r in rows)


def test_a_design_mechanism_is_the_one_its_written_files_load(tmp_path):
    """A family design's URDF is parsed once (the model the TOML was written with is loaded): the mechanism equals
    the one pinmob.load reads from the files written, model included (joint placements, limits, names)."""
    spec = pinmob.load_spec(ROOT / "examples" / "3puu_sweep.toml")
    for i in (0, 24, 48):
        folder = tmp_path / str(i)
        folder.mkdir()
        mech = spec.source.mechanism(spec.values(i), folder)
        again = pinmob.load(folder / "design.toml")
        assert mech.model == again.model and mech.model is not again.model
        for field in dataclasses.fields(mech):  # every field to the last bit (pickled), the model's below
            if field.name not in ("model", "geometry"):
                assert pickle.dumps(getattr(mech, field.name)) == pickle.dumps(getattr(again, field.name)), field.name
        for a, b in zip(mech.model.jointPlacements, again.model.jointPlacements, strict=True):
            assert a.homogeneous.tobytes() == b.homogeneous.tobytes()
        assert mech.model.lowerPositionLimit.tobytes() == again.model.lowerPositionLimit.tobytes()
        assert mech.model.upperPositionLimit.tobytes() == again.model.upperPositionLimit.tobytes()
        assert list(mech.model.names) == list(again.model.names) and mech.source == again.source


def test_cli_sweep_survives_a_killed_worker(tmp_path, dask_cluster):
    """The worker that starts the first design is killed while it computes it (a worker plugin: whatever the
    machine's speed); Dask computes the design again and the file is the serial one."""
    import cloudpickle
    from dask.distributed import Client

    cloudpickle.register_pickle_by_value(worker_plugins)  # the workers cannot import the tests
    spec = _spec(tmp_path, n=3, m=7)
    assert main(["sweep", str(spec), "--out", str(tmp_path / "serial.parquet"), "--no-progress", "--no-plots"]) == 0
    flag = tmp_path / "killed"
    with Client(dask_cluster.scheduler_address) as client:
        plugin = KillOnFirstChunk(str(flag), int(signal.SIGKILL))
        client.register_plugin(plugin, name=KillOnFirstChunk.name)
        try:
            run = subprocess.run([*PINMOB, "sweep", str(spec), "--out", str(tmp_path / "dask.parquet"), "--no-plots",
                                  "--scheduler", dask_cluster.scheduler_address], capture_output=True, text=True,
                                 timeout=240)  # fmt: skip
        finally:
            client.unregister_worker_plugin(KillOnFirstChunk.name)
    # the killed worker's nanny starts another; the dask_cluster fixture waits for it (or replaces the cluster)
    # before the next test: waiting here for a fixed minute failed under load (1 of 2 workers after 60 s)
    assert flag.exists(), "no design ever ran on the cluster"
    assert run.returncode == 0, run.stderr
    assert "lost and replaced" in run.stdout
    assert pq.read_table(tmp_path / "dask.parquet").equals(pq.read_table(tmp_path / "serial.parquet"))


def test_a_worker_lost_after_the_last_look_is_counted(tmp_path, dask_cluster, monkeypatch):
    """A sweep's count of lost workers includes the map's last look, taken once every design is in. With the
    periodic looks pushed beyond the run (``POLL``), the worker killed on the first design is seen by that look
    only: the count read as each result came in missed it (``lost and replaced`` absent from the summary of
    :func:`test_cli_sweep_survives_a_killed_worker` once, on a loaded machine)."""
    import cloudpickle
    from dask.distributed import Client

    import pinmob.parallel.tasks as tasks

    cloudpickle.register_pickle_by_value(worker_plugins)  # the workers cannot import the tests
    monkeypatch.setattr(tasks, "POLL", 1e6)
    spec = pinmob.load_spec(_spec(tmp_path, n=2, m=5))
    flag = tmp_path / "killed"
    with Client(dask_cluster.scheduler_address) as client:
        client.register_plugin(KillOnFirstChunk(str(flag), int(signal.SIGKILL)), name=KillOnFirstChunk.name)
        try:
            run = pinmob.sweep(spec, scheduler=dask_cluster.scheduler_address)
            records = list(run)
        finally:
            client.unregister_worker_plugin(KillOnFirstChunk.name)
    assert flag.exists(), "no design ever ran on the cluster"
    assert [r["design"] for r in records] == [0, 1, 2, 3]
    assert run.lost_workers == 1


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("whole")
    whole = folder / "whole.parquet"
    assert main(["sweep", str(_spec(folder, n=6, m=5)), "--out", str(whole), "--no-progress", "--no-plots"]) == 0
    return whole


@pytest.mark.parametrize("sig", ["SIGINT", "SIGTERM", "SIGKILL"])
def test_resuming_an_interrupted_sweep_gives_the_uninterrupted_file(tmp_path, sig, uninterrupted, dask_cluster):
    """Interrupted once the first records are in the journal (handled: the file so far is published, marked
    incomplete; SIGKILL: the journal beside the file is recovered), then run again with the same command: the
    same file, byte for byte, as a run never interrupted.

    The interrupted run computes its designs on the test's cluster, where a worker plugin holds every design past
    the first six until the test has sent the signal: the run is interrupted while running, whatever the machine's
    speed (a signal sent on seeing the journal raced the run's end).
    """
    spec = _spec(tmp_path, n=6, m=5)
    whole, cut = uninterrupted, tmp_path / "cut.parquet"
    args = ["sweep", str(spec), "--out", str(cut), "--no-progress", "--no-plots"]
    journal = tmp_path / ".cut.parquet.pinmob-journal"

    def ready() -> bool:  # the journal holds a record (read as the store reads it: complete batches only)
        return 0 < sum(1 for _ in journal_records(journal)) < 36

    proc = interrupted(dask_cluster.scheduler_address, args, tmp_path / "gate", ready, getattr(signal, sig))
    out, err = proc.stdout, proc.stderr
    if sig == "SIGKILL":
        assert proc.returncode == -9 and journal.exists()
    else:
        assert proc.returncode == 130 and "Traceback" not in err and "run the same command to resume" in out
        meta = sweep_metadata(cut)
        assert meta is not None and not meta["complete"] and 0 < meta["written"] < 36
    again = subprocess.run([*PINMOB, *args], capture_output=True, text=True, timeout=120)
    assert again.returncode == 0, again.stderr
    assert "resuming" in again.stdout and "already written, skipped" in again.stdout
    assert pq.read_table(cut).equals(pq.read_table(whole))
    assert sweep_metadata(cut) == sweep_metadata(whole) and sweep_metadata(cut)["complete"]
    assert cut.read_bytes() == whole.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []


def _one_line_error(capsys, args: list[str], *words: str) -> None:
    assert main(args) == 2
    captured = capsys.readouterr()
    err = captured.err
    assert err.count("\n") == 1 and err.startswith("pinmob: error:"), err
    assert all(w in err for w in words), err
    assert captured.out == ""  # before any work: the sweep's first line ("sweep ...: N designs") not printed


def test_bad_specs_are_one_line_errors_before_any_work(tmp_path, capsys):
    out = tmp_path / "o.parquet"
    cases = [
        (SPEC.replace("small_r", "smal_r"), ["unknown parameter 'smal_r'", "'small_r'", "'link'"]),
        (SPEC.replace("[0.2, 0.35, {n}]", "[0.35, 0.2, 3]"), ["empty range", "design.parameters.link"]),
        (SPEC.replace("[0.2, 0.35, {n}]", "[0.2, 0.35, 0]"), ["empty range"]),
        (SPEC.replace('"3-PUU"', '"3-PUX"'), ["unknown family '3-PUX'", "'3-PUU'", "'Delta-3RUU'"]),
        (SPEC.replace('method = "grid"', 'method = "sobol"'), ["design.method", "'latin-hypercube'"]),
        (SPEC.replace('at = "generic"', 'at = "nowhere"'), ["'nowhere'", "'generic'", "'offset'"]),
        (SPEC + "colour = 1\n", ["unknown key 'scan.colour'"]),
    ]
    for text, words in cases:
        (tmp_path / "bad.toml").write_text(text.format(n=3, m=5))
        _one_line_error(capsys, ["sweep", str(tmp_path / "bad.toml"), "--out", str(out)], *words)
        assert not out.exists()
    # a template placeholder with no value
    shutil.copy(ROOT / "models" / "3puu.urdf", tmp_path / "3puu.urdf")
    text = (ROOT / "models" / "3puu.toml").read_text().replace("name = ", "length_scale = {L * k}\nname = ", 1)
    (tmp_path / "robot.toml").write_text(text)
    (tmp_path / "t.toml").write_text('template = "robot.toml"\n[design]\n[design.parameters]\nL = [0.2, 0.3, 2]\n')
    _one_line_error(capsys, ["sweep", str(tmp_path / "t.toml")], "placeholder {L * k}", "'k'", "no value")
    (tmp_path / "t.toml").write_text('template = "robot.toml"\n[parameters]\nk = 1\nq = 2\n[design]\n'
                                     "[design.parameters]\nL = [0.2, 0.3, 2]\n")  # fmt: skip
    _one_line_error(capsys, ["sweep", str(tmp_path / "t.toml")], "unknown parameter 'q'", "'L'", "'k'")
    # a placeholder whose value is complex here ((-0.8) ** 0.5): a traceback at load, "internal error" records later
    text = (ROOT / "models" / "3puu.toml").read_text().replace("name = ", "length_scale = {(L - 1) ** 0.5}\nname = ", 1)
    (tmp_path / "robot.toml").write_text(text)
    (tmp_path / "t.toml").write_text('template = "robot.toml"\n[design]\n[design.parameters]\nL = [0.2, 0.3, 2]\n')
    _one_line_error(capsys, ["sweep", str(tmp_path / "t.toml")], "placeholder {(L - 1) ** 0.5}", "not a real number")
    # the finite analysis's keys
    for extra, words in (("finite = false\nfinite_order = 3\n", ["finite_order", "finite = false"]),
                         ("finite_order = 9\n", ["finite_order", "from 2 to 8"]),
                         ('finite = "yes"\n', ["finite must be true or false"])):  # fmt: skip
        (tmp_path / "bad.toml").write_text(extra + SPEC.format(n=3, m=5))
        _one_line_error(capsys, ["sweep", str(tmp_path / "bad.toml")], *words)


def test_a_template_sweep_fills_its_placeholders(tmp_path):
    shutil.copy(ROOT / "models" / "3puu.urdf", tmp_path / "3puu.urdf")
    text = (ROOT / "models" / "3puu.toml").read_text().replace("name = ", "length_scale = {L * k}\nname = ", 1)
    (tmp_path / "robot.toml").write_text(text)
    (tmp_path / "t.toml").write_text('template = "robot.toml"\n[parameters]\nk = 2\n[design]\n[design.parameters]\n'
                                     'L = [0.1, 0.3, 2]\n[scan]\nfrom = "generic"\nto = "offset"\nsamples = 4\n')  # fmt: skip
    records = list(pinmob.sweep(tmp_path / "t.toml"))
    assert [r["L"] for r in records] == [0.1, 0.3] and all(r["status"] == "ok" for r in records)
    assert all((r["dof"], r["motion_type"], r["samples"]) == (3, "3T", 4) for r in records)  # units don't matter


def test_an_existing_file_of_another_sweep_is_kept(tmp_path, capsys):
    out = tmp_path / "o.parquet"
    out.write_text("mine")
    _one_line_error(capsys, ["sweep", str(_spec(tmp_path)), "--out", str(out)], "not a pinmob sweep file", "--force")
    assert out.read_text() == "mine"
    link = tmp_path / "l.parquet"
    link.symlink_to(tmp_path / "elsewhere.parquet")
    _one_line_error(capsys, ["sweep", str(_spec(tmp_path)), "--out", str(link), "--force"], "symbolic link")
    assert not (tmp_path / "elsewhere.parquet").exists()


def test_plots_and_csv_are_written_and_recognised(tmp_path, capsys):
    spec = _spec(tmp_path)
    out = tmp_path / "s.parquet"
    assert main(["sweep", str(spec), "--out", str(out), "--csv", str(tmp_path / "s.csv"), "--no-progress"]) == 0
    capsys.readouterr()
    for png in ("s_atlas.png", "s_pareto.png"):
        assert written_by(tmp_path / png) == f"pinmob sweep {pinmob.load_spec(spec).identity()}"
    assert len((tmp_path / "s.csv").read_text().splitlines()) == 10
    # re-running the finished sweep skips every design and may replace its own plots, not the CSV
    assert main(["sweep", str(spec), "--out", str(out), "--no-progress"]) == 0
    assert "9 of 9 designs already written" in capsys.readouterr().out


def test_design_sets_against_their_definitions():
    grid = DesignSet("grid", ("a", "b"), ((0.0, 1.0, 3), (10.0, 20.0, 2)))
    assert [tuple(grid.values(i).values()) for i in range(grid.count)] == list(
        itertools.product([0.0, 0.5, 1.0], [10.0, 20.0])
    )
    random = DesignSet("random", ("a",), ((2.0, 3.0, 0),), samples=50, seed=7)
    values = [random.values(i)["a"] for i in range(50)]
    assert all(2 <= v <= 3 for v in values) and len(set(values)) == 50
    longer = DesignSet("random", ("a",), ((2.0, 3.0, 0),), samples=80, seed=7)
    assert [longer.values(i)["a"] for i in range(50)] == values  # design i does not depend on the count
    lhs = latin_hypercube(((0.0, 1.0, 0), (-1.0, 1.0, 0)), 20, seed=3)
    for column, (lo, hi) in zip(lhs.T, ((0.0, 1.0), (-1.0, 1.0))):
        bins = np.floor((column - lo) / (hi - lo) * 20).astype(int)
        assert sorted(bins) == list(range(20))  # one sample in each of the 20 strata


def test_pareto_front_against_brute_force():
    rng = np.random.default_rng(5)
    for goals in (("max", "max"), ("max", "min"), ("min", "min")):
        xs, ys = rng.random(60), rng.random(60)
        sx, sy = (xs if goals[0] == "max" else -xs), (ys if goals[1] == "max" else -ys)
        truth = {i for i in range(60) if not any(sx[j] >= sx[i] and sy[j] >= sy[i] and (sx[j] > sx[i] or sy[j] > sy[i])
                                                 for j in range(60))}  # fmt: skip
        assert set(pareto_front(xs, ys, *goals).tolist()) == truth


def test_workers_is_checked(tmp_path, capsys):
    _one_line_error(capsys, ["sweep", str(_spec(tmp_path)), "--workers", "0"], "--workers")
    with pytest.raises(ConfigurationError, match="^workers must be a whole number"):
        pinmob.sweep(_spec(tmp_path), workers=0)


def test_finite_mobility_in_each_record(tmp_path):
    """``finite = true``: each record adds the finite analysis at the reference configuration. The 3-PUU's generic
    configuration is regular (no constraint nor limb singularity): the closed set is a manifold of constant rank
    there, so the finite DoF equal the instantaneous ones (3, every motion finite) and, the sliders held, 0."""
    (tmp_path / "f.toml").write_text(
        'family = "3-PUU"\nfinite = true\n[design]\nmethod = "table"\nrows = [{link = 0.25}, {link = 0.3}]\n'
        '[scan]\nfrom = "generic"\nto = "offset"\nsamples = 3\n'
    )
    spec = pinmob.load_spec(tmp_path / "f.toml")
    assert spec.finite_order == 4 and [n for n, _ in spec.fields()][-4:] == [
        "finite_dof", "finite_mechanism_dof", "finite_dof_locked", "finite_motions"]  # fmt: skip
    for record in pinmob.sweep(spec):
        assert record["status"] == "ok" and record["dof"] == 3 and record["mechanism_dof"] == 3
        assert (record["finite_dof"], record["finite_mechanism_dof"], record["finite_dof_locked"]) == (3, 3, 0)
        assert record["finite_motions"] == "T1 x: finite; T2 y: finite; T3 z: finite"
    plain = pinmob.load_spec(_spec(tmp_path))
    assert plain.finite_order is None and "finite_dof" not in [n for n, _ in plain.fields()]
    assert plain.identity() != spec.identity()


def test_a_design_task_carries_its_values_not_the_design_table(tmp_path):
    """What a Dask task needs besides its (index, values) is the same for 10 and for 100,000 Latin-hypercube designs
    (each task carried the whole spec, design table included: 1.6 MB per task for 100,000 designs)."""
    import pickle

    sizes = []
    for samples in (10, 100_000):
        text = SPEC.format(n=3, m=5).replace('method = "grid"', f'method = "latin-hypercube"\nsamples = {samples}')
        (tmp_path / "lhs.toml").write_text(text.replace(", 3]", "]"))
        spec = pinmob.load_spec(tmp_path / "lhs.toml")
        assert spec.count == samples
        sizes.append(len(pickle.dumps(spec.job())))
    assert sizes[0] == sizes[1] < 10_000
