"""Sweep throughput: designs per second in process, on 1 and 2 local Dask workers, and the cost of one design.

Runs the example sweep's family (3-PUU) on a small design set (``--designs``, default 16) with the example's
per-design scan (9 x 9 samples), and prints:

* first, the versions the figures depend on (``bench_scan.versions``: Python, numpy, Pinocchio, numba, orjson,
  numpy's BLAS);
* designs/s in this process, on a LocalCluster of 1 worker and of 2 workers (cluster start-up excluded), beside
  the figure recorded before the speed-up of issue 33, item 4 (:data:`BEFORE_MS`) and the ratio to it; and, in a
  git checkout, the in-process figure of that commit's tree (``--before``, default :data:`BEFORE_COMMIT`) measured
  in this run, on this machine, in turns with this tree's (``git archive`` of its ``pinmob`` folder, run in a child
  process with the same packages; its first run, which compiles its numba kernels, is not timed);
* per design: building and loading the mechanism, the analysis at the reference (with the generic rank),
  the scan (assembly and analysis of every sample), and the scheduling overhead per design (time on 1 Dask
  worker minus time in process, per design);
* the estimate of a large sweep (``--estimate-designs`` x ``--estimate-samples`` on ``--estimate-workers``)
  from these figures: (per-design time scaled by samples) / workers + overhead.

    python benchmarks/bench_sweep.py [--designs 16] [--before COMMIT | --before none]
"""

from __future__ import annotations

import argparse
import logging
import os
import subprocess
import sys
import tarfile
import tempfile
import time
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
EXAMPLE = ROOT / "examples" / "3puu_sweep.toml"
#: The commit before issue 33's item 4, whose tree ``--before`` times in the same run.
BEFORE_COMMIT = "38fc101"
#: Rounds of the in-process timing of this tree and the ``--before`` tree, in turns (the fastest of each kept).
ROUNDS = 3

#: Milliseconds per design before the speed-up of issue 33, item 4 (commit 38fc101, 2026-12-06, on the 2-core
#: development machine, unloaded): this benchmark's 16 designs in process (the lead's measurement: 32.9 ms), and
#: on a LocalCluster of 2 workers (this benchmark run on 38fc101's tree the same day, load about 1).
BEFORE_MS = {"in process": 32.9, "2 Dask worker(s)": 24.9}


def _timed(run) -> tuple[float, list]:
    t0 = time.perf_counter()
    out = list(run)
    return time.perf_counter() - t0, out


def sweep_seconds(designs: int, runs: int) -> list[float]:
    """Seconds of ``pinmob.sweep`` of the example's family on ``designs`` designs in this process, ``runs`` times.

    The ``pinmob`` imported (this tree's, or another's on ``PYTHONPATH``) is the one timed; a first sweep of one
    design, not timed, loads or compiles its numba kernels.
    """
    import numpy as np

    import pinmob

    spec = example_spec(designs)
    list(pinmob.sweep(spec, skip=np.arange(spec.count) > 0))
    return [_timed(pinmob.sweep(spec))[0] for _ in range(runs)]


def example_spec(designs: int) -> Any:
    """The example sweep's family and scan on a grid of at least ``designs`` designs (its side rounded up)."""
    from dataclasses import replace

    import numpy as np

    import pinmob
    from pinmob.sweeps.designs import DesignSet

    side = int(np.ceil(np.sqrt(designs)))
    spec = pinmob.load_spec(EXAMPLE)
    return replace(spec, designs=DesignSet("grid", ("link", "big_r"), ((0.26, 0.35, side), (0.2, 0.3, side))))


def _tree(commit: str, folder: Path) -> Path | None:
    """``commit``'s ``pinmob`` folder written under ``folder`` (``git archive``), or None outside a git checkout."""
    try:
        data = subprocess.run(["git", "-C", str(ROOT), "archive", "--format=tar", commit, "pinmob"],
                              capture_output=True, check=True, timeout=60).stdout  # fmt: skip
    except (OSError, subprocess.SubprocessError):
        return None
    archive = folder / "tree.tar"
    archive.write_bytes(data)
    with tarfile.open(archive) as tar:
        tar.extractall(folder, filter="data")
    return folder


def _child_seconds(tree: Path, designs: int) -> float:
    """One timed in-process sweep of ``designs`` designs by the ``pinmob`` of ``tree``, in a child process [s]."""
    env = {**os.environ, "PYTHONPATH": str(tree)}
    code = f"import sys; sys.path.insert(0, {str(Path(__file__).parent)!r}); import bench_sweep as b; "
    code += f"print(min(b.sweep_seconds({designs}, 1)))"
    out = subprocess.run([sys.executable, "-c", code], env=env, cwd=tree, capture_output=True, text=True,
                         check=True, timeout=1800)  # fmt: skip
    return float(out.stdout.split()[-1])


def _same_run(commit: str, designs: int) -> tuple[float, float] | None:
    """Seconds per design of ``commit``'s tree and of this one, each the fastest of ``ROUNDS`` child runs in turns."""
    with tempfile.TemporaryDirectory() as folder:
        tree = _tree(commit, Path(folder))
        if tree is None:
            return None
        mine, theirs = [], []
        for _ in range(ROUNDS):
            theirs.append(_child_seconds(tree, designs))
            mine.append(_child_seconds(ROOT, designs))
    return min(theirs) / designs, min(mine) / designs


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--designs", type=int, default=16)
    parser.add_argument(
        "--before",
        default=BEFORE_COMMIT,
        help=f"a commit whose tree is timed in process in this run (default {BEFORE_COMMIT}; none: skip)",
    )
    parser.add_argument("--estimate-designs", type=int, default=100_000)
    parser.add_argument("--estimate-samples", type=int, default=400)
    parser.add_argument("--estimate-workers", type=int, default=64)
    args = parser.parse_args()

    import numpy as np
    from bench_scan import versions  # this folder's
    from dask.distributed import Client, LocalCluster

    import pinmob
    from pinmob.analysis.entry_point import analyze
    from pinmob.parallel.cluster import WORKER_SETUP
    from pinmob.scan.scan_run import scan_in_process

    spec = example_spec(args.designs)
    samples = spec.scan.axes[0][3] * spec.scan.axes[1][3]
    list(pinmob.sweep(spec, skip=np.arange(spec.count) > 0))  # warm-up (numba cache, imports)

    # per-design split, in process
    build = analysis = scanning = 0.0
    for i in range(spec.count):
        with tempfile.TemporaryDirectory() as folder:
            t0 = time.perf_counter()
            mech = spec.source.mechanism(spec.values(i), Path(folder))
            t1 = time.perf_counter()
            scan = spec.scan.spec(mech)
            analyze(mech, scan.q_ref, rtol=scan.rtol, generic_rank=scan.generic_rank).mechanism_mobility  # noqa: B018
            t2 = time.perf_counter()
            for _ in scan_in_process(mech, scan):
                pass
            t3 = time.perf_counter()
        build, analysis, scanning = build + t1 - t0, analysis + t2 - t1, scanning + t3 - t2
    n = spec.count
    serial, records = _timed(pinmob.sweep(spec))
    rates = {"in process": n / serial}
    for workers in (1, 2):
        cluster = LocalCluster(n_workers=workers, threads_per_worker=1, host="127.0.0.1",
                               dashboard_address="127.0.0.1:0", silence_logs=logging.CRITICAL,
                               preload=[WORKER_SETUP])  # fmt: skip
        with cluster, Client(cluster) as client:  # started here: start-up not timed
            client.run(lambda: __import__("pinmob"))
            list(pinmob.sweep(spec, scheduler=cluster.scheduler_address, skip=np.arange(spec.count) >= workers))
            elapsed, dask_records = _timed(pinmob.sweep(spec, scheduler=cluster.scheduler_address))
            assert dask_records == records, "Dask records differ from the serial ones"
            rates[f"{workers} Dask worker(s)"] = n / elapsed
            if workers == 1:
                overhead = (elapsed - serial) / n
    print("versions: " + ", ".join(f"{k} {v}" for k, v in versions().items()))
    print(f"{n} designs of {spec.source.name} with a {samples}-sample scan each ({spec.scan.describe()})")
    for where, rate in rates.items():
        line = f"  {where:18s} {rate:6.2f} designs/s ({1e3 / rate:5.1f} ms per design)"
        before = BEFORE_MS.get(where)
        if before:
            line += (
                f"   before (38fc101): {1e3 / before:6.2f} designs/s ({before:.1f} ms), now x{rate * before / 1e3:.2f}"
            )
        print(line)
    if args.before != "none":
        pair = _same_run(args.before, n)
        if pair is None:
            print(f"  (not a git checkout with {args.before}: its tree not timed in this run)")
        else:
            old, new = pair
            print(f"  in process, in turns with {args.before}'s tree in child processes (fastest of {ROUNDS} each): "
                  f"{new * 1e3:.1f} ms per design, {args.before}'s {old * 1e3:.1f} ms, now x{old / new:.2f}")  # fmt: skip
    per = serial / n
    print(f"per design {per * 1e3:.0f} ms in process: mechanism built and loaded {build / n * 1e3:.1f} ms, "
          f"reference analysis + generic rank {analysis / n * 1e3:.1f} ms, scan {scanning / n * 1e3:.1f} ms "
          f"({scanning / n / samples * 1e3:.2f} ms per sample: assembly + analysis); "
          f"scheduling overhead on Dask {overhead * 1e3:.1f} ms per design")  # fmt: skip
    big = (build + analysis) / n + scanning / n / samples * args.estimate_samples
    total = args.estimate_designs * (big + max(overhead, 0.0)) / args.estimate_workers
    print(f"estimate: {args.estimate_designs} designs x {args.estimate_samples} samples on {args.estimate_workers} "
          f"workers of this speed: {big * 1e3:.0f} ms per design, {_duration(total)}")  # fmt: skip


def _duration(seconds: float) -> str:
    """A duration in the unit that shows it: hours from one hour, else minutes from one minute, else seconds."""
    if seconds >= 3600:
        return f"{seconds / 3600:.1f} h"
    return f"{seconds / 60:.1f} min" if seconds >= 60 else f"{seconds:.0f} s"


if __name__ == "__main__":
    main()
