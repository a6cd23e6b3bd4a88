"""Speed of pinmob's mobility analyses, side by side with a straightforward baseline.

Per mechanism (3-PUU, 6-UPS), at N fixed closed configurations (microseconds per configuration):

* ``baseline_us``: per configuration, in a Python loop: Pinocchio kinematics and frame Jacobians,
  then per limb ``scipy.linalg.null_space`` of the dimensionless joint screws (the limb's wrenches),
  then the SVD of the stacked wrenches (the constraint rank);
* ``floor_us``: the Pinocchio Jacobian calls of that loop alone (``computeJointJacobians``,
  ``updateFramePlacements``, one ``getFrameJacobian`` per limb): the cost of getting the frame
  Jacobians from Pinocchio, which no analysis built on them avoids;
* ``batch_us``: :func:`pinmob.analysis.batch.analyze_batch` on all N at once (DoF, constraint rank, limb twist
  ranks, locked DoF: the numbers of the baseline and more; no singular values, no motion classification);
* ``single_us``: one :func:`pinmob.analyze` call (full result with classified motions and constraints).

The text lines also print ``own``: the Pinocchio calls the batch path itself makes
(``computeJointJacobians`` and the platform frame's placement, in the same Python loop), a stricter
floor than ``floor_us``, and the batch time relative to it.

Then scan samples per second including re-assembly: ``pinmob.scan`` along a pose path (assembly,
mobility with classification, singularity report per sample) against the same warm-started assembly
plus the baseline analysis. Last, the peak Python memory (tracemalloc) of a 3-PUU scan streamed to
CSV and JSON files, for n and 8n samples (after a warm-up scan): flat in the number of samples when the ratio is near 1.

Usage: ``python benchmarks/bench_mobility.py [--quick]``; the last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
import tracemalloc
from pathlib import Path

import numpy as np
import pinocchio as pin
import scipy.linalg

import pinmob
from pinmob.analysis.batch import analyze_batch
from pinmob.scan.output import RowWriter
from pinmob.scan.run import columns, scan
from pinmob.scan.spec import path_spec, platform_pose, pose_vector
from pinmob.screw.algebra import twist_scaling

CONFIG = {"3-PUU": "generic", "6-UPS": "generic"}


def closed_configurations(mech: pinmob.Mechanism, n: int, seed: int = 0) -> np.ndarray:
    """n closed configurations: random platform poses near the generic one, assembled."""
    rng = np.random.default_rng(seed)
    q0 = pinmob.closed_configuration(mech, CONFIG[mech.name])
    base = pose_vector(platform_pose(mech, q0))
    out = []
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
    model, data = mech.model, mech.model.createData()
    tips = [limb.tip_id for limb in mech.limbs]
    for q in qs:
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        for tip in tips:
            pin.getFrameJacobian(model, data, tip, pin.LOCAL_WORLD_ALIGNED)


def own_calls(mech: pinmob.Mechanism, qs: np.ndarray) -> None:
    model, data, pid = mech.model, mech.model.createData(), mech.platform_id
    for q in qs:
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacement(model, data, pid)


def baseline_one(mech: pinmob.Mechanism, data: pin.Data, q: np.ndarray) -> int:
    model = mech.model
    st = twist_scaling(mech.length_scale)[:, None]
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    wrenches = []
    for limb in mech.limbs:
        jac = pin.getFrameJacobian(model, data, limb.tip_id, pin.LOCAL_WORLD_ALIGNED)[:, limb.v_indices]
        wrenches.append(scipy.linalg.null_space((st * jac).T, rcond=1e-6))
    stacked = np.hstack(wrenches)
    if stacked.shape[1] == 0:
        return 0
    s = np.linalg.svd(stacked.T, compute_uv=False)
    return int(np.sum(s > 1e-6 * s[0]))


def baseline(mech: pinmob.Mechanism, qs: np.ndarray) -> list[int]:
    data = mech.model.createData()
    return [baseline_one(mech, data, q) for q in qs]


def best_us(fn, n: int, repeats: int) -> float:  # type: ignore[no-untyped-def]
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best / n * 1e6


def bench_analyses(name: str, n: int, repeats: int) -> dict[str, float]:
    mech = pinmob.load(name)
    qs = closed_configurations(mech, n)
    ranks = analyze_batch(mech, qs).constraint_rank
    assert list(ranks) == baseline(mech, qs), "batch and baseline disagree on the constraint rank"
    single_n = max(10, n // 10)
    out = {
        "baseline_us": best_us(lambda: baseline(mech, qs), n, repeats),
        "floor_us": best_us(lambda: floor(mech, qs), n, repeats),
        "batch_us": best_us(lambda: analyze_batch(mech, qs), n, repeats),
        "single_us": best_us(lambda: [pinmob.analyze(mech, q) for q in qs[:single_n]], single_n, repeats),
        "own_us": best_us(lambda: own_calls(mech, qs), n, repeats),
    }
    return {k: round(v, 1) for k, v in out.items()}


def bench_scan(name: str, start: str, end: str, samples: int) -> dict[str, float]:
    mech = pinmob.load(name)
    spec = path_spec(mech, start, end, samples)
    t0 = time.perf_counter()
    rows = sum(1 for _ in scan(mech, spec, progress=False))
    pinmob_rate = rows / (time.perf_counter() - t0)
    data = mech.model.createData()
    t0 = time.perf_counter()
    q = spec.q_ref
    for k in range(samples):
        q = pinmob.assemble_pose(mech, spec.target(k)[1], q, max_iter=40)
        baseline_one(mech, data, q)
    base_rate = samples / (time.perf_counter() - t0)
    return {"scan_samples_per_s": round(pinmob_rate, 1), "baseline_samples_per_s": round(base_rate, 1)}


def scan_peak_kib(name: str, start: str, end: str, samples: int, out: Path) -> float:
    """Peak Python memory [KiB] (tracemalloc) of a scan streamed to CSV and JSON files, as ``pinmob scan`` does."""
    mech = pinmob.load(name)
    spec = path_spec(mech, start, end, samples)
    tracemalloc.start()
    with RowWriter(columns(spec), {"samples": samples}, str(out / "s.csv"), str(out / "s.json")) as writer:
        for row in scan(mech, spec, progress=False):
            writer.write(row)
    peak = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return peak / 1024


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer configurations (finishes in well under a minute)")
    args = parser.parse_args()
    n, repeats, samples = (200, 3, 41) if args.quick else (1000, 5, 201)
    result = {}
    for name in ("3-PUU", "6-UPS"):
        r = bench_analyses(name, n, repeats)
        own = r.pop("own_us")
        result[name] = r
        print(
            f"{name}: {n} closed configurations, us per configuration: baseline {r['baseline_us']}, "
            f"floor (Pinocchio Jacobians alone) {r['floor_us']}, batch {r['batch_us']}, single analyze {r['single_us']}; "
            f"batch is {r['baseline_us'] / r['batch_us']:.1f}x faster than the baseline and "
            f"{r['batch_us'] / r['floor_us']:.2f}x the floor (targets: >= 10x, <= 3x); "
            f"the batch path's own Pinocchio calls {own} us, batch {r['batch_us'] / own:.2f}x those"
        )
    for name, start, end in (("3-PUU", "generic", "offset"), ("6-UPS", "home", "type2")):
        s = bench_scan(name, start, end, samples)
        print(
            f"{name} scan {start} -> {end}, {samples} samples with re-assembly: pinmob.scan {s['scan_samples_per_s']} "
            f"samples/s (mobility + motion types + singularity report), assembly + baseline analysis "
            f"{s['baseline_samples_per_s']} samples/s (ratio {s['scan_samples_per_s'] / s['baseline_samples_per_s']:.2f})"
        )
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
    main()
