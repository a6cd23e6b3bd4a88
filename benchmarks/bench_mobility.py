"""Speed of pinmob's analyses, each figure beside its reference, in one run.

Per mechanism (3-PUU, 6-UPS), at N fixed closed configurations (microseconds per configuration):

* ``baseline_us``: the plain numpy loop a user would write to count the DoF: Pinocchio kinematics and
  each limb tip's Jacobian, ``np.linalg.svd`` of each limb's dimensionless joint screws (its wrenches:
  the left singular vectors beyond its rank), ``np.linalg.svd`` of the stacked wrenches (the constraint
  rank), ranks decided as :func:`pinmob.screw.rank.decide_rank` decides them;
* ``floor_us``: what the batch path needs from Pinocchio (``computeJointJacobians`` and the platform
  frame's placement, in the same Python loop);
* ``batch_us``: :func:`pinmob.analysis.batch.analyze_batch` on all N at once (DoF, constraint rank, limb
  twist ranks, locked DoF; numba's compiled loop when numba is installed, else batched numpy; the text
  line also gives the numpy engine's time);
* ``single_us``: one :func:`pinmob.analyze` call plus ``to_dict()`` of its Report at a named configuration
  of a loaded mechanism: everything ``pinmob analyze`` prints, nothing left lazy (the per-mechanism
  generic ranks estimated by a first call; the named configuration is closed at every call: 6-UPS's
  ``generic`` is a platform pose, assembled by the first call and kept by the mechanism, its closure
  checked again at every call);
* ``document_us``: building the Python objects of that report's JSON document alone, from its text
  (``json.loads``, in C): a reference for what the answer's objects cost without any analysis
  (``pickle.loads`` of the same objects takes about half);
* ``scan_us``: one sample of a path scan with re-assembly (:func:`pinmob.scan.scan_run.scan`, one worker:
  3-PUU ``generic -> offset``, 6-UPS ``home -> type2``; wall time over the samples, refinements included).

Per process (wall seconds, median of several fresh interpreters, run in turn):

* ``import_s``: ``python -c "import pinmob"``; ``import_pinocchio_s``: ``python -c "import pinocchio"``;
* ``cli_s``: ``pinmob analyze 3-PUU --config generic`` (load, analysis, printing);

pinmob's modules compiled to bytecode first, as an installed package has them (pip compiles at install;
an editable install is not compiled, and with ``PYTHONDONTWRITEBYTECODE`` set Python would compile
pinmob's sources in every fresh interpreter while numpy's and Pinocchio's come compiled).

Targets (each line says whether it is met): ``single_us <= baseline_us`` (the whole answer no slower than
the naive DoF count), ``scan_us <= 1.5 single_us``, ``import_s <= 1.4 import_pinocchio_s``,
``cli_s <= 2 import_pinocchio_s``. Then the peak Python memory (tracemalloc) of a 3-PUU scan streamed
to CSV and JSON files, for n and 8n samples (after a warm-up scan): flat when the ratio is near 1.

Usage: ``python benchmarks/bench_mobility.py [--quick]``; the last line printed is one JSON object,
one entry per model.
"""

from __future__ import annotations

import argparse
import compileall
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import tracemalloc
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pinocchio as pin

import pinmob
from pinmob.analysis.batch.batch_analysis import analyze_batch
from pinmob.scan import pose_vector
from pinmob.scan.scan_run import scan
from pinmob.scan.scan_spec import path_spec, platform_pose
from pinmob.screw.algebra import twist_scaling
from pinmob.screw.rank import RTOL

CONFIG = {"3-PUU": "generic", "6-UPS": "generic"}
SCAN = {"3-PUU": ("generic", "offset"), "6-UPS": ("home", "type2")}


def closed_configurations(mech: pinmob.Mechanism, n: int, seed: int = 0) -> np.ndarray:
    """n closed configurations: random platform poses near the generic one, assembled."""
    rng = np.random.default_rng(seed)
    q0 = pinmob.closed_configuration(mech, CONFIG[mech.name])
    base = pose_vector(platform_pose(mech, q0))
    out: list[np.ndarray] = []
    translational = mech.name.startswith("3-PUU")
    while len(out) < n:
        v = base.copy()
        v[:3] += rng.uniform(-0.03, 0.03, 3)
        if not translational:
            v[3:] += rng.uniform(-0.1, 0.1, 3)
        try:
            out.append(pinmob.assemble_pose(mech, pin.SE3(pin.rpy.rpyToMatrix(v[3:]), v[:3]), q0))
        except pinmob.ClosureError:
            continue
    return np.array(out)


def floor(mech: pinmob.Mechanism, qs: np.ndarray) -> None:
    model, data, pid = mech.model, mech.model.createData(), mech.platform_id
    for q in qs:
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacement(model, data, pid)


def baseline_one(mech: pinmob.Mechanism, data: pin.Data, q: np.ndarray, rtol: float = RTOL) -> int:
    """The constraint rank at q, the way a user would write it with numpy."""
    model = mech.model
    st = twist_scaling(mech.length_scale)[:, None]
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    wrenches = []
    for limb in mech.limbs:
        jac = pin.getFrameJacobian(model, data, limb.tip_id, pin.LOCAL_WORLD_ALIGNED)[:, limb.v_indices]
        u, s, _ = np.linalg.svd(st * jac)
        wrenches.append(u[:, int(np.sum(s > rtol * s[0])) :])
    s = np.linalg.svd(np.hstack(wrenches).T, compute_uv=False)
    return int(np.sum(s > rtol * s[0])) if s.size else 0


def baseline(mech: pinmob.Mechanism, qs: np.ndarray) -> list[int]:
    data = mech.model.createData()
    return [baseline_one(mech, data, q) for q in qs]


def best_us(fn: Callable[[], object], n: int, repeats: int) -> float:
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best / n * 1e6


def single(mech: pinmob.Mechanism, name: str, n: int) -> None:
    for _ in range(n):
        pinmob.analyze(mech, name).to_dict()


def bench_analyses(name: str, n: int, repeats: int) -> tuple[dict[str, float], str]:
    """The per-configuration figures of one mechanism, and the batch engine that ran."""
    mech = pinmob.load(name)
    qs = closed_configurations(mech, n)
    batch = analyze_batch(mech, qs)
    assert list(batch.constraint_rank) == baseline(mech, qs), "batch and baseline disagree"
    single(mech, CONFIG[name], 1)  # per-mechanism caches (the generic ranks) filled once
    single_n = max(20, n // 10)
    text = json.dumps(pinmob.analyze(mech, CONFIG[name]).to_dict())
    out = {
        "baseline_us": best_us(lambda: baseline(mech, qs), n, repeats),
        "floor_us": best_us(lambda: floor(mech, qs), n, repeats),
        "batch_us": best_us(lambda: analyze_batch(mech, qs), n, repeats),
        "single_us": best_us(lambda: single(mech, CONFIG[name], single_n), single_n, repeats),
        "document_us": best_us(lambda: [json.loads(text) for _ in range(single_n)], single_n, repeats),
        "batch_numpy_us": best_us(lambda: analyze_batch(mech, qs, engine="numpy"), n, repeats),
    }
    return {k: round(v, 1) for k, v in out.items()}, batch.engine


def bench_scan(name: str, samples: int, repeats: int) -> dict[str, float]:
    mech = pinmob.load(name)
    spec = path_spec(mech, *SCAN[name], samples)
    sum(1 for _ in scan(mech, path_spec(mech, *SCAN[name], 5), progress=False))  # caches filled once
    rows = sum(1 for _ in scan(mech, spec, progress=False))
    us = best_us(lambda: sum(1 for _ in scan(mech, spec, workers=1, progress=False)), samples, repeats)
    return {"scan_us": round(us, 1), "rows": rows}


def compile_pinmob() -> str:
    """Compile pinmob's modules to bytecode, as ``pip install`` does for the package and its dependencies.

    An editable install is not compiled, and Python does not write the bytecode itself when
    ``PYTHONDONTWRITEBYTECODE`` is set: every fresh interpreter would then compile pinmob's sources
    (about 35 ms) while numpy's and Pinocchio's come compiled. Returns a note for the printed line.
    """
    package = Path(pinmob.__file__).parent
    ok = compileall.compile_dir(str(package), quiet=2)
    said = "set" if os.environ.get("PYTHONDONTWRITEBYTECODE") else "not set"
    done = "compiled" if ok else "NOT all compiled (read-only?)"
    return f"pinmob's bytecode {done} first, as pip install does; PYTHONDONTWRITEBYTECODE {said} here"


def wall_medians(rounds: int) -> dict[str, float]:
    """Median wall time [s] of fresh interpreters: import pinocchio, import pinmob, pinmob analyze (in turn).

    pinmob's bytecode is compiled first (:func:`compile_pinmob`), as it is in an installed package.
    """
    script = Path(sys.executable).with_name("pinmob")
    cli = [str(script)] if script.exists() else [sys.executable, "-m", "pinmob"]
    commands = {
        "import_pinocchio_s": [sys.executable, "-c", "import pinocchio"],
        "import_s": [sys.executable, "-c", "import pinmob"],
        "cli_s": [*cli, "analyze", "3-PUU", "--config", "generic"],
    }
    times: dict[str, list[float]] = {k: [] for k in commands}
    for _ in range(rounds):
        for key, cmd in commands.items():
            t0 = time.perf_counter()
            subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
            times[key].append(time.perf_counter() - t0)
    return {k: round(statistics.median(v), 3) for k, v in times.items()}


def scan_peak_kib(name: str, start: str, end: str, samples: int, out: Path) -> float:
    """Peak Python memory [KiB] (tracemalloc) of a scan streamed to CSV and JSON files, as ``pinmob scan`` does."""
    mech = pinmob.load(name)
    spec = path_spec(mech, start, end, samples)
    tracemalloc.start()
    scan(mech, spec, progress=False, csv=str(out / "s.csv"), json=str(out / "s.json"), overwrite=True,
         keep_rows=False)  # fmt: skip
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak / 1024


def verdict(ok: bool) -> str:
    return "met" if ok else "NOT met"


def main() -> None:
    parser = argparse.ArgumentParser(description=(__doc__ or "").splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer configurations (finishes in about a minute)")
    args = parser.parse_args()
    n, repeats, samples, rounds = (200, 3, 41, 7) if args.quick else (1000, 5, 201, 9)
    result: dict[str, dict[str, float]] = {}
    for name in ("3-PUU", "6-UPS"):
        r, engine = bench_analyses(name, n, repeats)
        batch_numpy = r.pop("batch_numpy_us")
        s = bench_scan(name, samples, repeats)
        r["scan_us"] = s["scan_us"]
        result[name] = r
        print(
            f"{name}: {n} closed configurations, us per configuration: single analyze + to_dict {r['single_us']} vs "
            f"baseline {r['baseline_us']} (target single <= baseline: {verdict(r['single_us'] <= r['baseline_us'])}, "
            f"{r['single_us'] / r['baseline_us']:.2f}x; its document alone, json.loads of its text: {r['document_us']}, "
            f"{r['document_us'] / r['baseline_us']:.2f}x the baseline); batch ({engine}) {r['batch_us']} vs floor {r['floor_us']} "
            f"({r['batch_us'] / r['floor_us']:.1f}x the floor, {r['baseline_us'] / r['batch_us']:.1f}x faster than "
            f"the baseline; numpy engine {batch_numpy})"
        )
        print(
            f"{name}: scan {' -> '.join(SCAN[name])}, {samples} samples ({s['rows']} rows) with re-assembly, one "
            f"worker: {r['scan_us']} us per sample vs single analyze {r['single_us']} (target <= 1.5x: "
            f"{verdict(r['scan_us'] <= 1.5 * r['single_us'])}, {r['scan_us'] / r['single_us']:.2f}x)"
        )
    compiled = compile_pinmob()
    walls = wall_medians(rounds)
    pin_s = walls["import_pinocchio_s"]
    print(
        f"fresh interpreters, median of {rounds} ({compiled}): import pinmob {walls['import_s']} s vs import pinocchio {pin_s} s "
        f"(target <= 1.4x: {verdict(walls['import_s'] <= 1.4 * pin_s)}, {walls['import_s'] / pin_s:.2f}x); "
        f"pinmob analyze 3-PUU --config generic {walls['cli_s']} s (target <= 2x import pinocchio: "
        f"{verdict(walls['cli_s'] <= 2 * pin_s)}, {walls['cli_s'] / pin_s:.2f}x)"
    )
    for r in result.values():
        r.update(walls)
    small = 100 if args.quick else 200  # a chunk holds up to 32 samples: smaller scans peak lower
    with tempfile.TemporaryDirectory() as tmp:
        scan_peak_kib("3-PUU", "generic", "offset", 10, Path(tmp))  # warm-up: caches filled once per process
        peaks = [scan_peak_kib("3-PUU", "generic", "offset", k, Path(tmp)) for k in (small, 8 * small)]
    print(
        f"3-PUU scan generic -> offset streamed to CSV and JSON, peak Python memory (tracemalloc): {small} samples "
        f"{peaks[0]:.0f} KiB, {8 * small} samples {peaks[1]:.0f} KiB (ratio {peaks[1] / peaks[0]:.2f}; flat = 1)"
    )
    print(json.dumps(result))


if __name__ == "__main__":
    if shutil.which("pinmob") is None and not Path(sys.executable).with_name("pinmob").exists():
        print("note: no pinmob script beside this Python; cli_s runs python -m pinmob", file=sys.stderr)
    main()
