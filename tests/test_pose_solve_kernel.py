"""The single-sample solver at a platform pose compiled (``pinmob.assembly.compiled_solve``) against the Python loop.

The truths: Pinocchio's own ``log6`` and ``Jlog6`` (the kernel writes their formulas anew, the coefficients by their
series at small angles), and :func:`pinmob.assembly.solver.solve` iterating on Pinocchio's calls from the same start
(``assemble_pose`` without ``compiled``): the same verdict on every target, the same configuration where it closes,
the same residuals where it does not. numba is the optional ``fast`` extra: without it (and with
``PINMOB_KINEMATICS=pinocchio``, or a closure besides the limb tips) the Python loop runs.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest

import pinmob
from pinmob.assembly import assemble_joints, assemble_pose
from pinmob.assembly.compiled_solve import compiled_pose_solver
from pinmob.exceptions import ClosureError
from pinmob.model import joint_value, linear_velocity_mask
from pinmob.scan import platform_pose

pytestmark = pytest.mark.needs_numba


def _frames(mech: pinmob.Mechanism) -> list[int]:
    """assemble_pose's frames: the platform's, then the limb tips on other bodies."""
    body = mech.model.frames[mech.platform_id].parentJoint
    return [mech.platform_id] + [
        limb.tip_id for limb in mech.limbs if mech.model.frames[limb.tip_id].parentJoint != body
    ]


@pytest.mark.parametrize("angle", [0.0, 1e-9, 1e-6, 1e-4, 1e-3, 0.05, 0.1 - 1e-12, 0.1, 0.5, 2.0, np.pi - 1e-4])
def test_log6_and_jlog6_are_pinocchios(angle):
    """log6 and Jlog6 of placements turned by ``angle`` about random axes, at random offsets, against Pinocchio's
    and against central differences of Pinocchio's log6 (``d log6(M exp6(h e_k)) / dh``, h = 1e-6).

    Pinocchio's Jlog6 loses digits between 1e-4 and 1e-2 rad (its closed form there: 7e-7 at 3e-4 rad); the
    kernel's series do not, so it is compared to Pinocchio's to 1e-6 there and to 1e-10 elsewhere, and to the
    differences to 1e-7 everywhere.
    """
    from pinmob.assembly.compiled_solve.se3_log import log6_jlog6

    rng = np.random.default_rng(int(angle * 1e6) + 7)
    h = 1e-6
    for _ in range(20):
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        m = pin.SE3(pin.exp3(axis * angle), rng.normal(size=3))
        e, jlog = np.empty(6), np.empty((6, 6))
        log6_jlog6(np.ascontiguousarray(m.rotation), np.ascontiguousarray(m.translation), e, jlog)
        np.testing.assert_allclose(e, pin.log6(m).vector, rtol=0, atol=1e-12)
        loose = 1e-4 <= angle <= 1e-2
        np.testing.assert_allclose(jlog, pin.Jlog6(m), rtol=0, atol=1e-6 if loose else 1e-10)
        differences = np.array(
            [
                (pin.log6(m * pin.exp6(pin.Motion(h * k))).vector - pin.log6(m * pin.exp6(pin.Motion(-h * k))).vector)
                / (2 * h)
                for k in np.eye(6)
            ]  # fmt: skip
        ).T
        np.testing.assert_allclose(jlog, differences, rtol=0, atol=1e-7)


def _near_targets(mech: pinmob.Mechanism, q: np.ndarray, count: int, seed: int) -> list[pin.SE3]:
    """Platform poses the mechanism reaches: its actuated joints moved by up to 0.02 (x L, or rad) and closed."""
    rng = np.random.default_rng(seed)
    model, names = mech.model, mech.actuated
    scale = [mech.length_scale if linear_velocity_mask(model)[model.joints[model.getJointId(n)].idx_v] else 1.0
             for n in names]  # fmt: skip
    out = []
    for _ in range(count):
        moved = {n: joint_value(model, q, n) + rng.uniform(-0.02, 0.02) * k for n, k in zip(names, scale)}
        out.append(platform_pose(mech, assemble_joints(mech, moved, q)))
    return out


def _far_targets(mech: pinmob.Mechanism, q: np.ndarray, count: int, seed: int) -> list[pin.SE3]:
    """Platform poses moved by up to 1.5 (x L in position, rad in rotation) in every coordinate: mostly out of reach."""
    rng = np.random.default_rng(seed)
    moves = rng.uniform(-1.5, 1.5, size=(count, 6)) * np.array([mech.length_scale] * 3 + [1.0] * 3)
    return [platform_pose(mech, q) * pin.exp6(pin.Motion(m)) for m in moves]


@pytest.mark.filterwarnings("ignore:assembly at a platform pose of '6-UPS'")
@pytest.mark.parametrize("robot, at", [("3-PUU", "generic"), ("6-UPS", "home"), ("3-RPS", "home")])
def test_the_compiled_solve_gives_the_python_loops_verdicts_configurations_and_residuals(robot, at):
    """Targets the mechanism reaches near the reference and targets far from it: both loops from the same seed."""
    mech = pinmob.load(robot)
    q = pinmob.closed_configuration(mech, at)
    assert compiled_pose_solver(mech, _frames(mech)) is not None
    closed = failed = 0
    for pose in _near_targets(mech, q, 12, seed=len(robot)) + _far_targets(mech, q, 12, seed=len(robot)):
        outcome = []
        for compiled in (True, False):
            try:
                outcome.append(assemble_pose(mech, pose, q, max_iter=40, stall_window=5, compiled=compiled))
            except ClosureError as exc:
                outcome.append(exc)
        fast, slow = outcome
        if isinstance(slow, ClosureError):
            assert isinstance(fast, ClosureError) and list(fast.residuals) == list(slow.residuals)
            for key, value in slow.residuals.items():
                np.testing.assert_allclose(fast.residuals[key], value, rtol=1e-6, atol=1e-12)
            failed += 1
        else:
            assert not isinstance(fast, ClosureError)
            np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-9)
            closed += 1
    # both verdicts met; the 6-UPS closes at every far target (its legs then leave their limits: the warning)
    assert closed >= 12 and (failed >= 1 or robot == "6-UPS")


@pytest.mark.parametrize("robot", ["3-PUU", "6-UPS", "3-RPS", "3-UPU"])
def test_the_solves_jacobian_factorises_by_limbs(robot):
    """At a platform pose the stacked Jacobian is block-diagonal, a block a limb (its tip's rows, its joints'
    columns): Pinocchio's frame Jacobians are zero off the blocks at random configurations, and the SVD block by
    block (one-sided Jacobi) gives numpy's singular values, ``U^T e`` and the damped and pseudo-inverse steps."""
    from pinmob.assembly.compiled_solve.block_svd import block_svd, frame_blocks

    mech = pinmob.load(robot)
    model, frames = mech.model, _frames(mech)
    blocks = frame_blocks(model, frames)
    rows, rows_at, cols, cols_at = blocks
    assert len(rows_at) - 1 == len(mech.limbs) and sorted(rows) == list(range(6 * len(frames)))
    limb_columns = sorted(sorted(model.joints[model.getJointId(j)].idx_v for j in limb.joints) for limb in mech.limbs)
    assert sorted(cols[a:b].tolist() for a, b in zip(cols_at, cols_at[1:])) == limb_columns  # one-dof joints
    on = np.zeros((6 * len(frames), model.nv), bool)
    for b in range(len(rows_at) - 1):
        on[np.ix_(rows[rows_at[b] : rows_at[b + 1]], cols[cols_at[b] : cols_at[b + 1]])] = True
    rng = np.random.default_rng(3)
    data = model.createData()
    for _ in range(5):
        q = pin.randomConfiguration(model, -np.ones(model.nq), np.ones(model.nq))
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        jac = np.vstack([pin.getFrameJacobian(model, data, f, pin.LOCAL) for f in frames])
        assert np.abs(jac[~on]).max() == 0.0
        jac *= rng.uniform(0.1, 10.0, model.nv)  # column scales
        e = rng.normal(size=jac.shape[0])
        s, vt, g = np.empty(len(cols)), np.empty((len(cols), model.nv)), np.empty(len(cols))
        top = block_svd(jac, e, blocks, s, vt, g)
        u_ref, s_ref, vt_ref = np.linalg.svd(jac, full_matrices=False)
        np.testing.assert_allclose(np.sort(s)[::-1], s_ref[: len(s)], rtol=0, atol=1e-13 * s_ref[0])
        assert top == s.max()
        lam = 1e-3 * top**2
        damped = vt.T @ (s / (s**2 + lam) * g)
        np.testing.assert_allclose(damped, vt_ref.T @ (s_ref / (s_ref**2 + lam) * (u_ref.T @ e)), atol=1e-12)
        kept = s > 1e-9 * top
        pinv = vt[kept].T @ (g[kept] / s[kept])
        np.testing.assert_allclose(pinv, np.linalg.pinv(jac, rcond=1e-9) @ e, atol=1e-11 * np.abs(pinv).max())


def test_the_solve_by_blocks_and_by_lapack_agree():
    """The kernel's two factorisations (the SVD a block a limb, LAPACK's of the whole Jacobian where the frames
    make one block), from the same starts of the 3-PUU: the same verdicts, configurations and last residuals."""
    from pinmob.assembly.compiled_solve.block_svd import frame_blocks

    mech = pinmob.load("3-PUU")
    q = pinmob.closed_configuration(mech, "generic")
    solver = compiled_pose_solver(mech, _frames(mech))
    assert solver is not None and len(solver.blocks[1]) == 4  # three blocks
    whole = pin.buildSampleModelManipulator()
    one = frame_blocks(whole, [whole.getFrameId("wrist1_joint"), whole.getFrameId("effector_body")])
    closed = 0
    for pose in _near_targets(mech, q, 6, seed=5) + _far_targets(mech, q, 6, seed=5):
        by_blocks = solver.solve(pose, q, 1e-12, 40, stall_window=5)
        solver.blocks, blocks = one, solver.blocks
        try:
            by_lapack = solver.solve(pose, q, 1e-12, 40, stall_window=5)
        finally:
            solver.blocks = blocks
        assert by_blocks.converged == by_lapack.converged
        if by_blocks.converged:
            np.testing.assert_allclose(by_blocks.q, by_lapack.q, rtol=0, atol=1e-9)
            closed += 1
        else:
            np.testing.assert_allclose(by_blocks.residual, by_lapack.residual, rtol=1e-6)
    assert closed >= 6


def test_frames_that_share_joints_are_one_block():
    """A humanoid's hands and feet share its free-flyer root: one block, factorised whole (LAPACK's). Its base
    fixed, the feet are two blocks, the hands (both below the chest's joints) still one; two frames on one chain, one."""
    from pinmob.assembly.compiled_solve.block_svd import frame_blocks

    human = pin.buildSampleModelHumanoid()
    ends = ["larm_effector_body", "rarm_effector_body", "lleg_effector_body", "rleg_effector_body"]
    assert frame_blocks(human, [human.getFrameId(name) for name in ends])[1].tolist() == [0]
    fixed = pin.buildReducedModel(human, [human.getJointId("root_joint")], pin.neutral(human))
    rows, rows_at, cols, cols_at = frame_blocks(fixed, [fixed.getFrameId(name) for name in ends[2:]])
    assert rows_at.tolist() == [0, 6, 12] and cols_at.tolist() == [0, 6, 12] and len(set(cols)) == 12
    assert frame_blocks(fixed, [fixed.getFrameId(name) for name in ends[:2]])[1].tolist() == [0]
    arm = pin.buildSampleModelManipulator()
    assert frame_blocks(arm, [arm.getFrameId("wrist1_joint"), arm.getFrameId("effector_body")])[1].tolist() == [0]


def test_where_the_compiled_solve_does_not_run(monkeypatch):
    """A closure besides the limb tips (the Delta's parallelograms), or the Pinocchio engine asked for: Python."""
    delta = pinmob.load("Delta")
    assert delta.closures and compiled_pose_solver(delta, _frames(delta)) is None
    mech = pinmob.load("3-PUU")
    monkeypatch.setenv("PINMOB_KINEMATICS", "pinocchio")
    assert compiled_pose_solver(mech, _frames(mech)) is None
    monkeypatch.setenv("PINMOB_KINEMATICS", "compiled")
    assert compiled_pose_solver(mech, _frames(mech)) is not None


WITHOUT_NUMBA = """
import sys; sys.modules['numba'] = None
import pinmob
from pinmob.assembly import assemble_joints, assemble_pose
from pinmob.assembly.compiled_solve import compiled_pose_solver
from pinmob.scan import platform_pose
mech = pinmob.load("3-PUU")
q = pinmob.closed_configuration(mech, "generic")
print(compiled_pose_solver(mech, [mech.platform_id]) is None, sys.modules['numba'] is None)
q2 = assemble_pose(mech, platform_pose(mech, q), q, compiled=True)
print(float(abs(q2 - q).max()) < 1e-9)
"""


def test_without_numba_the_python_loop_runs():
    """numba absent: no compiled solve, and ``compiled=True`` iterates in Python."""
    out = subprocess.run([sys.executable, "-c", WITHOUT_NUMBA], capture_output=True, text=True, check=True, timeout=300)
    assert out.stdout.split() == ["True", "True", "True"]


def test_a_scan_out_of_reach_gives_the_same_rows_both_ways(monkeypatch):
    """The 3-PUU's wide grid (most samples out of reach: the single-sample solver's, and the refinements at the edges
    of the reachable set) with the compiled solve and with Pinocchio's loop: the same verdicts and reasons, the
    figures to 1e-7, a refined point's to 1e-6 (located by bisections and a minimisation: to its tolerances, not
    round-off, as in ``tests/test_scan_batch.py``)."""
    from pinmob.scan import grid_spec
    from pinmob.scan.scan_run import scan_in_process

    mech = pinmob.load("3-PUU")
    spec = grid_spec(mech, "generic", [("x", -0.3, 0.3, 9), ("y", -0.3, 0.3, 9)])
    rows = {}
    for engine in ("compiled", "pinocchio"):
        monkeypatch.setenv("PINMOB_KINEMATICS", engine)
        rows[engine] = list(scan_in_process(mech, spec))
    assert len(rows["compiled"]) == len(rows["pinocchio"]) > spec.size  # refined points added
    assert 0 < sum(r["reachable"] for r in rows["compiled"]) < len(rows["compiled"]) / 2
    for a, b in zip(rows["compiled"], rows["pinocchio"]):
        assert list(a) == list(b)
        for key in a:
            if isinstance(a[key], float) and np.isnan(a[key]):
                assert np.isnan(b[key]), key
            elif isinstance(a[key], float):
                rtol = 1e-6 if a["refined"] else 1e-7
                assert abs(a[key] - b[key]) <= rtol * max(1.0, abs(a[key]), abs(b[key])), key
            else:
                assert a[key] == b[key], key


def test_the_kernels_reference_code_is_the_kinematics_kernels():
    """The kernel names Pinocchio's LOCAL by the kinematics kernel's code (it cannot import that module's face)."""
    from pinmob.assembly.compiled_solve.pose_solve_kernel import LOCAL
    from pinmob.model.kinematics_kernel import LOCAL as KERNEL_LOCAL

    assert LOCAL == KERNEL_LOCAL
