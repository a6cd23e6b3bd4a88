"""Compiled frame kinematics (pinmob.model.compiled_kinematics) against Pinocchio's own calls, and its fallback.

The truth is Pinocchio computed here, separately (framesForwardKinematics for placements, computeJointJacobians +
getFrameJacobian for Jacobians), at random configurations of every built-in model, every model file under
tests/data pinmob loads (URDF, Extended URDF, MJCF through MuJoCo) and hand-built models of the joint types no
file uses (universal, planar, translation, unbounded revolutes, nested composite).
"""

from __future__ import annotations

import logging
import sys
import warnings
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pinmob
from pinmob.exceptions import ConfigurationError, PinmobError
from pinmob.model.compiled_kinematics import FrameKinematics, frame_kinematics
from pinmob.model.compiled_kinematics import numba_available as numba_installed

DATA = Path(__file__).parent / "data"
FILES = sorted(p for ext in ("toml", "xml", "yaml") for p in DATA.rglob(f"*.{ext}"))
REFERENCES = (pin.LOCAL, pin.LOCAL_WORLD_ALIGNED, pin.WORLD)
needs_numba = pytest.mark.skipif(not numba_installed(), reason="numba (the fast extra) is not installed")


def random_configurations(model: pin.Model, count: int, seed: int = 0) -> np.ndarray:
    """``count`` random configurations (angles and lengths in [-3, 3] where unbounded; unit quaternions)."""
    pin.seed(seed)
    low = np.maximum(model.lowerPositionLimit, -3.0)
    high = np.minimum(model.upperPositionLimit, 3.0)
    return np.array([pin.randomConfiguration(model, low, high) for _ in range(count)])


def pinocchio_truth(model: pin.Model, qs: np.ndarray, frames: list[int], reference) -> tuple:
    data = model.createData()
    rot = np.empty((len(qs), len(frames), 3, 3))
    pos = np.empty((len(qs), len(frames), 3))
    jac = np.empty((len(qs), len(frames), 6, model.nv))
    for b, q in enumerate(qs):
        pin.framesForwardKinematics(model, data, q)
        for i, f in enumerate(frames):
            rot[b, i], pos[b, i] = data.oMf[f].rotation, data.oMf[f].translation
        data = model.createData()  # the Jacobians from a fresh Data: nothing left over from the placements
        pin.computeJointJacobians(model, data, q)
        for i, f in enumerate(frames):
            jac[b, i] = np.reshape(pin.getFrameJacobian(model, data, f, reference), (6, model.nv))
    return rot, pos, jac


def assert_matches(model: pin.Model, engine: str | None = "compiled", count: int = 6) -> FrameKinematics:
    frames = list(range(model.nframes))
    kin = frame_kinematics(model, frames, engine)
    qs = random_configurations(model, count)
    for reference in REFERENCES:
        rot, pos, jac = kin.jacobians(qs, reference)
        t_rot, t_pos, t_jac = pinocchio_truth(model, qs, frames, reference)
        np.testing.assert_allclose(rot, t_rot, rtol=0, atol=1e-12)
        np.testing.assert_allclose(pos, t_pos, rtol=0, atol=1e-12 * max(1.0, np.abs(t_pos).max()))
        np.testing.assert_allclose(jac, t_jac, rtol=0, atol=1e-12 * max(1.0, np.abs(t_jac).max()))
    out = tuple(np.empty_like(a) for a in (t_rot, t_pos, t_jac))
    assert all(a is b for a, b in zip(kin.jacobians(qs, reference, out=out), out))  # filled in place
    np.testing.assert_allclose(out[2], t_jac, rtol=0, atol=1e-12 * max(1.0, np.abs(t_jac).max()))
    rot, pos = kin.placements(qs[0])  # one configuration: no stack dimension
    np.testing.assert_allclose(rot, t_rot[0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(pos, t_pos[0], rtol=0, atol=1e-12 * max(1.0, np.abs(t_pos).max()))
    if kin.engine == "compiled":
        assert_integrates(model, kin, qs)
    return kin


def assert_integrates(model: pin.Model, kin: FrameKinematics, qs: np.ndarray) -> None:
    """The compiled ``integrate`` and ``difference`` of an integrable model are Pinocchio's; a free-flyer or planar
    joint makes it not."""
    kinds = {j.shortname() for j in model.joints[1:]}
    assert kin.integrable == (not kinds & {"JointModelFreeFlyer", "JointModelPlanar"}), kinds
    if not kin.integrable:
        return
    from pinmob.model import difference_kernel, integrate_kernel

    rng = np.random.default_rng(0)
    _, kind, _, iq, iv = kin.tables[:5]
    for q in qs:
        for size in (1e-10, 1e-6, 0.3, 2.0):  # the series of a small rotation, and large steps
            v = rng.normal(0.0, size, model.nv)
            out = np.empty(model.nq)
            integrate_kernel(q, v, kind, iq, iv, out)
            np.testing.assert_allclose(out, pin.integrate(model, q, v), rtol=0, atol=1e-14)
            # its inverse, pin.difference (a spherical joint's the shorter way: both quaternion signs)
            moved = pin.integrate(model, q, v)
            d = np.empty(model.nv)
            difference_kernel(q, moved, kind, iq, iv, d)
            np.testing.assert_allclose(d, pin.difference(model, q, moved), rtol=0, atol=1e-13)
            for e in np.flatnonzero(kind == 3):  # SPHERICAL
                moved[iq[e] : iq[e] + 4] *= -1.0
            difference_kernel(q, moved, kind, iq, iv, d)
            np.testing.assert_allclose(d, pin.difference(model, q, moved), rtol=0, atol=1e-13)
    for q0, q1 in zip(qs, qs[::-1]):  # far apart
        d = np.empty(model.nv)
        difference_kernel(q0, q1, kind, iq, iv, d)
        np.testing.assert_allclose(d, pin.difference(model, q0, q1), rtol=0, atol=1e-12)


def load_quietly(path: Path) -> pinmob.Mechanism:
    with warnings.catch_warnings():  # meshes not found: kinematics only
        warnings.simplefilter("ignore")
        logging.disable(logging.WARNING)
        try:
            return pinmob.load(path)
        finally:
            logging.disable(logging.NOTSET)


# --- hand-built models of the joint types no file uses ---------------------------------------------------------


def chain(*joints: pin.JointModel) -> pin.Model:
    """A serial chain of ``joints``, each placed at an arbitrary pose in its parent, with a frame at each body."""
    model = pin.Model()
    rng = np.random.default_rng(7)
    parent = 0
    for k, joint in enumerate(joints):
        placement = pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3))
        parent = model.addJoint(parent, joint, placement, f"j{k}")
        previous = model.addJointFrame(parent)
        model.addBodyFrame(f"b{k}", parent, pin.SE3(pin.exp3(rng.normal(size=3)), rng.normal(size=3)), previous)
    return model


def skew_axis() -> np.ndarray:
    return np.array([0.3, -0.5, 0.8]) / np.linalg.norm([0.3, -0.5, 0.8])


def composite() -> pin.JointModelComposite:
    inner = pin.JointModelComposite(pin.JointModelPY())
    inner.addJoint(
        pin.JointModelRevoluteUnaligned(skew_axis()), pin.SE3(pin.exp3(np.array([0.1, 0.2, 0.3])), np.ones(3))
    )
    joint = pin.JointModelComposite(pin.JointModelRX())
    joint.addJoint(inner, pin.SE3(pin.exp3(np.array([-0.4, 0.0, 0.7])), np.array([0.2, -0.1, 0.5])))
    joint.addJoint(pin.JointModelSpherical(), pin.SE3.Identity())
    return joint


HAND_BUILT = {
    "revolute and prismatic on each axis": lambda: chain(pin.JointModelRX(), pin.JointModelPY(), pin.JointModelRZ(),
                                                          pin.JointModelPX(), pin.JointModelRY(), pin.JointModelPZ()),
    "skew revolute, prismatic, unbounded": lambda: chain(pin.JointModelRevoluteUnaligned(skew_axis()),
                                                          pin.JointModelPrismaticUnaligned(skew_axis()),
                                                          pin.JointModelRUBX(), pin.JointModelRUBY()),
    "universal": lambda: chain(pin.JointModelUniversal(np.array([1.0, 0, 0]), np.array([0.0, 0.6, 0.8])),
                               pin.JointModelUniversal(np.array([0.0, 0, 1]), np.array([1.0, 0, 0]))),
    "free, spherical, planar, translation": lambda: chain(pin.JointModelFreeFlyer(), pin.JointModelSpherical(),
                                                           pin.JointModelPlanar(), pin.JointModelTranslation()),
    "composite": lambda: chain(pin.JointModelRZ(), composite(), pin.JointModelPX()),
}  # fmt: skip


@needs_numba
@pytest.mark.parametrize("name", sorted(HAND_BUILT))
def test_hand_built_joint_types(name):
    model = HAND_BUILT[name]()
    assert assert_matches(model).engine == "compiled"


@needs_numba
def test_branches_and_frames_on_the_world():
    """A tree (two branches from one joint) and a frame fixed to the world: only the supporting columns move it."""
    model = chain(pin.JointModelRX(), pin.JointModelSpherical())
    model.addJoint(1, pin.JointModelPZ(), pin.SE3(np.eye(3), np.array([0.0, 1.0, 0.0])), "branch")
    model.addJointFrame(model.njoints - 1)
    model.addBodyFrame("fixed", 0, pin.SE3(pin.exp3(np.array([0.2, 0.1, 0.0])), np.array([1.0, 2.0, 3.0])), 0)
    assert_matches(model)


# --- every built-in model and every model file of the tests ----------------------------------------------------


@needs_numba
@pytest.mark.parametrize("name", sorted(pinmob.builtin_models()))
def test_builtin_models(name):
    assert assert_matches(pinmob.load(name).model).engine == "compiled"


@needs_numba
def test_model_files():
    """Every model file under tests/data that pinmob loads (the others are there to be refused)."""
    kinds, loaded, refused = set(), 0, set()
    for path in FILES:
        try:
            mech = load_quietly(path)
        except (PinmobError, ValueError, RuntimeError):
            refused.add(Path(path).name)
            continue
        model = mech.model
        assert assert_matches(model, count=3).engine == "compiled", path
        kinds |= {j.shortname() for j in model.joints[1:]}
        loaded += 1
    assert loaded >= 60 and refused <= {"package.xml"}, refused  # only ROS manifests beside xacro files are refused
    # the files hold each of these (the others are hand-built above)
    assert {"JointModelFreeFlyer", "JointModelSpherical", "JointModelComposite", "JointModelRUBZ",
            "JointModelRevoluteUnaligned", "JointModelPrismaticUnaligned"} <= kinds  # fmt: skip


# --- the fallback ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["3-PUU", "6-UPS", "Bennett"])
def test_pinocchio_engine(name):
    """The fallback gives Pinocchio's figures through the same interface (stacks, one configuration, references)."""
    assert assert_matches(pinmob.load(name).model, engine="pinocchio").engine == "pinocchio"


def test_unsupported_joint_falls_back_to_pinocchio(monkeypatch):
    monkeypatch.delenv("PINMOB_KINEMATICS", raising=False)
    model = chain(
        pin.JointModelRX(),
        pin.JointModelSphericalZYX(),
        pin.JointModelHelicalUnaligned(skew_axis(), 0.1),
        pin.JointModelRevoluteUnboundedUnaligned(),
    )
    kin = assert_matches(model, engine=None)
    assert kin.engine == "pinocchio"
    if numba_installed():
        assert "JointModelSphericalZYX" in kin.reason and "'j1'" in kin.reason
        with pytest.raises(ConfigurationError, match="cannot run: joint 'j1' is a JointModelSphericalZYX"):
            frame_kinematics(model, [0], "compiled")


def test_without_numba(monkeypatch):
    """numba absent (its import fails): Pinocchio computes, and asking for the compiled engine says why not."""
    monkeypatch.delenv("PINMOB_KINEMATICS", raising=False)
    monkeypatch.setitem(sys.modules, "numba", None)
    assert not numba_installed()
    kin = assert_matches(pinmob.load("3-PUU").model, engine=None)
    assert kin.engine == "pinocchio" and "numba is not installed" in kin.reason
    with pytest.raises(ConfigurationError, match="numba is not installed"):
        frame_kinematics(pinmob.load("3-PUU").model, [0], "compiled")


def test_bad_engine_and_reference():
    model = pinmob.load("3-PUU").model
    with pytest.raises(ConfigurationError, match="unknown kinematics engine 'fast'; valid: compiled, pinocchio"):
        frame_kinematics(model, [0], "fast")
    with pytest.raises(ConfigurationError, match="unknown Jacobian reference"):
        frame_kinematics(model, [0]).jacobians(np.zeros(model.nq), reference="local")
    with pytest.raises(ConfigurationError, match=r"out must be C-ordered float arrays of shapes \(2, 1, 3, 3\)"):
        frame_kinematics(model, [0]).jacobians(np.zeros((2, model.nq)), out=(np.empty((2, 1, 3, 3)),) * 3)


@needs_numba
def test_compile_cache_outside_the_package():
    """The kernel's numba cache is pinmob's per-user folder, never beside the installed module (site-packages)."""
    from pinmob.jit_cache import cache_dir
    from pinmob.model import kinematics_kernel

    cache = kinematics_kernel.frames_kernel._cache  # numba's FunctionCache
    path = Path(cache._cache_path)
    assert path.is_relative_to(cache_dir())
    assert not path.is_relative_to(Path(kinematics_kernel.__file__).parent)


@pytest.mark.parametrize("engine", ["compiled", "pinocchio"])
@pytest.mark.parametrize("name", ["3-PUU", "6-UPS", "Bennett"])
def test_world_joint_jacobians(name, engine):
    """The whole world joint Jacobian, Pinocchio's data.J after computeJointJacobians, and the frames' placements."""
    if engine == "compiled" and not numba_installed():
        pytest.skip("numba (the fast extra) is not installed")
    model = pinmob.load(name).model
    frames = list(range(model.nframes))
    qs = random_configurations(model, 4)
    full, rot, pos = frame_kinematics(model, frames, engine).world_jacobians(qs)
    t_rot, t_pos, _ = pinocchio_truth(model, qs, frames, pin.WORLD)
    data = model.createData()
    for b, q in enumerate(qs):
        pin.computeJointJacobians(model, data, q)
        np.testing.assert_allclose(full[b], data.J, rtol=0, atol=1e-12 * max(1.0, np.abs(data.J).max()))
    np.testing.assert_allclose(rot, t_rot, rtol=0, atol=1e-12)
    np.testing.assert_allclose(pos, t_pos, rtol=0, atol=1e-12 * max(1.0, np.abs(t_pos).max()))


def test_engine_from_the_environment(monkeypatch):
    model = pinmob.load("3-PUU").model
    monkeypatch.setenv("PINMOB_KINEMATICS", "pinocchio")
    assert frame_kinematics(model, [0]).engine == "pinocchio"
    monkeypatch.setenv("PINMOB_KINEMATICS", "fast")
    with pytest.raises(
        ConfigurationError, match="PINMOB_KINEMATICS='fast' is not a kinematics engine; valid: compiled"
    ):
        frame_kinematics(model, [0])
    if numba_installed():
        monkeypatch.setenv("PINMOB_KINEMATICS", "compiled")
        assert frame_kinematics(model, [0]).engine == "compiled"


@needs_numba
@pytest.mark.parametrize(
    "robot, at, axes",
    [
        ("3-PUU", "generic", [("x", -0.05, 0.05, 5), ("y", -0.05, 0.05, 5)]),
        ("3-RPS", "home", [("roll", -0.2, 0.2, 4), ("pitch", -0.2, 0.2, 4)]),
    ],
)
def test_scan_rows_both_ways(monkeypatch, robot, at, axes):
    """A scan's batched predictor on the compiled kinematics and on Pinocchio's: the same rows (floats to 1e-9)."""
    from pinmob.assembly.batched.batch_solver import PoseProblem
    from pinmob.scan.scan_run import scan_in_process
    from pinmob.scan.scan_spec import grid_spec
    from pinmob.testing import kinematics_calls

    mech = pinmob.load(robot)
    spec = grid_spec(mech, at, axes)
    rows, calls = {}, {}
    for engine in ("compiled", "pinocchio"):
        monkeypatch.setenv("PINMOB_KINEMATICS", engine)
        assert PoseProblem(mech).fast.engine == engine
        rows[engine] = list(scan_in_process(mech, spec))
        calls[engine] = kinematics_calls(lambda: list(scan_in_process(mech, spec)))
    assert calls["compiled"] < calls["pinocchio"] / 2  # the predictor's kinematics left Pinocchio
    assert len(rows["compiled"]) == len(rows["pinocchio"]) == spec.size
    for a, b in zip(rows["compiled"], rows["pinocchio"]):
        assert list(a) == list(b)
        for key in a:
            if isinstance(a[key], float):
                assert a[key] == pytest.approx(b[key], rel=1e-9, abs=1e-9, nan_ok=True), key
            else:
                assert a[key] == b[key], key


@needs_numba
@pytest.mark.parametrize(
    "robot, moved, free", [("3-PUU", [0, 1, 2], ()), ("6-UPS", [0, 1, 2, 3, 4, 5], ()), ("3-RPS", [2, 3, 4], (0, 1, 5))]
)
def test_whole_newton_loop_compiled(robot, moved, free):
    """The batched solver's loop in one compiled call (kinematics, steps, Pinocchio's integrate compiled) lands on
    the configurations of the loop that calls the kernels once per iteration, to the last bit."""
    from pinmob.assembly import PoseProblem, closed_configuration, pose_vector, solve_poses
    from pinmob.scan import platform_pose

    mech = pinmob.load(robot)
    q0 = closed_configuration(mech, "home" if robot != "3-PUU" else "generic")
    rng = np.random.default_rng(3)
    target = pose_vector(platform_pose(mech, q0))
    poses = np.repeat(target[None], 12, axis=0)  # the pose coordinates the platform can move, moved
    scale = np.array([0.02 * mech.length_scale] * 3 + [0.05] * 3)[moved]
    poses[:, moved] += rng.normal(0.0, 1.0, (12, len(moved))) * scale
    seeds = np.repeat(q0[None], 12, axis=0)
    problem = PoseProblem(mech, free)  # the 3-RPS's x, y and yaw follow: unknowns
    assert problem.fast.integrable and problem.kernel is not None
    fused = solve_poses(problem, seeds, poses)
    problem.fast.integrable = False  # the loop of one compiled call per iteration
    try:
        loop = solve_poses(problem, seeds, poses)
    finally:
        problem.fast.integrable = True
    np.testing.assert_array_equal(fused.q, loop.q)
    np.testing.assert_array_equal(fused.converged, loop.converged)
    np.testing.assert_array_equal(fused.jacobians, loop.jacobians)
    assert fused.converged.sum() >= 6  # most of them close: the comparison is of real solves
