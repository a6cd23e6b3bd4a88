"""Cost of the finite-mobility analysis per configuration, on every built-in model and named configuration.

For each configuration (closed once, outside the timing): ``total_ms``, the whole finite analysis of
:func:`pinmob.analysis.finite.finite_mobility.finite_mobility` (free and with the actuators held: higher-order conditions,
cone and branches, every motion traced, closed samples), on a fresh :class:`pinmob.Configuration` each time;
``screw_ms``, its screw-based part alone (loop screws, the conditions, the second-order cone and an order test
per platform motion, no tracing and no sampling). Each is the median of ``--repeat`` runs; the reference is
the issue's target, 1000 ms per configuration. The machine's load average is printed with the figures (the
development machine is shared: figures taken under load are slower), and beside each wall-clock figure the
process's CPU time (``cpu``, ``time.process_time``, the median of the same runs), which waiting for a core does
not inflate.

Then the cost of ``pinmob scan --finite`` per sample: the same path scanned with and without the finite DoF of
each sample (``scan_ms`` per sample without, ``scan_finite_ms`` with), on the 3-PUU (generic to offset, regular)
and the flat 3-PUU (flat to flat-raised, shaky).

Usage: ``python benchmarks/bench_finite.py [--repeat N] [--only NAME]``; the last line is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
import tomllib
from pathlib import Path

import numpy as np

import pinmob
from pinmob.analysis.chain.closed_chain import frame_rows
from pinmob.analysis.finite.finite_mobility import finite_mobility
from pinmob.analysis.finite.higher_order import HigherOrder
from pinmob.analysis.finite.loop_screws import mechanism_loops
from pinmob.analysis.finite.tangent_cone import cone
from pinmob.scan import path_spec, scan, with_finite
from pinmob.screw.algebra import twist_scaling
from pinmob.screw.rank import RTOL, decide_rank

MODELS = Path(__file__).resolve().parent.parent / "models"
REFERENCE_MS = 1000.0


def screw_part(mech: pinmob.Mechanism, q: np.ndarray) -> None:
    """The screw-based part: conditions, cone, and an order test per platform motion."""
    conf = pinmob.Configuration(mech, q)
    ho = HigherOrder(mechanism_loops(conf), RTOL)
    cone(ho)
    if mech.has_platform:
        on_kernel = frame_rows(conf, mech.platform) @ ho.kernel[: mech.model.nv]
        lifts = decide_rank(on_kernel, RTOL, n=ho.m, at_least=1.0).null_space.T
        for m in pinmob.analyze(mech, conf).motions:
            ho.test(np.linalg.lstsq(on_kernel, twist_scaling(mech.length_scale) * m.twist, rcond=None)[0], lifts)


def whole(mech: pinmob.Mechanism, q: np.ndarray) -> None:
    """The whole finite analysis, numerical confirmation included."""
    finite_mobility(pinmob.Configuration(mech, q), RTOL)


def median_ms(run, mech: pinmob.Mechanism, q: np.ndarray, repeat: int) -> tuple[float, float]:
    """Median wall-clock and CPU time [ms] of ``repeat`` runs."""
    wall, cpu = [], []
    for _ in range(repeat):
        t0, c0 = time.perf_counter(), time.process_time()
        run(mech, q)
        wall.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    return 1e3 * statistics.median(wall), 1e3 * statistics.median(cpu)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3, help="runs per configuration (median; default 3)")
    parser.add_argument("--only", help="one built-in model")
    args = parser.parse_args()
    cases = [
        (tomllib.loads(p.read_text())["name"], c)
        for p in sorted(MODELS.glob("*.toml"))
        for c in tomllib.loads(p.read_text())["configurations"]
    ]
    cases = [c for c in cases if args.only in (None, c[0])]
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores; reference {REFERENCE_MS:.0f} ms")
    out = {}
    for name, config in cases:
        mech = pinmob.load(name)
        q = pinmob.closed_configuration(mech, config)
        whole(mech, q)  # first call: imports and caches
        (total, total_cpu), (screws, _) = (
            median_ms(whole, mech, q, args.repeat),
            median_ms(screw_part, mech, q, args.repeat),
        )
        out[f"{name}:{config}"] = {
            "total_ms": round(total, 1),
            "total_cpu_ms": round(total_cpu, 1),
            "screw_ms": round(screws, 1),
        }
        print(
            f"{name:16s} {config:20s} total {total:7.1f} ms (cpu {total_cpu:7.1f})  screw-based part {screws:6.1f} ms"
        )
    worst = max(out.values(), key=lambda v: v["total_ms"])
    worst_cpu = max(v["total_cpu_ms"] for v in out.values())
    print(
        f"slowest {worst['total_ms']:.0f} ms (cpu {worst_cpu:.0f} ms; reference {REFERENCE_MS:.0f} ms); "
        f"load average {os.getloadavg()[0]:.1f}"
    )
    for name, start, end in (("3-PUU", "generic", "offset"), ("3-PUU-flat", "flat", "flat-raised")):
        if args.only not in (None, name):
            continue
        mech = pinmob.load(name)
        spec = path_spec(mech, start, end, 11)
        per = {}
        for key, run in (("scan_ms", spec), ("scan_finite_ms", with_finite(mech, spec))):
            wall, cpu = [], []
            for _ in range(args.repeat):
                t0, c0 = time.perf_counter(), time.process_time()
                rows = list(scan(mech, run, progress=False))
                wall.append((time.perf_counter() - t0) / len(rows))
                cpu.append((time.process_time() - c0) / len(rows))
            per[key] = round(1e3 * statistics.median(wall), 1)
            per[key.replace("_ms", "_cpu_ms")] = round(1e3 * statistics.median(cpu), 1)
        out[f"scan {name}:{start}->{end}"] = per
        print(f"pinmob scan {name} --from {start} --to {end}: {per['scan_ms']:.1f} ms per sample (cpu "
              f"{per['scan_cpu_ms']:.1f}), {per['scan_finite_ms']:.1f} ms with --finite (cpu {per['scan_finite_cpu_ms']:.1f})")  # fmt: skip
    print(json.dumps(out))


if __name__ == "__main__":
    main()
