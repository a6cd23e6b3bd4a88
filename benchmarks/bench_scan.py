"""Per-sample cost of a grid scan, beside the loop a Pinocchio user would write and the floors, in one run.

Per robot and grid (microseconds per sample):

* ``cli_us``: ``pinmob scan <robot> --grid ... --at ... --json FILE`` by the command line's function
  (:func:`pinmob.cli.main`) in this process: the model loaded, the scan, its summary and the JSON file
  (``json_bytes``); and ``cli_start_s``: a fresh process's CPU time (user + system of the child) for a 2 x 2
  grid, what a run pays once on top (interpreter, imports, model);
* ``pinmob_us``: the same scan in process (:func:`pinmob.scan.scan_run.scan_in_process` on
  :func:`pinmob.scan.scan_spec.grid_spec`, no file): the batched engine, refinements included;
* ``plain_us``: the plain loop a Pinocchio user writes (:func:`plain_scan`, in this file): the samples in
  serpentine order, each warm-started from the last closed one; damped Gauss-Newton with
  ``computeJointJacobians`` + ``updateFramePlacements``, the tips' ``log6`` errors and
  ``Jlog6 @ getFrameJacobian(LOCAL)`` rows, the normal equations solved until the largest error is below
  1e-12; assembled iff within the closure tolerance; then each limb's wrenches by an SVD of its scaled
  Jacobian and the platform's DoF by an SVD of the stacked wrenches (the motion type of the free twists in a
  second, untimed run, for the comparison of verdicts; the analysis is :func:`platform_analysis`). For a
  grid with following (parasitic) coordinates (the 3-RPS's x, y and yaw over roll x pitch) the same loop with
  those coordinates among the unknowns (the leanest general loop: their columns only when there are some).
  For a joint grid (the 3-PUU's motors) the leanest loop for it (:func:`joint_scan`): the gridded and held
  joints set in q, the same serpentine order and warm start, damped Gauss-Newton on the closure residuals,
  the limb tips' ``log6`` errors relative to the first limb's tip with rows ``Jlog6 @ (J_i - Ad(m^-1) J_0)``
  of the LOCAL frame Jacobians less the gridded and held joints' columns, to 1e-12; assembled iff within the
  closure tolerance; then the same analysis. pinmob's (reachable, DoF, motion type) verdict on every sample
  is compared with the loop's (``agree``, and the first differences printed);
* ``old_us``: the old general loop (:func:`naive_scan`, the "naive loop" of issue 23: its RPY columns built,
  stacked and a generator's max at every iteration, lines warm-started from their first sample, stopped at
  1e-6, a null-space DoF count; pose grids only: None on the joint grid); its (reachable, DoF) verdicts are
  counted against pinmob's too;
* ``floor_us``: the Pinocchio floor, the calls the job cannot avoid: ``computeJointJacobians`` and
  ``updateFramePlacements`` at the plain loop's configurations, as many times as its iterations plus one (the
  closure checked; the analysis reads that kinematics);
* ``compiled_floor_us``: the same kinematics by :mod:`pinmob.model.compiled_kinematics` (numba; the tips'
  placements and LOCAL Jacobians), ``GROUP`` configurations per call into reused arrays;
* the ``computeJointJacobians`` calls per sample of pinmob and of the plain loop (counted by
  :func:`pinmob.testing.kinematics_calls` in a separate, untimed run), and the split of pinmob's time
  (fractions of one cProfile run): the batched predictor (:func:`pinmob.assembly.batched.batch_solver.solve_poses`),
  the single-sample solver, the batch analysis, the single-sample analysis and the rest (rows: joint values,
  limits, targets), with Pinocchio's kinematics alone (the floor's cost per call at pinmob's count of calls).

First, the versions the figures depend on (Python, numpy, Pinocchio, numba, orjson, numpy's BLAS: the plain loop's
many small calls cost 2-3x more on some stacks than on others), then the compiled kinematics' first call in a
fresh process with an empty numba cache (a temporary
``NUMBA_CACHE_DIR``: what a new installation pays once) and in a second process with the cache it wrote.

Robots: the 3-PUU over x x y (a full-pose grid: its rotations cannot change), the 6-UPS over x x y, the
3-RPS over roll x pitch (z held, x, y and yaw following), the 3-PUU over x x y five times wider (most
samples out of reach: what an unreachable sample costs, and the refinements at the edges), and the 3-PUU over
its motors (``A_slider`` x ``B_slider`` over +-0.2 m, ``C_slider`` held at ``generic``: the designer's joint
grid, forward kinematics with every passive joint following; every sample assembles, and the grid crosses
limb singularities, refined between samples). Wider motor ranges leave the translational branch at the edge
of its reach: there pinmob's restarts and the loop's warm start may close a sample on different assembly
modes (at +-0.25 m the two agree on 362 of 441 samples), each a true assembly. With ``--sweep``,
the per-design cost of the example sweep (``examples/3puu_sweep.toml``, a 9 x 9 scan per design) in this
process and on a Dask ``LocalCluster`` of 2 workers (cluster start-up not timed).

The in-process figures are CPU time of this process (``time.process_time``: the load of other jobs on a
shared machine inflates them less than wall-clock time; it still does, through the shared caches), each the
fastest of ``REPEATS`` runs, pinmob's and its references' alike, run in turns (:func:`timed_in_turns`: a round
runs pinmob in process, the command line, the plain loop, the Pinocchio floor, the compiled floor and the old loop
once each, so that a drift of the machine's speed slows them alike); the sweep's are wall-clock time. Compare
the ratios printed in one run. Issue 33's target: ``cli_us <= 0.1 plain_us`` on the first three grids and
0.2 on the wide one.

Usage: ``python benchmarks/bench_scan.py [--quick | --count N] [--sweep]`` (21 x 21 grids by default, 9 x 9 with
``--quick``); the last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import logging
import os
import resource
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

import pinmob
from pinmob.assembly.batched.batch_solver import PoseProblem
from pinmob.cli import main as cli_main
from pinmob.model.closure import CLOSURE_TOL
from pinmob.model.compiled_kinematics import frame_kinematics
from pinmob.scan import pose_vector
from pinmob.scan.scan_run import scan_in_process
from pinmob.scan.scan_spec import POSE_COORDS, ScanSpec, grid_spec, pose_from_vector
from pinmob.screw.algebra import twist_scaling
from pinmob.screw.motion_label import motion_type_of_orthonormal
from pinmob.screw.rank import RTOL
from pinmob.testing import kinematics_calls

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "3puu_sweep.toml"

#: label: (robot, reference configuration, grid axes (name, low, high)).
GRIDS = {
    "3-PUU": ("3-PUU", "generic", [("x", -0.06, 0.06), ("y", -0.06, 0.06)]),
    "6-UPS": ("6-UPS", "home", [("x", -0.05, 0.05), ("y", -0.05, 0.05)]),
    "3-RPS": ("3-RPS", "home", [("roll", -0.2, 0.2), ("pitch", -0.2, 0.2)]),
    "3-PUU wide": ("3-PUU", "generic", [("x", -0.3, 0.3), ("y", -0.3, 0.3)]),
    "3-PUU motors": ("3-PUU", "generic", [("A_slider", -0.2, 0.2), ("B_slider", -0.2, 0.2)]),
}
#: Solver iterations per sample of the naive loop, and its damping (of J J^T, dimensionless).
MAX_ITER, DAMPING, TOL = 40, 1e-10, 1e-6
#: The plain loop's iterations per sample at most and its damping of the normal equations (dimensionless).
PLAIN_MAX_ITER, PLAIN_DAMPING = 30, 1e-12
#: Configurations per call of the compiled floor.
GROUP = 64


#: Runs of each timed loop of a grid; the fastest is reported (timeit's convention: the run least disturbed by
#: the machine's other jobs), for pinmob and its references alike.
REPEATS = 3


def timed(fn: Callable[[], Any], clock: Callable[[], float] = time.process_time, repeats: int = 1) -> tuple[float, Any]:
    """Seconds ``fn`` took (the fastest of ``repeats`` runs) and its result; by default CPU time of this process,
    which other jobs on a shared machine inflate less (wall-clock time for the sweep on Dask workers, whose work
    is in other processes)."""
    best, out = float("inf"), None
    for _ in range(repeats):
        t0 = clock()
        out = fn()
        best = min(best, clock() - t0)
    return best, out


def timed_in_turns(fns: dict[str, Callable[[], Any]], repeats: int = REPEATS) -> dict[str, tuple[float, Any]]:
    """:func:`timed` of each of ``fns`` (CPU seconds, the fastest of ``repeats`` runs, and the last run's result), their
    runs in turns: each round runs every one once. A machine whose speed drifts (a shared one: its load, its
    clock) slows each of them alike, so their ratios hold; run one after the other, the plain loop of one run
    took 246 us a sample and that of another, an hour later, 349."""
    best = dict.fromkeys(fns, float("inf"))
    out: dict[str, Any] = {}
    for _ in range(repeats):
        for name, fn in fns.items():
            t0 = time.process_time()
            out[name] = fn()
            best[name] = min(best[name], time.process_time() - t0)
    return {name: (best[name], out[name]) for name in fns}


# --- the plain loop, as a Pinocchio user writes it ----------------------------------------------------------------


def serpentine(shape: tuple[int, ...]) -> list[int]:
    """pinmob's sample indices (last axis fastest) in serpentine order: every other line walked backwards."""
    lines, n = int(np.prod(shape[:-1])), shape[-1]
    return [r * n + (j if r % 2 == 0 else n - 1 - j) for r in range(lines) for j in range(n)]


def plain_scan(
    mech: pinmob.Mechanism, spec: ScanSpec, motion_types: bool = False
) -> tuple[list[tuple[bool, int, str]], list[int], list[np.ndarray]]:
    """(reachable, DoF, motion type) per sample in pinmob's order, iterations per sample, configurations.

    The samples in serpentine order, each warm-started from the last closed one; damped Gauss-Newton on the
    limb tips' ``log6`` errors against the target pose, rows ``Jlog6 @ getFrameJacobian(LOCAL)`` (and, for the
    coordinates that follow, ``-Jlog6 @ Ad(m^-1)`` times the target's own local twist per unit coordinate),
    the normal equations solved until the largest dimensionless error is below 1e-12 (``PLAIN_MAX_ITER``
    iterations at most); closed iff each tip is within ``CLOSURE_TOL`` (position / L, rotation [rad]). Then
    :func:`platform_analysis`, with ``motion_types`` (for the comparison of verdicts, not timed: the loop the
    issue times stops at the DoF) the motion type too.
    """
    model, data, nv, length = mech.model, mech.model.createData(), mech.model.nv, mech.length_scale
    assert not mech.closures, "limbs only"
    tips = [limb.tip_id for limb in mech.limbs]
    free = [POSE_COORDS.index(c) for c in spec.following]
    scale = np.tile(twist_scaling(length), len(tips))
    analysis = platform_analysis(mech)
    shape = tuple(a[3] for a in spec.axes)
    grids = [np.linspace(lo, hi, n) for _, lo, hi, n in spec.axes]
    base = pose_vector(pinmob.scan.platform_pose(mech, spec.q_ref))
    for c, v in spec.held:
        base[POSE_COORDS.index(c)] = v
    axes = [POSE_COORDS.index(a[0]) for a in spec.axes]
    rows, unknowns = 6 * len(tips), nv + len(free)
    e, jac = np.empty(rows), np.zeros((rows, unknowns))
    verdicts: list[tuple[bool, int, str]] = [(False, -1, "")] * spec.size
    iters, closed = [0] * spec.size, [spec.q_ref] * spec.size
    q, p = spec.q_ref.copy(), base.copy()
    for k in serpentine(shape):
        t = p.copy()
        for a, g, ix in zip(axes, grids, np.unravel_index(k, shape)):
            t[a] = g[ix]
        qk = q
        target = pose_from_vector(t)
        for it in range(PLAIN_MAX_ITER + 1):
            pin.computeJointJacobians(model, data, qk)
            pin.updateFramePlacements(model, data)
            if free and it:
                target = pose_from_vector(t)
            if free:
                cols = _free_columns(target, free)
            for i, tip in enumerate(tips):
                m = target.actInv(data.oMf[tip])
                jlog = pin.Jlog6(m)
                e[6 * i : 6 * i + 6] = pin.log6(m).vector
                jac[6 * i : 6 * i + 6, :nv] = jlog @ pin.getFrameJacobian(model, data, tip, pin.LOCAL)
                if free:
                    jac[6 * i : 6 * i + 6, nv:] = -jlog @ m.inverse().action @ cols
            es = e * scale
            if np.max(np.abs(es)) < 1e-12 or it == PLAIN_MAX_ITER:
                break
            js = jac * scale[:, None]
            step = np.linalg.solve(js.T @ js + PLAIN_DAMPING * np.eye(unknowns), -js.T @ es)
            qk = pin.integrate(model, qk, step[:nv])
            t[free] += step[nv:]
        iters[k] = it
        parts = es.reshape(-1, 2, 3)
        if np.max(np.linalg.norm(parts, axis=2)) > CLOSURE_TOL:
            continue
        q, p, closed[k] = qk, t, qk
        verdicts[k] = analysis(data, motion_types)
    return verdicts, iters, closed


def joint_scan(
    mech: pinmob.Mechanism, spec: ScanSpec, motion_types: bool = False
) -> tuple[list[tuple[bool, int, str]], list[int], list[np.ndarray]]:
    """:func:`plain_scan`'s loop for a grid over joints (the motors): forward kinematics by the closures.

    The gridded and held joints (one-degree joints) set in q; the samples in serpentine order, each
    warm-started from the last closed one; damped Gauss-Newton on the limb tips' errors relative to the first
    limb's tip, ``log6(oM_0^-1 oM_i)``, rows ``Jlog6 @ (J_i - Ad(m^-1) J_0)`` of the LOCAL frame Jacobians with the
    gridded and held joints' columns removed, the normal equations solved until the largest dimensionless error
    is below 1e-12 (``PLAIN_MAX_ITER`` iterations at most); closed iff each tip is within ``CLOSURE_TOL`` of the
    first's (position / L, rotation [rad]); then :func:`platform_analysis`.
    """
    model, data, nv, length = mech.model, mech.model.createData(), mech.model.nv, mech.length_scale
    assert not mech.closures and not spec.pose_grid, "limbs only, joints only"
    tips = [limb.tip_id for limb in mech.limbs]
    joints = [model.joints[model.getJointId(c)] for c in (*(a[0] for a in spec.axes), *(c for c, _ in spec.held))]
    assert all(j.nq == 1 and j.nv == 1 for j in joints), "one-degree joints"
    fixed = [j.idx_v for j in joints]
    unknown = [v for v in range(nv) if v not in fixed]
    scale = np.tile(twist_scaling(length), len(tips) - 1)
    analysis = platform_analysis(mech)
    shape = tuple(a[3] for a in spec.axes)
    grids = [np.linspace(lo, hi, n) for _, lo, hi, n in spec.axes]
    slots = [j.idx_q for j in joints[: len(shape)]]
    q = spec.q_ref.copy()
    for j, (_, v) in zip(joints[len(shape) :], spec.held):
        q[j.idx_q] = v
    rows = 6 * (len(tips) - 1)
    e, jac, dq = np.empty(rows), np.empty((rows, len(unknown))), np.zeros(nv)
    verdicts: list[tuple[bool, int, str]] = [(False, -1, "")] * spec.size
    iters, closed = [0] * spec.size, [spec.q_ref] * spec.size
    for k in serpentine(shape):
        qk = q.copy()
        for slot, g, ix in zip(slots, grids, np.unravel_index(k, shape)):
            qk[slot] = g[ix]
        for it in range(PLAIN_MAX_ITER + 1):
            pin.computeJointJacobians(model, data, qk)
            pin.updateFramePlacements(model, data)
            first = data.oMf[tips[0]]
            j0 = pin.getFrameJacobian(model, data, tips[0], pin.LOCAL)[:, unknown]
            for i, tip in enumerate(tips[1:]):
                m = first.actInv(data.oMf[tip])
                e[6 * i : 6 * i + 6] = pin.log6(m).vector
                ji = pin.getFrameJacobian(model, data, tip, pin.LOCAL)[:, unknown]
                jac[6 * i : 6 * i + 6] = pin.Jlog6(m) @ (ji - m.inverse().action @ j0)
            es = e * scale
            if np.max(np.abs(es)) < 1e-12 or it == PLAIN_MAX_ITER:
                break
            js = jac * scale[:, None]
            dq[unknown] = np.linalg.solve(js.T @ js + PLAIN_DAMPING * np.eye(len(unknown)), -js.T @ es)
            qk = pin.integrate(model, qk, dq)
        iters[k] = it
        if np.max(np.linalg.norm(es.reshape(-1, 2, 3), axis=2)) > CLOSURE_TOL:
            continue
        q, closed[k] = qk, qk
        verdicts[k] = analysis(data, motion_types)
    return verdicts, iters, closed


def platform_analysis(mech: pinmob.Mechanism) -> Callable[[pin.Data, bool], tuple[bool, int, str]]:
    """The plain loops' analysis of a closed configuration whose kinematics ``data`` holds
    (``computeJointJacobians`` + ``updateFramePlacements`` done): ``(True, DoF, motion type)`` of the platform,
    each limb's wrenches from an SVD of its scaled platform Jacobian (its joints' columns), the platform's DoF
    from an SVD of the stacked wrenches; with its second argument, the motion type of the free twists
    (:func:`pinmob.screw.motion_label.motion_type_of_orthonormal`, the label of a span; "" otherwise). The
    limbs' tips, columns and scaling are taken once, before the loop."""
    model, length = mech.model, mech.length_scale
    st = twist_scaling(length)[:, None]
    limbs = [(limb.tip_id, limb.screw_v_indices) for limb in mech.limbs]

    def verdict(data: pin.Data, motion_types: bool) -> tuple[bool, int, str]:
        wrenches = []
        for tip, cols_v in limbs:
            jac = st * pin.getFrameJacobian(model, data, tip, pin.LOCAL_WORLD_ALIGNED)[:, cols_v]
            u, s, _ = np.linalg.svd(jac)
            wrenches.append(u[:, int(np.sum(s > RTOL * s[0])) :].T)
        stacked = np.vstack(wrenches)
        if stacked.shape[0]:
            _, s, vt = np.linalg.svd(stacked)
            rank = int(np.sum(s > RTOL * s[0])) if s[0] > 0 else 0
        else:
            rank, vt = 0, np.eye(6)
        return True, 6 - rank, motion_type_of_orthonormal(vt[rank:].T, length) if motion_types else ""

    return verdict


def compiled_floor(mech: pinmob.Mechanism, qs: list[np.ndarray], calls: list[int]) -> tuple[Callable[[], None], str]:
    """The tips' placements and LOCAL Jacobians by the compiled kinematics, ``calls[i]`` times at each
    configuration, in calls of ``GROUP`` configurations into the same arrays (a lockstep group's stack), as a loop to
    time (the stack built here, before any clock starts), and the engine that runs it."""
    kin = frame_kinematics(mech.model, [limb.tip_id for limb in mech.limbs])
    stack = np.repeat(np.array(qs), calls, axis=0)
    groups = [stack[i : i + GROUP] for i in range(0, len(stack), GROUP)]
    outs = {len(g): kin.jacobians(g) for g in groups}  # compiled, or loaded from the cache; the arrays reused

    def run() -> None:
        for g in groups:
            kin.jacobians(g, pin.LOCAL, out=outs[len(g)])

    return run, kin.engine


FIRST_COMPILE = """
import time, numpy as np, pinmob
from pinmob.model.compiled_kinematics import frame_kinematics
mech = pinmob.load("6-UPS")
kin = frame_kinematics(mech.model, [limb.tip_id for limb in mech.limbs], "compiled")
t0 = time.perf_counter()
kin.jacobians(mech.neutral()[None])
print(time.perf_counter() - t0)
"""


def first_compile() -> tuple[float, float]:
    """Seconds of the compiled kinematics' first call with an empty numba cache (a temporary folder), then in
    a second process with that cache (both in fresh interpreters; the user's cache is not touched)."""
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        out = [float(subprocess.run([sys.executable, "-c", FIRST_COMPILE], env=env, capture_output=True, text=True,
                                    check=True).stdout.split()[-1]) for _ in range(2)]  # fmt: skip
    return out[0], out[1]


def cli_seconds(robot: str, grid_args: list[str], folder: Path) -> float:
    """CPU seconds (user + system, of the child) of ``pinmob scan ... --json`` in a fresh process."""
    out = folder / "scan.json"
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    subprocess.run([sys.executable, "-m", "pinmob", "scan", robot, *grid_args, "--json", str(out), "--force",
                    "--no-progress"], check=True, capture_output=True)  # fmt: skip
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def cli_in_process(robot: str, grid_args: list[str], folder: Path) -> None:
    """``pinmob scan ... --json FILE`` by the command line's function (:func:`pinmob.cli.main`), in this
    process: the model loaded, the scan, its summary (to a string) and the JSON file written."""
    with contextlib.redirect_stdout(io.StringIO()):
        status = cli_main(["scan", robot, *grid_args, "--json", str(folder / "scan.json"), "--force", "--no-progress"])
    assert status == 0, status


# --- the old general loop (the naive loop of issue 23) -----------------------------------------------------------


def _free_columns(pose: pin.SE3, free: list[int]) -> np.ndarray:
    """(6, k) local twist of the target pose per unit change of its free coordinates (x y z roll pitch yaw)."""
    rpy = pin.rpy.matrixToRpy(pose.rotation)
    rt = pose.rotation.T
    world = np.zeros((6, 6))
    world[:3, :3] = rt  # a world translation seen in the target's frame
    world[3:, 3:] = rt @ pin.rpy.computeRpyJacobian(rpy, pin.WORLD)  # rpy rates -> angular velocity, local
    return world[:, free]


def naive_solve(
    mech: pinmob.Mechanism, data: pin.Data, q: np.ndarray, p: np.ndarray, free: list[int]
) -> tuple[np.ndarray | None, np.ndarray, int]:
    """Damped Gauss-Newton: every limb tip at the pose p; the coordinates ``free`` of p are unknowns too.

    Returns the configuration (None: no convergence in MAX_ITER iterations), the pose and the iterations.
    """
    model, nv, L = mech.model, mech.model.nv, mech.length_scale
    tips = [limb.tip_id for limb in mech.limbs]
    scale = np.tile(twist_scaling(L), len(tips))
    p = p.copy()
    for it in range(MAX_ITER + 1):
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        target = pose_from_vector(p)
        cols = _free_columns(target, free)
        errors, rows = [], []
        for tip in tips:
            m = target.actInv(data.oMf[tip])
            jlog = pin.Jlog6(m)
            errors.append(pin.log6(m).vector)
            jq = jlog @ pin.getFrameJacobian(model, data, tip, pin.LOCAL)
            rows.append(np.hstack([jq, -jlog @ m.inverse().action @ cols]))
        e = np.concatenate(errors) * scale
        worst = max(max(np.linalg.norm(e[6 * i : 6 * i + 3]), np.linalg.norm(e[6 * i + 3 : 6 * i + 6]))
                    for i in range(len(tips)))  # fmt: skip
        if worst <= TOL:
            return q, p, it
        if it == MAX_ITER:
            break
        jac = np.vstack(rows) * scale[:, None]
        step = -jac.T @ np.linalg.solve(jac @ jac.T + DAMPING * np.eye(jac.shape[0]), e)
        q = pin.integrate(model, q, step[:nv])
        p[free] += step[nv:]
    return None, p, MAX_ITER


def naive_dof(mech: pinmob.Mechanism, data: pin.Data, q: np.ndarray) -> int:
    """The platform's DoF at a closed q: rank of the platform twists over the closed chain's motions (SVDs)."""
    model = mech.model
    st = twist_scaling(mech.length_scale)[:, None]
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    jacs = [st * pin.getFrameJacobian(model, data, limb.tip_id, pin.LOCAL_WORLD_ALIGNED) for limb in mech.limbs]
    closure = np.vstack([j - jacs[0] for j in jacs[1:]])  # every tip moves with the first (tips coincide)
    _, s, vt = np.linalg.svd(closure)
    null = vt[int(np.sum(s > RTOL * s[0])) :].T
    s = np.linalg.svd(jacs[0] @ null, compute_uv=False)
    return int(np.sum(s > RTOL * s[0])) if s.size else 0


def naive_scan(mech: pinmob.Mechanism, spec: ScanSpec) -> tuple[list[tuple[bool, int]], list[int], list[np.ndarray]]:
    """(reachable, DoF) per sample in pinmob's sample order, iterations, configurations (closed, else the seed)."""
    data = mech.model.createData()
    names = [a[0] for a in spec.axes]
    grids = [np.linspace(lo, hi, n) for _, lo, hi, n in spec.axes]
    held = dict(spec.held)
    free = [POSE_COORDS.index(c) for c in spec.following]
    base = pose_vector(pinmob.scan.platform_pose(mech, spec.q_ref))
    n_line = spec.axes[-1][3]
    verdicts, iters, closed = [], [], []
    q_line, p_line = spec.q_ref.copy(), base.copy()  # warm start of the next line: the first of this one
    q, p = q_line, p_line
    for k, idx in enumerate(np.ndindex(*[a[3] for a in spec.axes])):
        if k % n_line == 0:
            q, p = q_line, p_line
        target = p.copy()
        for c, v in held.items():
            target[POSE_COORDS.index(c)] = v
        for c, g, i in zip(names, grids, idx):
            target[POSE_COORDS.index(c)] = g[i]
        sol, p_sol, it = naive_solve(mech, data, q, target, free)
        iters.append(it)
        if sol is None:
            verdicts.append((False, -1))
            closed.append(q)
            continue
        verdicts.append((True, naive_dof(mech, data, sol)))
        closed.append(sol)
        q, p = sol, p_sol
        if k % n_line == 0:
            q_line, p_line = sol, p_sol
    return verdicts, iters, closed


def floor_loop(mech: pinmob.Mechanism, qs: list[np.ndarray], calls: list[int]) -> None:
    """The Jacobians and frame placements only, ``calls[i]`` times at each configuration."""
    model, data = mech.model, mech.model.createData()
    for q, n in zip(qs, calls):
        for _ in range(n):
            pin.computeJointJacobians(model, data, q)
            pin.updateFramePlacements(model, data)


# --- pinmob -----------------------------------------------------------------------------------------------------


#: The parts of the engine's time, by the functions cProfile charges (cumulative: a part's first function
#: whole, each later one from callers outside the part, a refinement's trial points examined before their row).
PARTS = {
    "batched predictor": ("solve_poses",),
    "single-sample solver": ("assemble_target",),
    "batch analysis": ("analyse_stack",),
    "single-sample analysis": ("_evaluate", "examine"),
}


def profile_split(mech: pinmob.Mechanism, spec: ScanSpec) -> dict[str, float]:
    """Fractions of the engine's time (one cProfile run): :data:`PARTS` and the rest (Pinocchio's calls are not
    profiled: their time counts in their callers')."""
    import cProfile
    import pstats

    prof = cProfile.Profile()
    prof.enable()
    list(scan_in_process(mech, spec))
    prof.disable()
    stats = pstats.Stats(prof).stats  # type: ignore[attr-defined]
    total = sum(tt for (_, _, _), (_, _, tt, _, _) in stats.items())
    cum: dict[str, float] = {}
    for (path, _, name), (_, _, _, ct, callers) in stats.items():
        for part, names in PARTS.items():
            if name not in names or "pinmob" not in path:
                continue
            if name != names[0]:  # its calls from outside the part's functions only (no time counted twice)
                ct = sum(c[3] for (_, _, caller), c in callers.items() if caller not in names)
            cum[part] = cum.get(part, 0.0) + ct
    out = {part: cum.get(part, 0.0) / total for part in PARTS}
    out["rest"] = max(0.0, 1.0 - sum(out.values()))
    return out


def bench_grid(label: str, count: int, folder: Path) -> dict[str, Any]:
    robot, at, axes = GRIDS[label]
    mech = pinmob.load(robot)
    spec = grid_spec(mech, at, [(c, lo, hi, count) for c, lo, hi in axes])
    n = spec.size
    small = replace(spec, axes=tuple((c, lo, hi, 3) for c, lo, hi, _ in spec.axes))
    list(scan_in_process(mech, small))  # warm-up: numba's caches loaded
    grid_args = ["--grid", *(f"{c}:{lo:g}:{hi:g}:{k}" for c, lo, hi, k in spec.axes), "--at", at]
    small_args = ["--grid", *(f"{c}:{lo:g}:{hi:g}:2" for c, lo, hi, _ in spec.axes), "--at", at]
    cli_in_process(robot, small_args, folder)  # warm-up
    plain_loop = plain_scan if spec.pose_grid else joint_scan
    _, iters, closed = plain_loop(mech, spec)  # the floors' configurations, and their calls:
    calls = [it + 1 for it in iters]  # the last one (the closure checked) serves the analysis too
    compiled_loop, engine = compiled_floor(mech, closed, calls)
    loops: dict[str, Callable[[], Any]] = {
        "pinmob": lambda: [r for r in scan_in_process(mech, spec)],
        "cli": lambda: cli_in_process(robot, grid_args, folder),
        "plain": lambda: plain_loop(mech, spec),
        "floor": lambda: floor_loop(mech, closed, calls),
        "compiled": compiled_loop,
    }
    if spec.pose_grid:  # the old general loop scans pose grids only
        loops["old"] = lambda: naive_scan(mech, spec)
    times = timed_in_turns(loops)
    t_pinmob, rows = times["pinmob"]
    t_cli = times["cli"][0]
    t_plain, (_, iters, _) = times["plain"]
    t_floor = times["floor"][0]
    json_bytes = (folder / "scan.json").stat().st_size
    t_start = cli_seconds(robot, small_args, folder)  # a fresh process, 4 samples: the start-up
    samples = [r for r in rows if not r["refined"]]
    verdicts = plain_loop(mech, spec, motion_types=True)[0]
    ours = [(bool(r["reachable"]), int(r["dof"]) if r["reachable"] else -1, r["motion_type"] if r["reachable"] else "")
            for r in samples]  # fmt: skip
    agree = sum(a == b for a, b in zip(ours, verdicts))
    differ = [(k, a, b) for k, (a, b) in enumerate(zip(ours, verdicts)) if a != b][:3]
    t_old, old_agree = None, None
    if "old" in times:
        t_old, (old_verdicts, _, _) = times["old"]
        old_agree = sum(a[:2] == b for a, b in zip(ours, old_verdicts))
    t_compiled = times["compiled"][0]
    split = profile_split(mech, spec)
    us = 1e6 / n
    calls_pinmob = kinematics_calls(lambda: list(scan_in_process(mech, spec)))
    calls_plain = kinematics_calls(lambda: plain_loop(mech, spec))
    return {
        "grid": " ".join(grid_args[1:-2]),
        "at": at,
        "following": list(spec.following),
        "held_joints": [c for c, _ in spec.held if c not in POSE_COORDS],
        "samples": n,
        "reachable": int(sum(v[0] for v in verdicts)),
        "pinmob_reachable": int(sum(v[0] for v in ours)),
        "refined": len(rows) - len(samples),
        "agree": agree,
        "differ": [f"sample {k}: pinmob {a}, plain loop {b}" for k, a, b in differ],
        "old_agree": old_agree,
        "pinmob_us": t_pinmob * us,
        "cli_us": t_cli * us,
        "cli_start_s": t_start,
        "json_bytes": json_bytes,
        "plain_us": t_plain * us,
        "old_us": None if t_old is None else t_old * us,
        "floor_us": t_floor * us,
        "compiled_floor_us": t_compiled * us,
        "compiled_engine": engine,
        "predictor_kinematics": PoseProblem(mech).fast.engine,
        "plain_iterations": float(np.mean(iters)),
        "kinematics_per_sample": {"pinmob": calls_pinmob / n, "plain": calls_plain / n, "floor": float(np.mean(calls))},
        "split": split,
    }


def bench_sweep(designs: int) -> dict[str, float]:
    """Per-design seconds of the example sweep (its 9 x 9 scan) in this process and on 2 local Dask workers."""
    from dask.distributed import Client, LocalCluster

    from pinmob.parallel.cluster import WORKER_SETUP
    from pinmob.sweeps.designs import DesignSet

    spec = pinmob.load_spec(EXAMPLE)
    side = int(np.ceil(np.sqrt(designs)))
    spec = replace(spec, designs=DesignSet("grid", ("link", "big_r"), ((0.26, 0.35, side), (0.2, 0.3, side))))
    list(pinmob.sweep(spec, skip=np.arange(spec.count) > 0))  # warm-up
    serial, records = timed(lambda: list(pinmob.sweep(spec)), time.perf_counter)
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address="127.0.0.1:0",
                           silence_logs=logging.CRITICAL, preload=[WORKER_SETUP])  # fmt: skip
    with cluster, Client(cluster) as client:
        client.run(lambda: __import__("pinmob"))
        list(pinmob.sweep(spec, scheduler=cluster.scheduler_address, skip=np.arange(spec.count) >= 2))  # warm-up
        elapsed, dask_records = timed(
            lambda: list(pinmob.sweep(spec, scheduler=cluster.scheduler_address)), time.perf_counter
        )
    assert dask_records == records, "Dask records differ from the in-process ones"
    return {"designs": spec.count, "in_process_s": serial / spec.count, "dask2_s": elapsed / spec.count}


def versions() -> dict[str, str]:
    """The versions the figures depend on (the plain loop's small numpy and Pinocchio calls cost 2-3x more on some
    stacks than on others): Python, numpy, Pinocchio, numba (or absent), orjson, and numpy's BLAS."""
    import importlib.metadata as metadata
    import platform

    out = {"Python": platform.python_version(), "numpy": np.__version__, "Pinocchio": pin.__version__}
    for name in ("numba", "orjson"):
        try:
            out[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            out[name] = "absent"
    blas = np.show_config(mode="dicts").get("Build Dependencies", {}).get("blas", {})
    out["BLAS"] = f"{blas.get('name', '?')} {blas.get('version', '?')}"
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="9 x 9 grids (the same as --count 9)")
    parser.add_argument("--count", type=int, default=21, help="samples per grid axis (default 21)")
    parser.add_argument("--sweep", action="store_true", help="the example sweep too (in process and on 2 workers)")
    args = parser.parse_args()
    count = 9 if args.quick else args.count
    out: dict[str, Any] = {}
    out["versions"] = versions()
    print("versions: " + ", ".join(f"{k} {v}" for k, v in out["versions"].items()))
    cold, warm = out["first_compile_s"] = first_compile()
    print(f"compiled kinematics, first call in a fresh process: {cold:.1f} s with an empty numba cache (compiling), "
          f"{warm:.2f} s with the cache it wrote")  # fmt: skip
    print(f"per sample [us of CPU time, fastest of {REPEATS} runs in turns] (compare the ratios of one run)")  # fmt: skip
    with tempfile.TemporaryDirectory() as folder:
        for name in GRIDS:
            r = out[name] = bench_grid(name, count, Path(folder))
            robot = GRIDS[name][0]
            follow = f", {' '.join(r['following'])} following" if r["following"] else ""
            follow += f", {' '.join(r['held_joints'])} held" if r["held_joints"] else ""
            plain = r["plain_us"]
            print(f"{robot} --grid {r['grid']} --at {r['at']}{follow}: {r['pinmob_reachable']}/{r['samples']} reachable "
                  f"(plain loop {r['reachable']}), {r['refined']} refined points; verdicts (reachable, DoF, motion "
                  f"type) of pinmob and the plain loop agree on {r['agree']}/{r['samples']}")  # fmt: skip
            for line in r["differ"]:
                print(f"  differ: {line}")
            print(f"  pinmob CLI --json {r['cli_us']:6.0f} ({r['cli_us'] / plain:.2f}x, {r['json_bytes'] / 1e6:.2f} MB)"
                  f"   in process {r['pinmob_us']:6.0f} ({r['pinmob_us'] / plain:.2f}x)   a fresh process's "
                  f"start-up {r['cli_start_s']:.2f} s (a 2 x 2 grid, CPU)")  # fmt: skip
            old = (f"old general loop {r['old_us']:6.0f} ({r['old_us'] / plain:.2f}x; its verdicts (reachable, DoF) "
                   f"agree on {r['old_agree']}/{r['samples']})" if r["old_agree"] is not None
                   else "old general loop: pose grids only")  # fmt: skip
            print(f"  plain loop {plain:6.0f} ({r['plain_iterations']:.1f} iterations)   {old}")
            kin = r["kinematics_per_sample"]
            print(f"  Pinocchio floor {r['floor_us']:5.1f} ({kin['floor']:.1f} x computeJointJacobians + "
                  f"updateFramePlacements)   compiled floor {r['compiled_floor_us']:5.2f} (the same kinematics, "
                  f"{r['compiled_engine']} engine, {GROUP} configurations a call)")  # fmt: skip
            kinematics = r["floor_us"] * kin["pinmob"] / kin["floor"]  # the floor's cost per call, at pinmob's count
            print(f"  computeJointJacobians calls per sample: pinmob {kin['pinmob']:.1f} (its batched predictor's kinematics: "
                  f"{r['predictor_kinematics']}), plain loop {kin['plain']:.1f}; "
                  "pinmob's time (cProfile): " + ", ".join(f"{k} {v:.0%}" for k, v in r["split"].items())
                  + f"; Pinocchio's kinematics at its calls ~{kinematics:.0f} us ({kinematics / r['pinmob_us']:.0%})")  # fmt: skip
    if args.sweep:
        s = out["sweep"] = bench_sweep(4 if args.quick else 16)
        print(f"example sweep ({EXAMPLE.name}, 9 x 9 scan per design, {s['designs']} designs): "
              f"{s['in_process_s'] * 1e3:.0f} ms per design in process, {s['dask2_s'] * 1e3:.0f} ms per design on "
              f"2 Dask workers")  # fmt: skip
    print(json.dumps(out))


if __name__ == "__main__":
    main()
