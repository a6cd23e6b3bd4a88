"""Per-sample cost of a grid scan, beside the loop a Pinocchio user would write and the Pinocchio floor, in one run.

Per robot and grid (microseconds per sample, single process):

* ``pinmob_us``: what ``pinmob scan <robot> --grid ...`` runs (:func:`pinmob.scan.scan_run.scan_in_process` on
  :func:`pinmob.scan.scan_spec.grid_spec`), the batched engine: samples of up to 16 chunks assembled in lockstep by
  the batched predictor (:mod:`pinmob.scan.lockstep`), analysed in one batch (:mod:`pinmob.scan.batch_rows`),
  the single-sample path where the batch cannot decide, refinements included;
* ``single_us``: the same scan on the single-sample engine (``ScanSpec.engine = "single"``, every sample
  assembled and analysed on its own: pinmob before the batched engine); both engines' rows are compared
  (verdicts equal, figures to 1e-7: ``rows_equal``);
* ``naive_us``: the loop a Pinocchio user writes for the same grid (:func:`naive_scan`, in this file): damped
  Gauss-Newton on the limb tips' pose errors (``log6`` of the target pose against each limb tip, from
  ``pin.computeJointJacobians`` / ``pin.getFrameJacobian``), warm-started from the previous sample of the
  line (the first sample of a line from the first of the previous line), the platform's following (parasitic)
  coordinates among the unknowns (the 3-RPS's x, y and yaw over a roll x pitch grid), then an SVD DoF count of
  the platform's free motions (the platform twists of the closed chain's null space). It must give pinmob's
  reachable / DoF verdict on each sample: the agreement is counted and printed;
* ``floor_us``: the Pinocchio calls the job cannot avoid: ``computeJointJacobians`` and
  ``updateFramePlacements`` once per solver step of the naive loop at each sample and once more (the closure
  checked, the kinematics the analysis needs), at the naive loop's configurations and iteration counts;
* ``batched_us``: a batched prototype of the engine issue 23 asks for (:func:`batched_scan`, in this file):
  the first sample of each line one after the other, then all lines' samples in lockstep, each warm-started
  from its line's previous sample (the continuation of pinmob's lines), Newton steps batched over the lines
  (Pinocchio's kinematics per sample in a Python loop, the errors, Jacobians and damped least-squares solves
  as numpy stacks, a sample stopping at 1e-12, when a step no longer halves a residual below 1e-6, or when it
  gained less than 0.1% over 5 iterations), then
  :func:`pinmob.analysis.batch.batch_analysis.analyze_batch` for the DoF; its verdicts are counted against pinmob's too;
* the ``computeJointJacobians`` calls per sample of each (counted by :func:`pinmob.testing.kinematics_calls` in a
  separate, untimed run);
* the split of the engine's time (fractions of one cProfile run, so not the load of the machine): the batched
  predictor (:func:`pinmob.assembly.batch_solver.solve_poses`: the samples and the chunks' seeding walk), the
  single-sample solver (samples the predictor did not converge, their polish near singular points, the
  refinements), the batch analysis, the single-sample analysis (:func:`pinmob.scan.sample.evaluate`: samples
  the batch does not decide, refinements) and the rest (rows: joint values, limits, targets); and
  Pinocchio's kinematics alone (the floor's cost per call at the engine's count of calls).

Robots: the 3-PUU over x x y (a full-pose grid: its rotations cannot change), the 6-UPS over x x y, the
3-RPS over roll x pitch (z held, x, y and yaw following), and the 3-PUU over x x y five times wider (most
samples out of reach: what an unreachable sample costs, and the refinements at the edges).

Then the per-design cost of the example sweep (``examples/3puu_sweep.toml``, a 9 x 9 scan per design) in this
process and on a Dask ``LocalCluster`` of 2 workers (cluster start-up not timed).

The per-sample figures are CPU time of this process (``time.process_time``: the load of other jobs on a
shared machine inflates them less than wall-clock time; it still does, through the shared caches), each the
fastest of ``REPEATS`` runs, pinmob's and its references' alike; the sweep's are wall-clock time. Compare
the ratios printed in one run. The target of issue 23 is
``pinmob_us <= 0.2 naive_us`` on the 3-PUU grid.

Usage: ``python benchmarks/bench_scan.py [--quick]``; the last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import json
import logging
import time
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

import pinmob
from pinmob.analysis.batch.batch_analysis import analyze_batch
from pinmob.scan import pose_vector
from pinmob.scan.scan_run import scan_in_process
from pinmob.scan.scan_spec import POSE_COORDS, ScanSpec, grid_spec, pose_from_vector
from pinmob.screw.algebra import twist_scaling
from pinmob.screw.rank import RTOL
from pinmob.testing import kinematics_calls

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "3puu_sweep.toml"

#: label: (robot, reference configuration, grid axes (name, low, high)).
GRIDS = {
    "3-PUU": ("3-PUU", "generic", [("x", -0.06, 0.06), ("y", -0.06, 0.06)]),
    "6-UPS": ("6-UPS", "home", [("x", -0.05, 0.05), ("y", -0.05, 0.05)]),
    "3-RPS": ("3-RPS", "home", [("roll", -0.2, 0.2), ("pitch", -0.2, 0.2)]),
    "3-PUU wide": ("3-PUU", "generic", [("x", -0.3, 0.3), ("y", -0.3, 0.3)]),
}
#: Solver iterations per sample of the naive loop, and its damping (of J J^T, dimensionless).
MAX_ITER, DAMPING, TOL = 40, 1e-10, 1e-6
#: The batched prototype stops a sample whose residual gained less than 0.1% over this many iterations.
STALL = 5


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


# --- the naive loop, as a Pinocchio user writes it -------------------------------------------------------------


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


# --- a batched prototype: the engine issue 23 asks for, as a reference figure -----------------------------------


def _rpy_matrices(rpy: np.ndarray) -> np.ndarray:
    """(B, 3, 3) ``Rz(yaw) Ry(pitch) Rx(roll)`` (Pinocchio's rpy) of (B, 3) angles."""
    (cr, cp, cy), (sr, sp, sy) = np.cos(rpy).T, np.sin(rpy).T
    return np.stack([np.stack([cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr], -1),
                     np.stack([sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr], -1),
                     np.stack([-sp, cp * sr, cp * cr], -1)], -2)  # fmt: skip


def _rpy_rates(rpy: np.ndarray) -> np.ndarray:
    """(B, 3, 3) world angular velocity per rpy rate (Pinocchio's ``computeRpyJacobian(rpy, WORLD)``)."""
    _, cp, cy = np.cos(rpy).T
    _, sp, sy = np.sin(rpy).T
    z, o = np.zeros_like(cp), np.ones_like(cp)
    return np.stack([np.stack([cy * cp, -sy, z], -1), np.stack([sy * cp, cy, z], -1), np.stack([-sp, z, o], -1)], -2)


def _log3(r: np.ndarray) -> np.ndarray:
    """(B, 3) rotation vectors of (B, 3, 3) rotations (angles below pi)."""
    theta = np.arccos(np.clip((np.trace(r, axis1=1, axis2=2) - 1) / 2, -1.0, 1.0))
    vee = 0.5 * np.stack([r[:, 2, 1] - r[:, 1, 2], r[:, 0, 2] - r[:, 2, 0], r[:, 1, 0] - r[:, 0, 1]], -1)
    small = theta < 1e-6
    factor = np.where(small, 1 + theta**2 / 6, theta / np.where(small, 1.0, np.sin(theta)))
    return vee * factor[:, None]


def _skew(v: np.ndarray) -> np.ndarray:
    z = np.zeros(len(v))
    x, y, w = v.T
    return np.stack([np.stack([z, -w, y], -1), np.stack([w, z, -x], -1), np.stack([-y, x, z], -1)], -2)


class BatchedNewton:
    """Every limb tip at a target pose, for B samples at once; the pose coordinates ``free`` unknowns too.

    Pinocchio's kinematics per sample (a Python loop), the rest batched: position errors and rotation vectors
    in world axes, their Jacobians from the world joint Jacobian (no ``Jlog``: quasi-Newton, quadratic near the
    solution anyway), damped least squares on dimensionless rates, solved with ``np.linalg.solve`` over the stack.
    A sample stops at a residual below 1e-12, when a step no longer halves a residual below 1e-6, or when it
    gained less than 0.1% over ``STALL`` iterations (then it is not closed unless below 1e-6).
    """

    def __init__(self, mech: pinmob.Mechanism, free: list[int]) -> None:
        model = self.model = mech.model
        assert model.nq == model.nv, "one-degree joints only (q moves by addition)"
        self.data, self.length, self.free = model.createData(), mech.length_scale, free
        self.tips = [limb.tip_id for limb in mech.limbs]
        self.masks = []
        for tip in self.tips:
            mask = np.zeros(model.nv)
            for j in model.supports[model.frames[tip].parentJoint].tolist()[1:]:
                mask[model.joints[j].idx_v : model.joints[j].idx_v + model.joints[j].nv] = 1.0
            self.masks.append(mask)
        linear = np.array([model.joints[j].shortname().startswith("JointModelP") for j in range(1, model.njoints)])
        self.col = np.concatenate([np.where(linear, self.length, 1.0), [self.length if f < 3 else 1.0 for f in free]])

    def residual(self, q: np.ndarray, p: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(B, 6k) dimensionless residuals and (B, 6k, nv + len(free)) Jacobians per dimensionless rate."""
        model, data, n = self.model, self.data, len(q)
        jw, tips = np.empty((n, 6, model.nv)), np.empty((n, len(self.tips), 4, 4))
        for b in range(n):
            jw[b] = pin.computeJointJacobians(model, data, q[b])
            pin.updateFramePlacements(model, data)
            for i, tip in enumerate(self.tips):
                tips[b, i] = data.oMf[tip].homogeneous
        rt = _rpy_matrices(p[:, 3:])
        rates = _rpy_rates(p[:, 3:])
        errors, rows = [], []
        for i, mask in enumerate(self.masks):
            pos, rot = tips[:, i, :3, 3], tips[:, i, :3, :3]
            jac = jw * mask
            lin = jac[:, :3] - _skew(pos) @ jac[:, 3:]
            extra = np.zeros((n, 6, len(self.free)))
            for c, f in enumerate(self.free):
                if f < 3:
                    extra[:, f, c] = -1.0
                else:
                    extra[:, 3:, c] = -rates[:, :, f - 3]
            errors.append(np.concatenate([(pos - p[:, :3]) / self.length, _log3(rot @ rt.transpose(0, 2, 1))], 1))
            rows.append(np.concatenate([np.concatenate([lin / self.length, jac[:, 3:]], 1), extra], 2))
        scale = np.array([1 / self.length] * 3 + [1.0] * 3)
        for r in rows:
            r[:, :3, self.model.nv :] *= scale[:3, None]
        return np.concatenate(errors, 1), np.concatenate(rows, 1) * self.col

    def solve(
        self, q: np.ndarray, p: np.ndarray, max_iter: int = MAX_ITER
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Closed configurations, poses and whether each sample closed to 1e-6 (B rows each)."""
        q, p = q.copy(), p.copy()
        nv, k = self.model.nv, len(self.tips)
        history = np.full((len(q), max_iter + 1), np.inf)
        last = np.full(len(q), np.inf)  # the residual at the configuration returned
        active = np.arange(len(q))
        for it in range(max_iter + 1):
            e, jac = self.residual(q[active], p[active])
            parts = e.reshape(len(active), k, 2, 3)
            now = history[active, it] = last[active] = np.max(np.linalg.norm(parts, axis=3), axis=(1, 2))
            before = np.min(history[active, : max(it - STALL + 1, 0)], axis=1, initial=np.inf)
            best = np.min(history[active, max(it - STALL + 1, 0) : it + 1], axis=1)
            stalled = best > (1 - 1e-3) * before  # less than 0.1% gained over the last STALL iterations
            polished = (now <= TOL) & (now > 0.5 * np.min(history[active, :it], axis=1, initial=np.inf))
            keep = (now > 1e-12) & ~stalled & ~polished
            active, e, jac = active[keep], e[keep], jac[keep]
            if not active.size:
                break
            jjt = jac @ jac.transpose(0, 2, 1)
            lam = 1e-12 * np.trace(jjt, axis1=1, axis2=2)[:, None, None] * np.eye(jjt.shape[1])
            dz = -(jac.transpose(0, 2, 1) @ np.linalg.solve(jjt + lam, e[..., None]))[..., 0]
            dz *= np.minimum(1.0, 1.0 / np.max(np.abs(dz), axis=1))[:, None]
            step = dz * self.col
            q[active] += step[:, :nv]
            p[np.ix_(active, self.free)] += step[:, nv:]
        return q, p, last <= TOL


def batched_scan(mech: pinmob.Mechanism, spec: ScanSpec) -> list[tuple[bool, int]]:
    """(reachable, DoF) per sample: the first sample of each line one after the other (each from the previous
    line's first), then every line's samples in lockstep (each from its line's previous sample), then
    :func:`pinmob.analysis.batch.batch_analysis.analyze_batch` on all closed samples."""
    names = [a[0] for a in spec.axes]
    grids = [np.linspace(lo, hi, n) for _, lo, hi, n in spec.axes]
    free = [POSE_COORDS.index(c) for c in spec.following]
    newton = BatchedNewton(mech, free)
    n_line = spec.axes[-1][3]
    lines = spec.size // n_line
    base = pose_vector(pinmob.scan.platform_pose(mech, spec.q_ref))
    for c, v in dict(spec.held).items():
        base[POSE_COORDS.index(c)] = v
    targets = np.tile(base, (spec.size, 1))
    for k, idx in enumerate(np.ndindex(*[a[3] for a in spec.axes])):
        for c, g, i in zip(names, grids, idx):
            targets[k, POSE_COORDS.index(c)] = g[i]
    targets = targets.reshape(lines, n_line, 6)
    qs = np.empty((lines, n_line, mech.model.nq))
    ok = np.zeros((lines, n_line), bool)
    q, p = spec.q_ref[None], base[None]
    for r in range(lines):
        target = targets[r, :1].copy()
        target[:, free] = p[:, free]
        sol, p_sol, closed = newton.solve(q, target)
        qs[r, 0], ok[r, 0] = sol[0], closed[0]
        if closed[0]:
            q, p = sol, p_sol
    q, p = qs[:, 0], targets[:, 0].copy()
    for j in range(1, n_line):
        target = targets[:, j].copy()
        target[:, free] = p[:, free]
        sol, p_sol, closed = newton.solve(q, target)
        qs[:, j], ok[:, j] = sol, closed
        q = np.where(closed[:, None], sol, q)
        p = np.where(closed[:, None], p_sol, p)
    ok, qs = ok.reshape(-1), qs.reshape(-1, mech.model.nq)
    dof = np.full(spec.size, -1)
    dof[ok] = analyze_batch(mech, qs[ok], rtol=spec.rtol).dof
    return [(bool(a), int(d)) for a, d in zip(ok, dof)]


# --- pinmob -----------------------------------------------------------------------------------------------------


def rows_equal(single: list[dict[str, Any]], batch: list[dict[str, Any]]) -> bool:
    """The two engines' rows: the same columns, equal values but floats, floats to 1e-7 (NaN equal to NaN)."""

    def same(a: Any, b: Any) -> bool:
        if isinstance(a, float) and isinstance(b, float):
            return (np.isnan(a) and np.isnan(b)) or abs(a - b) <= 1e-7 * max(1.0, abs(a), abs(b))
        return bool(a == b)

    return len(single) == len(batch) and all(
        list(s) == list(b) and all(same(s[k], b[k]) for k in s) for s, b in zip(single, batch)
    )


#: The parts of the engine's time, by the functions cProfile charges (cumulative; the last entry takes the rest).
PARTS = {
    "batched predictor": "solve_poses",
    "single-sample solver": "assemble_target",
    "batch analysis": "analyse",
    "single-sample analysis": "_evaluate",
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
    for (path, _, name), (_, _, _, ct, _) in stats.items():
        if name in PARTS.values() and "pinmob" in path:
            cum[name] = cum.get(name, 0.0) + ct
    out = {part: cum.get(fn, 0.0) / total for part, fn in PARTS.items()}
    out["rest"] = max(0.0, 1.0 - sum(out.values()))
    return out


def bench_grid(label: str, count: int) -> dict[str, Any]:
    robot, at, axes = GRIDS[label]
    mech = pinmob.load(robot)
    spec = grid_spec(mech, at, [(c, lo, hi, count) for c, lo, hi in axes])
    n = spec.size
    small = replace(spec, axes=tuple((c, lo, hi, 3) for c, lo, hi, _ in spec.axes))
    list(scan_in_process(mech, small))  # warm-up
    analyze_batch(mech, np.array([spec.q_ref] * 2), rtol=spec.rtol, singular_values=True)  # numba's cache loaded
    t_pinmob, rows = timed(lambda: [r for r in scan_in_process(mech, spec)], repeats=REPEATS)
    single_spec = replace(spec, engine="single")
    t_single, single_rows = timed(lambda: [r for r in scan_in_process(mech, single_spec)], repeats=REPEATS)
    samples = [r for r in rows if not r["refined"]]
    t_naive, (verdicts, iters, closed) = timed(lambda: naive_scan(mech, spec), repeats=REPEATS)
    ours = [(bool(r["reachable"]), int(r["dof"]) if r["reachable"] else -1) for r in samples]
    agree = sum(a == b for a, b in zip(ours, verdicts))
    reach = [v[0] for v in verdicts]
    calls = [it + 1 for it in iters]  # the last one (the closure checked) serves the analysis too
    t_floor, _ = timed(lambda: floor_loop(mech, closed, calls), repeats=REPEATS)
    t_batched, batched = timed(lambda: batched_scan(mech, spec), repeats=REPEATS)
    agree_batched = sum(a == b for a, b in zip(ours, batched))
    split = profile_split(mech, spec)
    us = 1e6 / n
    calls_pinmob = kinematics_calls(lambda: list(scan_in_process(mech, spec)))
    calls_single = kinematics_calls(lambda: list(scan_in_process(mech, single_spec)))
    calls_naive = kinematics_calls(lambda: naive_scan(mech, spec))
    return {
        "grid": " ".join(f"{c}:{lo:g}:{hi:g}:{k}" for c, lo, hi, k in spec.axes),
        "at": at,
        "following": list(spec.following),
        "samples": n,
        "reachable": int(sum(reach)),
        "refined": len(rows) - len(samples),
        "agree": agree,
        "pinmob_us": t_pinmob * us,
        "single_us": t_single * us,
        "rows_equal": rows_equal(single_rows, rows),
        "naive_us": t_naive * us,
        "floor_us": t_floor * us,
        "batched_us": t_batched * us,
        "batched_agree": agree_batched,
        "naive_iterations": float(np.mean(iters)),
        "kinematics_per_sample": {
            "pinmob": calls_pinmob / n,
            "single": calls_single / n,
            "naive": calls_naive / n,
            "floor": float(np.mean(calls)),
        },  # fmt: skip
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--quick", action="store_true", help="9 x 9 grids, 4 designs")
    args = parser.parse_args()
    count, designs = (9, 4) if args.quick else (21, 16)
    out: dict[str, Any] = {}
    print(f"per sample [us of CPU time, fastest of {REPEATS} runs], one process (compare the ratios of one run)")
    for name in GRIDS:
        r = out[name] = bench_grid(name, count)
        robot = GRIDS[name][0]
        follow = f", {' '.join(r['following'])} following" if r["following"] else ""
        print(f"{robot} --grid {r['grid']} --at {r['at']}{follow}: {r['reachable']}/{r['samples']} reachable, "
              f"{r['refined']} refined points; verdicts (reachable, DoF) agree on {r['agree']}/{r['samples']}")  # fmt: skip
        ratio = r["pinmob_us"] / r["naive_us"]
        print(f"  pinmob {r['pinmob_us']:6.0f}   naive loop {r['naive_us']:6.0f} ({r['naive_iterations']:.1f} "
              f"iterations)   floor {r['floor_us']:5.1f}   pinmob/naive {ratio:.2f}x "
              f"(target 0.2x: {'met' if ratio <= 0.2 else 'not met'})   pinmob/floor {r['pinmob_us'] / r['floor_us']:.0f}x")  # fmt: skip
        print(f"  single-sample engine {r['single_us']:.0f} ({r['single_us'] / r['naive_us']:.2f}x the naive loop; "
              f"batched/single {r['pinmob_us'] / r['single_us']:.2f}); rows of the two engines equal: {r['rows_equal']}")  # fmt: skip
        kin = r["kinematics_per_sample"]
        print(f"  batched prototype (in this file) {r['batched_us']:.0f}, {r['batched_us'] / r['naive_us']:.2f}x the naive "
              f"loop; its verdicts agree with pinmob's on {r['batched_agree']}/{r['samples']}")  # fmt: skip
        print(f"  computeJointJacobians calls per sample: pinmob {kin['pinmob']:.1f} (single-sample engine "
              f"{kin['single']:.1f}), naive loop {kin['naive']:.1f}, floor {kin['floor']:.1f}")  # fmt: skip
        kinematics = r["floor_us"] * kin["pinmob"] / kin["floor"]  # the floor's cost per call, at pinmob's count
        print("  the engine's time (cProfile): " + ", ".join(f"{k} {v:.0%}" for k, v in r["split"].items())
              + f"; Pinocchio's kinematics at its {kin['pinmob']:.1f} calls per sample ~{kinematics:.0f} us "
              f"({kinematics / r['pinmob_us']:.0%})")  # fmt: skip
    s = out["sweep"] = bench_sweep(designs)
    print(f"example sweep ({EXAMPLE.name}, 9 x 9 scan per design, {s['designs']} designs): "
          f"{s['in_process_s'] * 1e3:.0f} ms per design in process, {s['dask2_s'] * 1e3:.0f} ms per design on "
          f"2 Dask workers")  # fmt: skip
    print(json.dumps(out))


if __name__ == "__main__":
    main()
