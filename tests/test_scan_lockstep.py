"""The lockstep's work on stacks (pinmob.scan.lockstep): the targets as vectors, the secant starts and their check.

A group's samples are assembled step by step, every chunk's next sample at once; the targets are built as
(B, 6) pose-coordinate vectors (``ScanSpec.pose_targets``), not as poses and dicts, and the secant starts and the
off-secant check run over the whole stack (pinmob.assembly.batched.secant; with numba, with the solve in one
compiled call, Predictor.close). Checked here against the targets' own coordinates, against moves made by hand and
the compiled call against numpy's (the rows of whole scans: tests/test_scan_batch.py).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import pinmob
from pinmob.assembly import moved_stack, off_secants
from pinmob.assembly.batched.batch_solver import PoseProblem
from pinmob.assembly.partial_pose import pose_from_vector
from pinmob.assembly.reach import POSE_COORDS, pose_vector
from pinmob.model.joints import linear_velocity_mask
from pinmob.scan import grid_spec, path_spec


def _pose_targets_match(spec, ks):
    """pose_targets(ks) against each target's own pose (a pose) or given coordinates (NaN where following)."""
    got = spec.pose_targets(ks)
    assert got.shape == (len(ks), 6)
    for row, k in zip(got, ks):
        kind, value = spec.target(k)
        assert kind == spec.target_kind
        if kind == "pose":
            want = pose_vector(value)
            assert np.allclose(row[:3], want[:3], atol=1e-15)
            assert np.allclose(pose_from_vector(row).rotation, value.rotation, atol=1e-15)
        else:
            pose, joints = value
            assert not joints
            for i, c in enumerate(POSE_COORDS):
                assert (row[i] == pose[c]) if c in pose else np.isnan(row[i])
    return got


def test_the_targets_as_vectors_are_the_targets_coordinates():
    """A pose grid (the 3-PUU: all six coordinates given), a grid with following coordinates (the 3-RPS over roll
    and pitch: x, y and yaw NaN), a coordinate path and a pose path: the vectors hold the targets' coordinates, the
    grid's values lo + (hi - lo) i / (n - 1) by hand. Fails on the old code: no pose_targets."""
    puu = pinmob.load("3-PUU")
    spec = grid_spec(puu, "generic", [("x", -0.06, 0.06, 3), ("y", -0.04, 0.02, 4)])
    assert spec.target_kind == "pose"
    got = _pose_targets_match(spec, list(range(spec.size)))
    assert got[5, 0] == pytest.approx(0.0) and got[5, 1] == pytest.approx(-0.02)  # sample 5: x step 1, y step 1
    rps = pinmob.load("3-RPS")
    spec = grid_spec(rps, "home", [("roll", -0.2, 0.2, 3), ("pitch", -0.2, 0.2, 3)])
    assert spec.target_kind == "coords"
    got = _pose_targets_match(spec, list(range(spec.size)))
    assert np.isnan(got[:, [0, 1, 5]]).all() and got[7, 3] == 0.2 and got[7, 4] == 0.0
    path = path_spec(rps, "home", "roll=0.1,pitch=-0.1", 5)
    got = _pose_targets_match(path, [0, 2, 4])
    assert got[1, 3] == pytest.approx(0.05) and got[2, 4] == pytest.approx(-0.1)
    ups = pinmob.load("6-UPS")
    _pose_targets_match(path_spec(ups, "home", "0,0,0.4,0,0,2.0944", 7), [0, 3, 6])


def test_the_params_of_many_samples_are_each_samples_params():
    """ScanSpec.params_of (a group's samples at once) gives params(t) of each, the same floats: grids of one, two
    and three coordinates (one of them a single value), fractional samples between a line's, a path's s; a sample
    beyond the grid is refused as by params. Fails on the old code: no params_of."""
    puu = pinmob.load("3-PUU")
    for axes in (
        [("x", -0.06, 0.06, 21), ("y", -0.06, 0.06, 21)],
        [("y", -0.07, 0.05, 13)],
        [("x", -0.06, 0.06, 1), ("y", -0.07, 0.05, 13)],
        [("x", -0.06, 0.06, 3), ("y", -0.06, 0.06, 5), ("z", -0.25, -0.15, 4)],
    ):
        spec = grid_spec(puu, "generic", axes)
        ts = [*range(spec.size), 0.5, spec.size - 1.75]
        assert spec.params_of(ts) == [spec.params(t) for t in ts]
        with pytest.raises(ValueError, match="beyond the grid"):
            spec.params_of([spec.size + 2])
    spec = grid_spec(puu, "generic", [("x", -0.06, 0.06, 3), ("y", -0.06, 0.06, 5)])
    assert spec.params_of([6])[0] == pytest.approx({"grid_x": 0.0, "grid_y": -0.03})  # x step 1 of 2, y 1 of 4
    path = path_spec(puu, "generic", "offset", 7)
    assert path.params_of([0, 3, 6, 2.5]) == [path.params(t) for t in (0, 3, 6, 2.5)]


def test_targets_with_joint_values_as_vectors():
    """A joint grid's targets: no pose coordinate (NaN), its joints' values by hand (lo + (hi - lo) i / (n - 1),
    the held one at its value); a joint path's targets give no pose coordinate either, and its joints' values
    along the path."""
    puu = pinmob.load("3-PUU")
    spec = grid_spec(puu, "generic", [("A_slider", -0.01, 0.01, 3), ("B_slider", 0.0, 0.04, 5)])
    assert spec.target_joints == ("A_slider", "B_slider", "C_slider")
    assert np.isnan(spec.pose_targets([0, 7])).all()
    held = dict(spec.held)["C_slider"]
    np.testing.assert_allclose(spec.joint_targets([0, 7, 14]), [[-0.01, 0.0, held], [0.0, 0.02, held],
                                                                [0.01, 0.04, held]], rtol=0, atol=1e-15)  # fmt: skip
    for k in (0, 7, 14):  # the targets' own joint values, the same floats
        _, (pose, joints) = spec.target(k)
        assert not pose and list(spec.joint_targets([k])[0]) == [joints[n] for n in spec.target_joints]
    joint_path = path_spec(puu, "generic", "A_slider=0.01", 3)  # from generic's A_slider to 0.01, the others held
    names = joint_path.target_joints
    assert "A_slider" in names and names == tuple(joint_path.joints)
    assert np.isnan(joint_path.pose_targets([0, 1, 2])).all()
    a = pinmob.model.joint_values.joint_value(puu.model, pinmob.closed_configuration(puu, "generic"), "A_slider")
    values = joint_path.joint_targets([0, 1, 2])
    np.testing.assert_allclose(values[:, names.index("A_slider")], [a, 0.5 * (a + 0.01), 0.01], rtol=0, atol=1e-15)
    for k in (0, 1, 2):  # the targets' own joint values, the same floats
        kind, joints = joint_path.target(k)
        assert kind == "joints" and list(values[k]) == [joints[n] for n in names]


@pytest.mark.parametrize("vector_space", [True, False])
def test_the_secant_starts_and_their_check_over_a_stack_follow_moves_made_by_hand(vector_space):
    """Per row: the start is the seed moved on by (seed - before), the short way round across the wrap at +-pi;
    off_secants is True exactly where the correction (start to q) is longer than that step (joint metric, slides
    per L), False where it is shorter or where there was no secant (start = seed). The stack's answers are the
    rows' (off_secants of one row); the moves' lengths are the steps off_secants measures against. On q + move and
    on Pinocchio's difference / integrate path."""
    mech = pinmob.load("3-PUU")
    problem = PoseProblem(mech)
    problem.vector_space = vector_space
    rng = np.random.default_rng(3)
    q0 = pinmob.closed_configuration(mech, "generic")
    angle = int(problem.angles[0])
    slide = int(np.flatnonzero(linear_velocity_mask(mech.model))[0])
    n = 6
    seeds = np.tile(q0, (n, 1)) + 0.01 * rng.normal(size=(n, mech.model.nq))
    before = seeds.copy()
    seeds[:, angle], before[:, angle] = -np.pi + 0.01, np.pi - 0.03  # 0.04 rad on across the wrap at +-pi
    before[:, slide] -= 0.03 * mech.length_scale  # 0.03 L behind: the step's length is 0.05
    has = np.array([True, True, True, True, False, True])
    starts, step = moved_stack(problem, before, seeds, has, seeds)
    want = seeds.copy()
    want[has, angle] = -np.pi + 0.05
    want[has, slide] += 0.03 * mech.length_scale
    assert np.allclose(starts, want, atol=1e-12)
    assert np.allclose(step, np.where(has, 0.05, 0.0), atol=1e-12)  # slide 0.03 and angle 0.04 (joint metric)
    # corrections from the start: 0.06 (longer than the step, 0.05) or 0.04 (shorter), along the slide
    qs = starts.copy()
    longer = np.array([True, False, True, False, True, False])
    qs[:, slide] += np.where(longer, 0.06, 0.04) * mech.length_scale
    expected = longer & has  # no secant (row 4): never off it
    assert off_secants(problem, seeds, starts, qs).tolist() == expected.tolist()
    assert [
        off_secants(problem, s[None], t[None], q[None])[0] for s, t, q in zip(seeds, starts, qs)
    ] == expected.tolist()


@pytest.mark.parametrize(("name", "at", "axes"), [
    ("3-PUU", "generic", [("x", -0.06, 0.06, 4), ("y", -0.06, 0.06, 4)]),
    ("3-RPS", "home", [("roll", -0.2, 0.2, 4), ("pitch", -0.2, 0.2, 4)]),
])  # fmt: skip
def test_the_predictors_kinematics_are_pinocchios_at_the_closed_configurations(name, at, axes):
    """The analysis of a predicted sample reads the kinematics the predictor computed at its last iterate
    (Predictor.close) instead of computing them again: they are Pinocchio's at the returned, angle-wrapped
    configuration (computed here), and the batch rows made from them are the rows made without them."""
    import pinocchio as pin

    from pinmob.scan.batch_rows import analyse
    from pinmob.scan.predictor import Predictor

    mech = pinmob.load(name)
    spec = grid_spec(mech, at, axes)
    predictor = Predictor(mech, spec)
    ks = list(range(spec.size))
    seeds = np.array([spec.q_ref] * len(ks))
    closed = predictor.close(spec.pose_targets(ks), seeds, spec.target_kind)
    assert closed.converged.all()
    data = mech.model.createData()
    for q, jac, platform in zip(closed.q, closed.jacobians, closed.platform):
        assert np.allclose(pin.computeJointJacobians(mech.model, data, q), jac, atol=1e-12)
        assert np.allclose(pin.updateFramePlacement(mech.model, data, mech.platform_id).homogeneous, platform,
                           atol=1e-12)  # fmt: skip
    qs = list(closed.q)
    known = list(zip(closed.jacobians, closed.platform))
    fresh, read = (
        analyse(mech, qs, spec.rtol, spec.generic_rank),
        analyse(mech, qs, spec.rtol, spec.generic_rank, known),
    )
    assert all(a is not None for a in fresh) and len(read) == len(fresh)
    for a, b in zip(fresh, read):
        assert a is not None and b is not None and list(a[0]) == list(b[0])
        for key, value in a[0].items():
            if isinstance(value, float):
                assert value == pytest.approx(b[0][key], abs=1e-12, nan_ok=True), key
            else:
                assert value == b[0][key], key


@pytest.mark.parametrize(
    ("name", "at", "axes"),
    [
        ("6-UPS", "home", [("x", -0.05, 0.05, 41), ("y", -0.05, 0.05, 41)]),
        ("3-PUU", "generic", [("A_slider", -0.2, 0.2, 41), ("B_slider", -0.2, 0.2, 41)]),
    ],  # fmt: skip
)
def test_the_walks_turns_are_closed_across_the_lines(monkeypatch, name, at, axes):
    """Lines of two chunks (a grid line's chunks cut to 32 samples): the walk turns at every line; from the third
    line on, the predictor closes the turns.

    The seeds are the single-sample walk's (``engine="single"``: every waypoint by the single-sample solver from
    the one before), on the same branch, and the batched walk calls that solver at most on the approach's first
    two waypoints and on the first two lines' (five each; along the 3-PUU's A_slider = -0.2 m edge the predictor
    closes none of them from their secant), 83 times before the turns were closed across the lines.
    """
    from dataclasses import replace

    import pinmob.scan.scan_spec as scan_spec
    import pinmob.scan.seeding_walk as walk

    monkeypatch.setattr(scan_spec, "LINE_CHUNK", 32)  # 41-sample lines in two chunks (one chunk each by default)
    mech = pinmob.load(name)
    spec = grid_spec(mech, at, axes)
    solves = []
    solve = walk.chunk.assemble_target

    def counted(*args, **kwargs):
        solves.append(args[1])
        return solve(*args, **kwargs)

    reference = list(walk.chunk_seeds(mech, replace(spec, engine="single")))
    monkeypatch.setattr(walk.chunk, "assemble_target", counted)
    walked = list(walk.chunk_seeds(mech, spec))
    assert [(a, b) for a, b, _ in walked] == [(a, b) for a, b, _ in reference]
    assert len(walked) == 2 * 41
    assert len(solves) <= 2 + 2 * 5, len(solves)
    col = np.where(linear_velocity_mask(mech.model), mech.length_scale, 1.0)
    for (_, _, q), (_, _, want) in zip(walked, reference):
        assert np.max(np.abs(pin.difference(mech.model, want, q) / col)) < 1e-6


def _continuous_3rps(folder):
    """The 3-RPS with its first limb's revolutes and one spherical revolute of each other limb unbounded
    (URDF ``continuous``: Pinocchio's (cos, sin) joints, whose difference and integrate are not plain arithmetic)."""
    toml = pinmob.builtin_models()["3-RPS"]
    urdf = (toml.parent / "3rps.urdf").read_text()
    for joint in ("A_r", "A_sa", "A_sb", "A_sc", "B_sc", "C_sb"):
        urdf = urdf.replace(f'<joint name="{joint}" type="revolute">', f'<joint name="{joint}" type="continuous">', 1)
    (folder / "3rps_cont.urdf").write_text(urdf)
    text = toml.read_text().replace('"3rps.urdf"', '"3rps_cont.urdf"').replace('name = "3-RPS"', 'name = "3-RPS-cont"')
    (folder / "3rps_cont.toml").write_text(text)
    return pinmob.load(folder / "3rps_cont.toml")


@pytest.mark.needs_numba
def test_the_compiled_close_of_unbounded_joints_is_the_numpy_one_to_round_off(monkeypatch, tmp_path):
    """Off a vector space (unbounded revolutes: the moves are Pinocchio's difference and integrate, compiled, equal
    to 1e-13 in tests/test_compiled_kinematics.py), Predictor.close with numba against numpy's moves and checks
    around the compiled solve: the same convergence and the same rows off their moves, configurations within
    1e-12 (not to the last bit: the compiled difference and integrate round otherwise)."""
    import warnings

    import pinocchio as pin

    import pinmob.scan.predictor as predictor_module
    from pinmob.scan.predictor import Predictor

    mech = _continuous_3rps(tmp_path)
    spec = grid_spec(mech, "home", [("roll", -0.2, 0.2, 5), ("pitch", -0.2, 0.2, 5)])
    assert not Predictor(mech, spec).problem.vector_space
    ks = list(range(1, 5)) + list(range(6, 10))
    rng = np.random.default_rng(11)
    q0 = np.array(spec.q_ref, float)
    seeds = np.array([pin.integrate(mech.model, q0, 1e-3 * rng.normal(size=mech.model.nv)) for _ in ks])
    behind = np.array([pin.integrate(mech.model, q, -2e-3 * rng.normal(size=mech.model.nv)) for q in seeds])
    moves = (behind, seeds, np.arange(len(ks)) % 3 != 1)
    poses = spec.pose_targets(ks)

    def close(ratio: float, redo: bool):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return Predictor(mech, spec).close(poses.copy(), seeds.copy(), spec.target_kind, moves=moves,
                                               ratio=ratio, redo=redo)  # fmt: skip

    runs = {}
    for path in ("compiled", "numpy"):
        if path == "numpy":
            monkeypatch.setattr(predictor_module, "close_moved", lambda *args: None)
        runs[path] = [close(1.0, True), close(1e-6, True), close(1e-6, False)]
    for compiled, plain in zip(*runs.values()):
        assert compiled.converged.tolist() == plain.converged.tolist()
        np.testing.assert_allclose(compiled.q, plain.q, rtol=0, atol=1e-12)
    assert runs["compiled"][0].converged.all() and not runs["compiled"][2].converged[moves[2]].any()


def _line_stack(mech, spec, ks):
    """Seeds (the reference, each row nudged), moves from a point behind them, and the targets of samples ks."""
    rng = np.random.default_rng(11)
    q0 = np.array(spec.q_ref, float)
    seeds = np.tile(q0, (len(ks), 1))
    unit = np.where(linear_velocity_mask(mech.model), mech.length_scale, 1.0)
    seeds += 1e-3 * rng.normal(size=seeds.shape) * unit  # the same joints (a vector space): q and v alike
    behind = seeds - 2e-3 * rng.normal(size=seeds.shape) * unit
    has = np.arange(len(ks)) % 3 != 1
    joints = spec.joint_targets(ks) if spec.target_joints else None
    return seeds, (behind, seeds, has), spec.pose_targets(ks), joints


@pytest.mark.needs_numba
@pytest.mark.parametrize(("name", "at", "axes", "shifted"), [
    ("3-PUU", "generic", [("x", -0.06, 0.06, 5), ("y", -0.06, 0.06, 5)], False),  # a pose: all six given
    ("3-RPS", "home", [("roll", -0.2, 0.2, 5), ("pitch", -0.2, 0.2, 5)], False),  # x, y, yaw follow
    ("3-PUU", "generic", [("A_slider", -0.2, 0.2, 5), ("B_slider", -0.2, 0.2, 5)], False),  # joints held
    ("3-PUU", "generic", [("x", -0.06, 0.06, 5), ("y", -0.06, 0.06, 5)], True),  # angles left to wrap_angles
])  # fmt: skip
@pytest.mark.parametrize("vector_space", [True, False])
def test_the_compiled_close_is_the_numpy_moves_solve_finish_and_check(monkeypatch, name, at, axes, shifted,
                                                                     vector_space):  # fmt: skip
    """Predictor.close with numba (pinmob.assembly.close_moved: the moves, the solve, the angles wrapped and the
    check of each correction in one compiled call) against the same method on numpy's moves and checks around
    the compiled solve (close_moved made to decline): the same configurations, convergence and kinematics to the
    last bit, the same rows off their moves, closed again from their seeds (redo) or left unclosed. With the
    targets' joints held (the motor grid), following coordinates (the 3-RPS), on Pinocchio's difference and
    integrate path (vector_space False), and with an angle whose limits lie past pi (``shifted``: every closed row
    is finished again by wrap_angles and its correction measured again)."""
    import warnings

    import pinmob.scan.predictor as predictor_module
    from pinmob.scan.predictor import Predictor

    mech = pinmob.load(name)
    if shifted:  # the first angle's limits a turn up around its value: wrapped into (-pi, pi] it is outside them
        model = mech.model
        angle = int(PoseProblem(pinmob.load(name)).angles[0])  # (its shape is kept per mechanism)
        value = float(pinmob.closed_configuration(mech, at)[angle])
        lower, upper = model.lowerPositionLimit.copy(), model.upperPositionLimit.copy()
        lower[angle], upper[angle] = value + 2 * np.pi - 1.0, value + 2 * np.pi + 1.0
        model.lowerPositionLimit, model.upperPositionLimit = lower, upper
    spec = grid_spec(mech, at, axes)
    ks = list(range(1, 5)) + list(range(6, 10))
    seeds, moves, poses, joints = _line_stack(mech, spec, ks)
    kind = spec.target_kind

    def close(ratio: float, redo: bool):
        predictor = Predictor(mech, spec)
        predictor.problem.vector_space = vector_space
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # joints outside their limits: the same warnings on both paths
            return predictor.close(poses.copy(), seeds.copy(), kind, joints=joints, moves=moves, ratio=ratio, redo=redo)

    runs = {}
    for path in ("compiled", "numpy"):
        if path == "numpy":
            monkeypatch.setattr(predictor_module, "close_moved", lambda *args: None)
        runs[path] = [close(1.0, True), close(1e-6, True), close(1e-6, False), close(1.0, False)]
    for compiled, plain in zip(*runs.values()):
        assert compiled.converged.tolist() == plain.converged.tolist()
        assert np.array_equal(compiled.q, plain.q)
        assert np.array_equal(compiled.jacobians, plain.jacobians, equal_nan=True)
        assert np.array_equal(compiled.platform, plain.platform, equal_nan=True)
    moved = moves[2]
    full, off_all, kept, _ = runs["compiled"]
    assert full.converged.all() and off_all.converged.all()  # every row closes, from its move or from its seed
    assert not kept.converged[moved].any() and kept.converged[~moved].all()  # every move is off at 1e-6
    if shifted:  # wrap_angles kept the angle inside its limits, a turn up
        assert (full.q[:, angle] > np.pi).all()
