"""The batched scan engine gives the single-sample rows (issue 23, item 3).

Every built-in model is scanned over a grid of its first two actuated joints around its first configuration
(forward kinematics, every other joint following), the platform models also over two pose coordinates, and
the paths of the other scan tests that cross singular points and edges of the reachable set: with
``engine="batch"`` (a chunk's samples analysed together, :mod:`pinmob.scan.batch_rows`) and ``engine="single"``
(each sample on its own, the path the scans took before the batch). The verdict columns (reachable, DoF,
motion type, ranks, singularity class, near-singular flag, closest question, limbs, uncontrolled motions,
reason) are equal and the figures (pose coordinates, joint values, distances, singular values, grid
parameters) agree to round-off; with numba absent the numpy path gives the same rows.
"""

from __future__ import annotations

import math
import subprocess
import sys
from dataclasses import replace
from types import SimpleNamespace
from typing import Any

import pytest

import pinmob
from pinmob.exceptions import PinmobError
from pinmob.io.loader import builtin_models
from pinmob.scan import grid_spec, path_spec
from pinmob.scan.batch_rows import analyse, batchable
from pinmob.scan.chunk import assemble_target
from pinmob.scan.scan_run import scan_in_process

#: Pose grids of the platform models, over coordinates that move: (model, at, axes).
POSE_GRIDS = [
    ("3-PUU", "generic", [("x", -0.06, 0.06, 7), ("y", -0.06, 0.06, 7)]),
    ("3-PUU", "generic", [("x", -0.3, 0.3, 7), ("y", -0.3, 0.3, 7)]),  # mostly out of reach: edges refined
    ("6-UPS", "home", [("x", -0.05, 0.05, 7), ("y", -0.05, 0.05, 7)]),
    ("3-RPS", "home", [("roll", -0.2, 0.2, 7), ("pitch", -0.2, 0.2, 7)]),
    ("3-PRS", "home", [("roll", -0.2, 0.2, 7), ("pitch", -0.2, 0.2, 7)]),
    ("Delta", "generic", [("x", -0.05, 0.05, 5), ("y", -0.05, 0.05, 5)]),
    # coarse and wide: the seeding walk's steps are long (the first from 'generic' to yaw -2.5, pitch -1), where
    # two solvers from one seed can close on equivalent joint values (U joints turned by pi): the walk must be the
    # single-sample engine's
    ("3-UPU-wrist", "generic", [("yaw", -2.5, 2.5, 4), ("pitch", -1.0, 1.0, 4)]),
    # three coordinates: the walk turns lines in a serpentine, with long joint moves between waypoints (a
    # correction of the order of the secant's step closed a spherical joint on its other Euler triple)
    ("3-RPS", "home", [("roll", -0.2, 0.2, 4), ("pitch", -0.2, 0.2, 3), ("z", -0.02, 0.02, 3)]),
    # the constraint singularity at z = 0 between samples: one refined point per line, not two a few 1e-6 apart
    ("3-UPU", "generic", [("x", -0.0082, 0.0082, 3), ("y", -0.0082, 0.0082, 3), ("z", -0.0082, 0.0082, 4)]),
]
#: Paths of the other scan tests: through a Type II pose, to a constraint singularity, off the workspace.
PATHS = [("6-UPS", "home", "0,0,0.4,0,0,2.0944", 70), ("3-UPU", "generic", "constraint-singular", 40)]

VERDICTS = ("index", "refined", "reachable", "dof", "motion_type", "constraint_rank", "locked_dof", "singularity",
            "near_singular", "closest", "singular_limbs", "dependent_limbs", "uncontrolled", "reason")  # fmt: skip


def _joint_grid(mech: pinmob.Mechanism):
    at = next(iter(mech.configurations))
    q = pinmob.closed_configuration(mech, at)
    axes = []
    for name in mech.actuated[:2]:
        v = pinmob.model.joint_values.joint_value(mech.model, q, name)
        step = (
            0.02 * mech.length_scale
            if mech.model.joints[mech.model.getJointId(name)].shortname().startswith("JointModelP")
            else 0.1
        )
        axes.append((name, v - step, v + step, 5))
    return grid_spec(mech, at, axes)


def _joint_path(mech: pinmob.Mechanism):
    """A path over the first two actuated joints (the grid's steps), from the first configuration, 9 samples."""
    grid = _joint_grid(mech)
    end = ",".join(f"{name}={hi!r}" for name, _, hi, _ in grid.axes)
    return path_spec(mech, next(iter(mech.configurations)), end, 9, joints=True)


def _specs():
    for name in builtin_models():
        mech = pinmob.load(name)
        if mech.actuated and mech.configurations:
            yield pytest.param(name, "joints", id=f"{name}-joints")
            yield pytest.param(name, "joint path", id=f"{name}-joint-path")
    for i, (name, at, axes) in enumerate(POSE_GRIDS):
        yield pytest.param(name, ("grid", at, axes), id=f"{name}-grid{i}")
    for name, start, end, n in PATHS:
        yield pytest.param(name, ("path", start, end, n), id=f"{name}-path")


#: A refined point is located to the refinement's accuracy, not to round-off: from seeds that differ by round-off
#: (the walk's predictor against the single-sample solver) its figures at a singular point agree to ~1e-7.
REFINED_RTOL = 1e-6


def _close(a: object, b: object, rtol: float = 1e-7) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        if math.isnan(a) or math.isnan(b):
            return math.isnan(a) and math.isnan(b)
        return abs(a - b) <= rtol * max(1.0, abs(a), abs(b))
    return a == b


def _compare(single: list[dict], batch: list[dict]) -> None:
    assert len(batch) == len(single)
    for s, b in zip(single, batch):
        assert list(b) == list(s)
        for key in s:
            if key in VERDICTS or not isinstance(s[key], float):
                assert b[key] == s[key], (key, s, b)
            else:
                assert _close(b[key], s[key], REFINED_RTOL if s["refined"] else 1e-7), (key, s[key], b[key])


@pytest.mark.parametrize(("name", "what"), list(_specs()))
def test_batch_rows_equal_single_rows(name, what):
    mech = pinmob.load(name)
    try:
        if what == "joints":
            spec = _joint_grid(mech)
        elif what == "joint path":
            spec = _joint_path(mech)
        elif what[0] == "grid":
            spec = grid_spec(mech, what[1], what[2])
        else:
            spec = path_spec(mech, what[1], what[2], what[3])
    except PinmobError as exc:
        pytest.fail(f"{name}: {exc}")
    single = list(scan_in_process(mech, replace(spec, engine="single")))
    batch = list(scan_in_process(mech, spec))
    _compare(single, batch)


def test_the_batch_decides_the_plain_samples_and_leaves_the_singular_ones():
    """On the benchmark grids the batch decides every sample (none is near a singularity); at the 3-UPU's
    constraint singularity and the 6-UPS's Type II pose it leaves the sample to the single-sample analysis."""
    for name, at, axes in POSE_GRIDS[:1] + POSE_GRIDS[2:4]:
        mech = pinmob.load(name)
        spec = grid_spec(mech, at, axes)
        qs = [pinmob.closed_configuration(mech, at)]
        for k in range(spec.size):
            qs.append(assemble_target(mech, spec.target(k), qs[-1], tol=spec.closure_tol))
        assert batchable(mech) and all(a is not None for a in analyse(mech, qs, spec.rtol, spec.generic_rank))
    for name, at in (("3-UPU", "constraint-singular"), ("6-UPS", "type2")):
        mech = pinmob.load(name)
        q = pinmob.closed_configuration(mech, at)
        g = pinmob.analysis.generic.generic_constraint_rank(mech)
        assert analyse(mech, [q], 1e-6, g) == [None]
    assert not batchable(pinmob.load("Delta"))  # loops inside its limbs: every sample on its own


NO_NUMBA = """
import sys; sys.modules['numba'] = None
import math
import subprocess
import sys
from dataclasses import replace
import pinmob
from pinmob.analysis.batch.batch_analysis import numba_available
from pinmob.scan import grid_spec
from pinmob.scan.batch_rows import analyse, batchable
from pinmob.scan.chunk import assemble_target
from pinmob.scan.scan_run import scan_in_process
assert not numba_available()
for name, at, axes in {grids!r}:
    mech = pinmob.load(name)
    spec = grid_spec(mech, at, axes)
    single = list(scan_in_process(mech, replace(spec, engine="single")))
    batch = list(scan_in_process(mech, spec))
    same = len(single) == len(batch) and all(
        list(s) == list(b) and all(s[k] == b[k] or (isinstance(s[k], float) and (math.isnan(s[k]) and math.isnan(b[k])
        or abs(s[k] - b[k]) <= 1e-7 * max(1.0, abs(s[k])))) for k in s) for s, b in zip(single, batch))
    print(name, len(batch), same)
"""


def test_without_numba_the_numpy_path_gives_the_same_rows():
    """numba is an optional extra: without it the batch runs on numpy's batched SVDs, with the same rows."""
    grids = [POSE_GRIDS[0], POSE_GRIDS[3]]
    code = NO_NUMBA.format(grids=grids)
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True, timeout=600)
    assert out.stdout.split() == ["3-PUU", "49", "True", "3-RPS", "49", "True"]


def test_the_predictors_rotation_error_is_right_up_to_a_half_turn():
    """The batched solver's rotation vectors (numpy path: ``rotation_stacks.log3_stack``) against the vectors the rotations were made
    from: a closed form from the antisymmetric part gave 1e6 instead of 2.5 rad at pi - 1e-10."""
    import numpy as np
    import pinocchio as pin

    from pinmob.assembly.batched.rotation_stacks import log3_stack as _log3

    axis = np.array([0.3, 0.5, 0.8]) / np.linalg.norm([0.3, 0.5, 0.8])
    angles = [0.0, 1e-8, 1.0, 3.0, np.pi - 1e-7, np.pi - 1e-10]
    rotations = np.stack([pin.exp3(axis * t) for t in angles])
    np.testing.assert_allclose(_log3(rotations), [axis * t for t in angles], atol=1e-6)


def test_the_predictors_rpy_stacks_are_pinocchios():
    """The numpy path's target rotations and rpy rates (``rotation_stacks.rpy_matrices``, ``rpy_rates``) on a stack
    of angles, up to the gimbal lock, against Pinocchio's ``rpyToMatrix`` and ``computeRpyJacobian`` (WORLD) of
    each."""
    import numpy as np
    import pinocchio as pin

    from pinmob.assembly.batched.rotation_stacks import rpy_matrices, rpy_rates

    rpy = np.random.default_rng(5).uniform(-np.pi, np.pi, (12, 3))
    rpy[0], rpy[1, 1] = 0.0, np.pi / 2
    np.testing.assert_allclose(rpy_matrices(rpy), [pin.rpy.rpyToMatrix(a) for a in rpy], atol=1e-15)
    np.testing.assert_allclose(rpy_rates(rpy), [pin.rpy.computeRpyJacobian(a, pin.WORLD) for a in rpy], atol=1e-15)


def _rotations_for_rpy() -> Any:
    """Rotations for matrixToRpy: random ones (small to large), near the gimbal lock (pitch within 1e-12 to 1e-1 of
    +-pi/2) and at multiples of pi/2 (the branches of Eigen's eulerAngles and of Pinocchio's range)."""
    import numpy as np
    import pinocchio as pin

    rng = np.random.default_rng(9)
    out = [pin.exp3(rng.normal(size=3) * s) for s in (1e-3, 0.3, 2.0, 10.0) for _ in range(500)]
    for _ in range(500):
        sign = rng.choice([-1.0, 1.0])
        out.append(pin.rpy.rpyToMatrix(rng.normal(), sign * (np.pi / 2 - 10 ** rng.uniform(-12, -1)), rng.normal()))
    special = [0.0, np.pi / 2, -np.pi / 2, np.pi, -np.pi, 1e-17]
    out += [pin.rpy.rpyToMatrix(*rng.choice(special, size=3)) for _ in range(300)]
    return np.array(out)


@pytest.mark.parametrize("compiled", [pytest.param(True, marks=pytest.mark.needs_numba), False])
def test_the_rows_angles_are_pinocchios_matrix_to_rpy_to_the_last_bit(compiled, monkeypatch):
    """``rotation_stacks.matrices_rpy`` (a batch row's roll, pitch and yaw, read off the predictor's placements) is
    ``pin.rpy.matrixToRpy`` of each rotation to the last bit: compiled (``rpy_kernel.matrix_rpy``: Eigen's
    eulerAngles(2, 1, 0) and Pinocchio's pitch range, the same operations), and Pinocchio's own call without numba;
    on (B, 3, 3) rotations and on (B, 4, 4) placements."""
    import numpy as np
    import pinocchio as pin

    import pinmob.assembly.batched.rotation_stacks as stacks

    if compiled:
        assert stacks._rpy_kernel() is not None
    else:
        monkeypatch.setattr(stacks, "_rpy_kernel", lambda: None)  # as without numba: Pinocchio's call on each
    rotations = _rotations_for_rpy()
    want = np.array([pin.rpy.matrixToRpy(r) for r in rotations])
    assert np.array_equal(stacks.matrices_rpy(rotations), want)
    placements = np.zeros((len(rotations), 4, 4))
    placements[:, :3, :3], placements[:, :3, 3], placements[:, 3, 3] = rotations, 1.0, 1.0
    assert np.array_equal(stacks.matrices_rpy(placements), want)


@pytest.mark.needs_numba
def test_the_compiled_rotation_error_is_right_up_to_a_half_turn():
    """The compiled predictor's ``log3`` (by the unit quaternion) against the vectors the rotations were made from,
    to round-off: its first form (the angle from ``acos`` of the trace) was 2e-8 off at pi - 1e-12."""
    import numpy as np
    import pinocchio as pin

    from pinmob.assembly.batched.batch_newton_kernel import log3

    rng = np.random.default_rng(3)
    out = np.empty(3)
    for t in [0.0, 1e-12, 1e-8, 1e-4, 0.5, 2.0, 3.0, *(np.pi - np.logspace(-13, -1, 13)), np.pi]:
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        log3(pin.exp3(axis * t), out)
        if t == np.pi:  # either direction of the axis is the same half turn
            out *= np.sign(out @ axis)
        np.testing.assert_allclose(out, axis * t, atol=5e-15 * max(1.0, t))


def _off_closure(name, at, free, rng, count):
    """A ``PoseProblem`` of model ``name`` (pose coordinates ``free`` unknowns) and ``count`` configurations
    perturbed off its closed configuration ``at``, with their kinematics and random target poses near the origin."""
    import numpy as np
    import pinocchio as pin

    from pinmob.assembly.batched.batch_solver import PoseProblem

    mech = pinmob.load(name)
    q0 = pinmob.closed_configuration(mech, at)
    problem = PoseProblem(mech, free)
    qs = np.array([pin.integrate(mech.model, q0, 0.05 * rng.normal(size=mech.model.nv)) for _ in range(count)])
    poses = 0.05 * rng.normal(size=(count, 6))
    full, frames = problem.kinematics(qs)
    return problem, full, frames, poses


@pytest.mark.needs_numba
def test_the_compiled_steps_are_numpys_steps():
    """The compiled errors and damped steps (``batch_newton_kernel``) equal the numpy path's (``residual_of``, the
    normal equations solved by LAPACK) to round-off, at configurations off closure, with and without free coordinates (where they are determined)."""
    import numpy as np

    from pinmob.assembly.batched import batch_newton_kernel as kernel
    from pinmob.assembly.batched.batch_solver import DAMPING, MAX_STEP

    rng = np.random.default_rng(4)
    for name, at, free in (("3-PUU", "generic", ()), ("3-RPS", "home", (0, 1, 5)), ("6-UPS", "home", ())):
        problem, full, frames, poses = _off_closure(name, at, free, rng, 6)
        e, jac = problem.residual_of(full, frames, poses)
        jtj = jac.transpose(0, 2, 1) @ jac
        jtj += (DAMPING / jtj.shape[1]) * np.einsum("bii->b", jtj)[:, None, None] * np.eye(jtj.shape[1])
        dz = -np.linalg.solve(jtj, jac.transpose(0, 2, 1) @ e[..., None])[..., 0]
        dz *= np.minimum(1.0, MAX_STEP / np.abs(dz).max(axis=1))[:, None]
        e2, worst = kernel.pose_errors(frames, poses, problem.length)
        np.testing.assert_allclose(e2, e, atol=1e-14)
        np.testing.assert_allclose(worst, np.linalg.norm(e.reshape(6, -1, 3), axis=2).max(axis=1), rtol=1e-14)
        which = np.array([0, 2, 5])
        mask = problem.mask[:, 0]
        structure = kernel.step_structure(mask, mask.shape[1], len(free))
        steps = kernel.damped_steps(full, frames, poses, e2, which, mask, problem.col, problem.free_array,
                                    problem.length, DAMPING, MAX_STEP, structure)  # fmt: skip
        np.testing.assert_allclose(steps, dz[which], atol=1e-12)


def _dense_steps(full, frames, poses, e, which, mask, col, free, length, damping, max_step):
    """The damped steps of ``batch_newton_kernel.damped_steps`` by the textbook loops in Python: the Jacobian
    (the kernel's expressions, a frame's rows zero in the joints that do not carry it; ``math``'s cosines and sines,
    the C library's, as the compiled code's), every product of the normal equations summed, zeros included, and
    Gaussian elimination with partial pivoting on the whole matrix."""
    import numpy as np

    nf, nv = frames.shape[1], full.shape[2]
    m = nv + len(free)
    out = np.empty((len(which), m))
    for s, b in enumerate(which):
        jac = np.zeros((6 * nf, m))
        cy, sy, cp, sp = math.cos(poses[b, 5]), math.sin(poses[b, 5]), math.cos(poses[b, 4]), math.sin(poses[b, 4])
        for f in range(nf):
            px, py, pz, r = frames[b, f, 0, 3], frames[b, f, 1, 3], frames[b, f, 2, 3], 6 * f
            for j in range(nv):
                if mask[f, j] != 0.0:
                    wx, wy, wz = full[b, 3, j], full[b, 4, j], full[b, 5, j]
                    jac[r, j] = (full[b, 0, j] - (py * wz - pz * wy)) / length * col[j]
                    jac[r + 1, j] = (full[b, 1, j] - (pz * wx - px * wz)) / length * col[j]
                    jac[r + 2, j] = (full[b, 2, j] - (px * wy - py * wx)) / length * col[j]
                    jac[r + 3, j], jac[r + 4, j], jac[r + 5, j] = wx * col[j], wy * col[j], wz * col[j]
            for c, k in enumerate(free):
                if k < 3:
                    jac[r + k, nv + c] = -col[nv + c] / length
                elif k == 3:
                    jac[r + 3, nv + c], jac[r + 4, nv + c], jac[r + 5, nv + c] = -cy * cp, -sy * cp, sp
                elif k == 4:
                    jac[r + 3, nv + c], jac[r + 4, nv + c] = sy, -cy
                else:
                    jac[r + 5, nv + c] = -1.0
        a, g, x = [[0.0] * m for _ in range(m)], [0.0] * m, [0.0] * m
        for i in range(m):
            acc = 0.0
            for r in range(6 * nf):
                acc += jac[r, i] * e[b, r]
            g[i] = -acc
            for j in range(m):
                acc = 0.0
                for r in range(6 * nf):
                    acc += jac[r, i] * jac[r, j]
                a[i][j] = acc
        mu = damping / m * sum(a[i][i] for i in range(m))
        for i in range(m):
            a[i][i] += mu
        for k in range(m):
            p = max(range(k, m), key=lambda i: (abs(a[i][k]), -i))  # the first of the largest
            a[k], a[p], g[k], g[p] = a[p], a[k], g[p], g[k]
            for i in range(k + 1, m):
                factor = a[i][k] / a[k][k]
                for j in range(k + 1, m):
                    a[i][j] -= factor * a[k][j]
                g[i] -= factor * g[k]
        for i in range(m - 1, -1, -1):
            acc = g[i]
            for j in range(i + 1, m):
                acc -= a[i][j] * x[j]
            x[i] = acc / a[i][i]
        biggest = max(abs(v) for v in x)
        out[s] = np.array(x) * (min(1.0, max_step / biggest) if biggest > 0.0 else 1.0)
    return out


@pytest.mark.needs_numba
def test_the_compiled_steps_are_the_textbook_loops_exactly():
    """The kernel skips the zeros of the block structure (a limb's joints move its own tip only: the 6-UPS's 36
    x 36 system is six 6 x 6 blocks), never a non-zero: its steps equal the textbook loops' (every product summed,
    elimination on the whole matrix; :func:`_dense_steps`) exactly (``np.array_equal``: a zero's sign aside, which
    a summed product of zeros may turn), without free coordinates, with the 3-RPS's x, y, yaw and the 6-UPS's
    roll, pitch, yaw and x free, and on random stacks whose frames share joints."""
    import numpy as np

    from pinmob.assembly.batched import batch_newton_kernel as kernel
    from pinmob.assembly.batched.batch_solver import DAMPING, MAX_STEP

    def structure(mask, free):
        return kernel.step_structure(mask, mask.shape[1], len(free))

    rng = np.random.default_rng(7)
    cases = (
        ("3-PUU", "generic", ()),
        ("3-RPS", "home", (0, 1, 5)),
        ("6-UPS", "home", ()),
        ("6-UPS", "home", (3, 4, 5, 0)),
    )
    for name, at, free in cases:
        problem, full, frames, poses = _off_closure(name, at, free, rng, 4)
        e, _ = kernel.pose_errors(frames, poses, problem.length)
        which, mask = np.array([0, 1, 3]), problem.frame_mask
        assert (mask == 0.0).any()  # a structure to skip
        args = (full, frames, poses, e, which, mask, problem.col, problem.free_array, problem.length, DAMPING)
        steps = kernel.damped_steps(*args, MAX_STEP, structure(mask, free))
        assert np.array_equal(steps, _dense_steps(*args, MAX_STEP)), (name, free)
    for _ in range(40):  # random stacks: 1 to 4 frames whose supports overlap, 0 to 3 free coordinates
        nf, nv = int(rng.integers(1, 5)), int(rng.integers(2, 9))
        mask = (rng.random((nf, nv)) < 0.5).astype(float)
        free = rng.permutation(6)[: int(rng.integers(0, 4))].astype(np.int64)
        frames = np.tile(np.eye(4), (3, nf, 1, 1))
        frames[:, :, :3, 3] = rng.normal(size=(3, nf, 3))
        args = (rng.normal(size=(3, 6, nv)), frames, rng.normal(size=(3, 6)), rng.normal(size=(3, 6 * nf)),
                np.arange(3), mask, rng.uniform(0.5, 2.0, nv + free.size), free, 0.3, DAMPING)  # fmt: skip
        steps = kernel.damped_steps(*args, MAX_STEP, structure(mask, free))
        assert np.array_equal(steps, _dense_steps(*args, MAX_STEP)), (mask, free)


def _rps_free_twists():
    """The 3-RPS, its closed samples over a 3 x 3 roll x pitch grid (and home), and their batch analysis."""
    import numpy as np

    from pinmob.analysis.batch.batch_analysis import analyze_batch

    mech = pinmob.load("3-RPS")
    spec = grid_spec(mech, "home", [("roll", -0.2, 0.2, 3), ("pitch", -0.2, 0.2, 3)])
    qs = [pinmob.closed_configuration(mech, "home")]
    for k in range(spec.size):
        qs.append(assemble_target(mech, spec.target(k), qs[-1], tol=spec.closure_tol))
    return mech, qs, analyze_batch(mech, np.array(qs), twists=True)


def test_the_motion_type_from_the_counts_is_classify_twists_label():
    """motion_type_of_span (the batch's label, counts only) against motion_type(classify_twists(...)) (the single
    analysis's): random spans of every dimension, world-aligned ones moved off the origin and mixed, a helical
    screw beside a translation, and the 3-RPS's free twists at closed samples of a roll x pitch grid."""
    import numpy as np

    from pinmob.screw.classify import classify_twists, motion_type
    from pinmob.screw.motion_label import motion_type_of_span

    rng, length = np.random.default_rng(5), 0.3
    spans = [rng.normal(size=(6, k)) for k in range(7) for _ in range(10)]
    for cols in ([0, 1, 2], [0, 1, 5], [3, 4, 5], [0, 1, 2, 5], [2, 3, 4], [5], [0, 5]):
        t = np.eye(6)[:, cols]
        t[:3] += np.cross(rng.normal(size=3), t[3:].T).T  # about a point off the origin
        spans.append(t @ np.linalg.qr(rng.normal(size=(len(cols), len(cols))))[0])
    helix = np.zeros((6, 2))
    helix[5, 0], helix[2, 0], helix[0, 1] = 1.0, 0.01, 1.0
    spans.append(helix)
    mech, qs, res = _rps_free_twists()
    st = np.array([1 / mech.length_scale] * 3 + [1.0] * 3)[:, None]
    spans += [res.free_twists[i][:, : res.dof[i]] / st for i in range(len(qs))]
    labels = set()
    for t, size in zip(spans, [length] * (len(spans) - len(qs)) + [mech.length_scale] * len(qs)):
        label = motion_type(classify_twists(t, size))
        assert motion_type_of_span(t, size) == label, (t, label)
        labels.add(label)
    assert {"rigid", "3T", "3R", "2T1R", "3T1R", "3T3R", "1T1H"} <= set(labels)


@pytest.mark.needs_numba
def test_the_batchs_motion_types_are_classify_twists_labels_compiled_and_not():
    """motion_types (the batch's labels of orthonormal dimensionless spans, as analyze_jacobians gives them): the
    compiled counts (motion_kernel, numba) and the numpy path against motion_type(classify_twists(...)) of the same
    spans in SI units: random spans of every dimension and rank, world-aligned ones off the origin (some with
    a pitch), a helical screw beside a translation, pure translations, and the 3-RPS's free twists."""
    import numpy as np

    from pinmob.analysis.batch.batch_analysis import motion_types
    from pinmob.screw.classify import classify_twists, motion_type

    rng = np.random.default_rng(6)
    spans = [rng.normal(size=(6, k)) for k in range(7) for _ in range(10)]
    for _ in range(80):  # rank-deficient
        k = int(rng.integers(1, 6))
        r = int(rng.integers(0, k + 1))
        spans.append(rng.normal(size=(6, r)) @ rng.normal(size=(r, k)) if r else np.zeros((6, k)))
    for _ in range(80):  # world-aligned about a point off the origin, some turned into screws of one pitch
        cols = sorted(rng.choice(6, size=int(rng.integers(1, 6)), replace=False).tolist())
        t = np.eye(6)[:, cols]
        t[:3] += np.cross(rng.normal(size=3), t[3:].T).T
        t[:3] += 0.02 * int(rng.integers(-1, 2)) * t[3:]
        spans.append(t @ np.linalg.qr(rng.normal(size=(len(cols), len(cols))))[0])
    helix = np.zeros((6, 2))
    helix[5, 0], helix[2, 0], helix[0, 1] = 1.0, 0.01, 1.0
    spherical = np.eye(6)[:, 3:]
    spherical[:3] = np.cross([0.1, -0.2, 0.3], spherical[3:].T).T  # 3R about a point off the origin
    spans += [helix, spherical, np.eye(6)[:, :3] @ rng.normal(size=(3, 2))]
    length = 0.3
    st = np.array([1 / length] * 3 + [1.0] * 3)[:, None]
    free, dof, want = np.full((len(spans), 6, 6), np.nan), np.zeros(len(spans), np.int64), []
    for i, t in enumerate(spans):
        want.append(motion_type(classify_twists(t, length)))
        if t.shape[1]:
            u, s, _ = np.linalg.svd(st * t)
            dof[i] = int(np.sum(s > 1e-6 * s[0])) if s[0] > 0 else 0
            free[i, :, : dof[i]] = u[:, : dof[i]]
    mech, qs, res = _rps_free_twists()
    rps_st = np.array([1 / mech.length_scale] * 3 + [1.0] * 3)[:, None]
    rps = [motion_type(classify_twists(res.free_twists[i][:, : res.dof[i]] / rps_st, mech.length_scale))
           for i in range(len(qs))]  # fmt: skip
    for engine in ("numba", "numpy"):
        assert motion_types(free, dof, length, 1e-6, engine) == want, engine
        assert motion_types(res.free_twists, res.dof, mech.length_scale, 1e-6, engine) == rps, engine
    assert {"rigid", "3T", "2T", "3R", "2T1R", "1T2R", "3T1R", "3T3R", "1T1H", "1H", "2H", "3H"} <= set(want)


def test_the_secant_start_moves_on_along_the_line_the_short_way_round():
    """The predictor's start on a line (``pinmob.assembly.moved_stack`` from the sample before to the seed): the
    closed sample moved on by the last step, a revolute angle's part of it the short way round across the wrap at
    +-pi; the start is nearer the next closed sample than the sample is (3-PUU, a line of x at generic). Both on the
    vector-space path (q + move) and on Pinocchio's difference / integrate path."""
    import numpy as np

    from pinmob.assembly import PoseProblem, moved_stack

    mech = pinmob.load("3-PUU")
    q0 = pinmob.closed_configuration(mech, "generic")
    line = [pinmob.assemble_pose(mech, _moved(mech, q0, dx), q0) for dx in (0.0, 0.01, 0.02)]
    for vector_space in (True, False):
        problem = PoseProblem(mech)
        problem.vector_space = vector_space
        seeds = np.array([line[1], line[1]])
        start, step = moved_stack(problem, np.array([line[0], line[1]]), seeds, np.array([True, False]), seeds)
        assert np.array_equal(start[1], line[1]) and step[1] == 0.0  # no sample before: the seed itself
        assert np.linalg.norm(start[0] - line[2]) < 0.1 * np.linalg.norm(line[1] - line[2])
        angle = int(problem.angles[0])
        before, seed = line[1].copy(), line[1].copy()
        before[angle], seed[angle] = np.pi - 0.02, -np.pi + 0.03  # moved +0.05 rad across the wrap
        moved = moved_stack(problem, before[None], seed[None], np.ones(1, bool), seed[None])[0][0]
        assert moved[angle] == pytest.approx(-np.pi + 0.08, abs=1e-12)


def _moved(mech, q, dx):
    """The platform pose at q moved by dx along x."""
    import pinocchio as pin

    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q)
    pose = data.oMf[mech.platform_id].copy()
    pose.translation = pose.translation + [dx, 0.0, 0.0]
    return pose


def test_the_rows_joint_values_and_limits_column_wise_are_the_per_sample_ones():
    """row_columns.joint_rows / limits_of over a stack equal joint_row / outside_limits per configuration (the
    per-sample functions the rows used before), with configurations outside the limits and samples not closed
    (None). Fails on the old code: no row_columns."""
    import numpy as np
    import pinocchio as pin

    from pinmob.model.joints import outside_limits
    from pinmob.scan.chain_scan import joint_row, value_joints
    from pinmob.scan.row_columns import joint_rows, limits_of, values_and_limits

    rng = np.random.default_rng(5)
    for name in ("3-PUU", "6-UPS", "Delta"):
        mech = pinmob.load(name)
        q0 = pinmob.closed_configuration(mech, next(iter(mech.configurations)))
        qs = [pin.integrate(mech.model, q0, 0.3 * rng.normal(size=mech.model.nv)) for _ in range(6)]
        qs[1] = qs[1].copy()
        qs[1][0] = mech.model.upperPositionLimit[0] + 0.5  # outside its limits
        qs[3] = None
        joints = value_joints(mech)
        targets = [None, {}, None, None, {joints[0]: 0.1}, None]
        want_limits = [None if q is None else outside_limits(mech.model, q) for q in qs]
        assert limits_of(mech.model, qs) == want_limits
        assert any(want_limits[1])
        want_rows = [None if q is None else joint_row(mech, joints, q, t) for q, t in zip(qs, targets)]
        assert joint_rows(mech, joints, qs, targets) == want_rows
        samples = [SimpleNamespace(q=q, known=None if q is None else t or {}) for q, t in zip(qs, targets)]
        got = values_and_limits(mech, joints, samples)  # the joint values as rows of one table (ArrayRow)
        assert [(None if v is None else dict(v), limits) for v, limits in got] == list(zip(want_rows, want_limits))
        assert {type(v).__name__ for v, _ in got} == {"ArrayRow", "NoneType"}
    assert limits_of(mech.model, [None]) == [None] and joint_rows(mech, joints, [None], [None]) == [None]


@pytest.mark.parametrize(("axes", "share"), [([("A_slider", -0.2, 0.2, 15), ("B_slider", -0.2, 0.2, 15)], 0.5),
                                             ([("x", -0.3, 0.3, 15), ("y", -0.3, 0.3, 15)], 1.0)])  # fmt: skip
def test_the_refinement_screen_leaves_only_samples_the_refinement_would_leave(monkeypatch, axes, share):
    """:func:`pinmob.scan.chunk.to_refine` screens, with numpy over the batch's distances (a group's chunks at once),
    the samples whose refinement would give nothing: the rows equal those of refining around every sample (a grid
    crossing limb singularities, refined between samples; a grid mostly out of reach, refined at the edges), while
    most samples are screened out."""
    import pinmob.scan.chunk as chunk
    import pinmob.scan.lockstep as lockstep
    from pinmob.scan.scan_run import scan_table

    mech = pinmob.load("3-PUU")
    spec = grid_spec(mech, "generic", axes)
    looked: list[int] = []
    refine = chunk._Chunk.refine
    monkeypatch.setattr(chunk._Chunk, "refine", lambda self, k, *a: looked.append(k) or refine(self, k, *a))
    screened = scan_table(mech, spec)
    screened_looks = len(looked)
    monkeypatch.setattr(
        lockstep, "to_refine", lambda chunks, *a: [list(range(start, stop)) for start, stop, *_ in chunks]
    )
    every = scan_table(mech, spec)
    assert screened.json_lines() == every.json_lines()
    assert int(screened["refined"].sum()) > 0
    assert len(looked) - screened_looks == spec.size and screened_looks < share * spec.size


def test_the_refinement_screen_of_a_group_is_each_chunk_screened_alone():
    """:func:`pinmob.scan.chunk.to_refine` screens a group's chunks in one numpy pass, each sample against its
    neighbours within its own chunk's entries. By hand, on a line of five samples with one distance 0.5, 0.4, 0.3,
    0.4, 0.5: only sample 2 (a local minimum) is left to refine; with sample 3 undecided (entry -1), samples 2, 3 and
    4 (next to it or it). Then, on random groups (lines of 1, 2, 3, 5 and 130 samples cut into chunks of 1 to 40,
    so that chunks start mid-line with a left neighbour, and end at their line's end or before it; a fifth of the
    entries undecided; distances from a few values, so with ties), the group's screen equals each chunk's alone."""
    import numpy as np

    from pinmob.scan.batch_rows import BatchRows
    from pinmob.scan.chunk import to_refine

    def batch_of(distances: list[list[float]]) -> BatchRows:
        d = np.array(distances, float)
        return BatchRows(np.ones(len(d), bool), {}, tuple(f"q{i}" for i in range(d.shape[1])), d)

    def entries_of(at: dict[int, int]):
        return lambda lo, hi: [at[k] for k in range(lo, hi)]

    line = batch_of([[0.5], [0.4], [0.3], [0.4], [0.5]])
    assert to_refine([(0, 5, 0, 4, entries_of(dict(enumerate(range(5)))))], line, 1e-9) == [[2]]
    assert to_refine([(0, 5, 0, 4, entries_of({0: 0, 1: 1, 2: 2, 3: -1, 4: 4}))], line, 1e-9) == [[2, 3, 4]]
    assert to_refine([], line, 1e-9) == [] and to_refine([(0, 2, 0, 4, entries_of({}))], None, 1e-9) == [[0, 1]]

    rng = np.random.default_rng(7)
    for _ in range(200):
        chunks, rows, first = [], [], 0
        for size in rng.choice([1, 2, 3, 5, 130], size=rng.integers(1, 5)):
            at = {k: (len(rows) + i if rng.random() > 0.2 else -1) for i, k in enumerate(range(first, first + size))}
            rows += [list(rng.choice([0.1, 0.2, 0.3, 1e-12], size=2)) for _ in range(size)]
            start = first
            while start < first + size:
                stop = min(first + size, start + int(rng.integers(1, 41)))
                chunks.append((start, stop, first, first + size - 1, entries_of(at)))
                start = stop
            first += size
        batch = batch_of(rows)
        assert to_refine(chunks, batch, 1e-9) == [to_refine([c], batch, 1e-9)[0] for c in chunks]
