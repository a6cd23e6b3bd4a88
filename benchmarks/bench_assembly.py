"""Convergence and speed of pinmob's closure solvers from random seeds.

Cases (each from the neutral configuration and N seeded random seeds, :func:`random_configuration`):

* ``delta-fk``: forward kinematics of the delta with parallelograms (tests/data/delta.toml) at motors
  (0.2, 0.1, -0.1) rad (:func:`solve_actuated`);
* ``fourbar-fk``: the four-bar (tests/data/fourbar.toml) at crank 0.4 rad;
* ``talos-fk``: the talos_like leg (example-parallel-robots) at the actuator values of its first
  closed configuration;
* ``delta-project``, ``talos-project``: projection onto the closed set (:func:`project`);
* ``3-UPU-pose``: the 3-UPU at its ``constraint-singular`` pose (:func:`assemble_pose`).

For each: the share of seeds that converge, the milliseconds per solve (failures included), and the
largest dimensionless residual (position / L, rotation [rad]) of the converged ones. Runs on any
pinmob version with these functions (compare by putting an older checkout first on PYTHONPATH).

Usage: ``python benchmarks/bench_assembly.py [--seeds N]``; the last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pinocchio as pin

import pinmob
from pinmob.assembly.assemble import project, solve_actuated
from pinmob.assembly.seeds import find_closed, random_configuration
from pinmob.exceptions import ClosureError

DATA = Path(__file__).resolve().parent.parent / "tests" / "data"


def _residual(mech: pinmob.Mechanism, q: np.ndarray) -> float:
    res = pinmob.check_closed(mech, q)
    return max([max(p / mech.length_scale, r) for p, r in res.values()], default=0.0)


def run(mech: pinmob.Mechanism, solver: Callable[[np.ndarray], np.ndarray], seeds: int) -> dict[str, float]:
    """Solve from the neutral configuration and ``seeds`` random ones; convergence, time, residual."""
    rng = np.random.default_rng(0)
    starts = [mech.neutral()] + [random_configuration(mech, rng) for _ in range(seeds)]
    ok, worst, t0 = 0, 0.0, time.perf_counter()
    for start in starts:
        try:
            q = solver(start)
        except ClosureError:
            continue
        ok += 1
        worst = max(worst, _residual(mech, q))
    elapsed = time.perf_counter() - t0
    return {"converged": ok / len(starts), "ms": 1e3 * elapsed / len(starts), "residual": worst}


def cases() -> dict[str, tuple[pinmob.Mechanism, Callable[[np.ndarray], np.ndarray]]]:
    delta = pinmob.load(DATA / "delta.toml")
    fourbar = pinmob.load(DATA / "fourbar.toml")
    talos = pinmob.load(DATA / "example-parallel-robots" / "talos_like" / "robot.yaml")
    q_talos = find_closed(talos).q
    m = talos.model
    talos_values = {a: float(q_talos[m.joints[m.getJointId(a)].idx_q]) for a in talos.actuated}
    upu = pinmob.load("3-UPU")
    pose = upu.configurations["constraint-singular"].pose
    motors = {"A_motor": 0.2, "B_motor": 0.1, "C_motor": -0.1}
    return {
        "delta-fk": (delta, lambda s: solve_actuated(delta, motors, s).q),
        "fourbar-fk": (fourbar, lambda s: solve_actuated(fourbar, {"crank": 0.4}, s).q),
        "talos-fk": (talos, lambda s: solve_actuated(talos, talos_values, s).q),
        "delta-project": (delta, lambda s: project(delta, s).q),
        "talos-project": (talos, lambda s: project(talos, s).q),
        "3-UPU-pose": (upu, lambda s: pinmob.assemble_pose(upu, pose if pose is not None else pin.SE3.Identity(), s)),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=40, help="random seeds per case (default 40)")
    args = parser.parse_args()
    warnings.simplefilter("ignore")  # missing meshes; joints outside limits
    out = {}
    for name, (mech, solver) in cases().items():
        out[name] = run(mech, solver, args.seeds)
        r = out[name]
        print(
            f"{name:14s} converged {r['converged']:6.1%}  {r['ms']:8.2f} ms/solve  worst residual {r['residual']:.1e}"
        )
    print(json.dumps(out))


if __name__ == "__main__":
    main()
