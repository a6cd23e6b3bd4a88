"""Scan grids in the coordinates a designer thinks in: pose coordinates with the parasitic ones following, joints.

Each test compares pinmob's rows with an independent computation written here (plain Pinocchio and
numpy/scipy), not with pinmob's own output.
"""

from __future__ import annotations

import csv
import shutil
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from scipy.optimize import least_squares

import pinmob
from pinmob.assembly.named_assembly import closed_configuration
from pinmob.cli import main
from pinmob.exceptions import ConfigurationError
from pinmob.scan import grid_spec, scan

ROOT = Path(__file__).resolve().parent.parent
POSE = ("x", "y", "z", "roll", "pitch", "yaw")


def _rows(path: Path) -> list[dict[str, str]]:
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def _q_of(mech: pinmob.Mechanism, row: dict) -> np.ndarray:
    """The configuration a row gives (every joint of these models has one degree: q from the q_<name> columns)."""
    model = mech.model
    q = np.zeros(model.nq)
    for j in range(1, model.njoints):
        q[model.joints[j].idx_q] = float(row[f"q_{model.names[j]}"])
    return q


def _tip_pose_errors(mech: pinmob.Mechanism, data: pin.Data, target: pin.SE3) -> np.ndarray:
    """Every limb tip's and the platform frame's pose error ``log6(target^-1 oMf)`` [m / L, rad], stacked."""
    frames = [mech.platform_id] + [b.tip_id for b in mech.limbs]
    errs = [pin.log6(target.actInv(data.oMf[f])).vector for f in frames]
    return np.concatenate([np.concatenate([e[:3] / mech.length_scale, e[3:]]) for e in errs])


def _rps_solve(mech: pinmob.Mechanism, z0: float, roll: float, pitch: float, u: np.ndarray) -> np.ndarray:
    """(q, x, y, yaw) with every limb tip at ``SE3(rpy(roll, pitch, yaw), (x, y, z0))``: scipy's LM from ``u``."""
    data = mech.model.createData()

    def residual(u: np.ndarray) -> np.ndarray:
        q, (x, y, yaw) = u[:-3], u[-3:]
        pin.framesForwardKinematics(mech.model, data, q)
        return _tip_pose_errors(mech, data, pin.SE3(pin.rpy.rpyToMatrix(roll, pitch, yaw), np.array([x, y, z0])))

    sol = least_squares(residual, u, method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    assert np.max(np.abs(sol.fun)) < 1e-10
    return sol.x


def test_3rps_roll_pitch_grid_assembles_every_sample_with_its_parasitic_motion(tmp_path, capsys):
    """The 3-RPS over roll x pitch at home: z held, x, y and yaw follow (before: 80 of 81 samples unreachable).

    Independent solve: unknowns (q, x, y, yaw), z held at home's height, roll and pitch at the grid's values;
    scipy's Levenberg-Marquardt on every limb tip's pose error against ``SE3(rpy(roll, pitch, yaw), (x, y, z))``,
    warm-started from the previous sample of the row (a row starts from the previous row's first sample).
    """
    out = tmp_path / "g.csv"
    args = ["scan", "3-RPS", "--grid", "roll:-0.2:0.2:9", "pitch:-0.2:0.2:9", "--at", "home", "--no-progress"]
    assert main([*args, "--csv", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "held: z; following the mechanism: x, y, yaw" in printed and "81 x " not in printed  # 72 + 9
    rows = [r for r in _rows(out) if r["refined"] == "False"]
    assert len(rows) == 81 and all(r["reachable"] == "True" for r in rows)
    mech = pinmob.load("3-RPS")
    model, data = mech.model, mech.model.createData()
    home = closed_configuration(mech, "home")
    pin.framesForwardKinematics(model, data, home)
    z0 = data.oMf[mech.platform_id].translation[2]
    u_row = np.concatenate([home, np.zeros(3)])
    for i, roll in enumerate(np.linspace(-0.2, 0.2, 9)):
        u = u_row
        for j, pitch in enumerate(np.linspace(-0.2, 0.2, 9)):
            u = _rps_solve(mech, z0, roll, pitch, u)
            u_row = u if j == 0 else u_row
            row = rows[9 * i + j]
            assert float(row["grid_roll"]) == pytest.approx(roll, abs=1e-15)
            assert float(row["grid_pitch"]) == pytest.approx(pitch, abs=1e-15)
            got = np.array([float(row[c]) for c in POSE])
            want = np.array([u[-3], u[-2], z0, roll, pitch, u[-1]])
            np.testing.assert_allclose(got, want, atol=1e-9)
            legs = [float(row[f"q_{n}_leg"]) for n in "ABC"]
            np.testing.assert_allclose(legs, [u[model.joints[model.getJointId(f"{n}_leg")].idx_q] for n in "ABC"],
                                       atol=1e-9)  # fmt: skip
            assert row["dof"] == "3"
    corner = rows[-1]  # roll = pitch = 0.2: the parasitic turn and shift of the independent solve
    assert float(corner["yaw"]) == pytest.approx(0.0201, abs=1e-4)
    assert float(corner["y"]) == pytest.approx(-2.4e-3, abs=1e-4)


def test_full_mobility_grid_holds_the_four_other_pose_coordinates():
    """The 6-UPS (6 DoF) over x, y: nothing follows; every sample has z, roll, pitch, yaw of the reference."""
    mech = pinmob.load("6-UPS")
    spec = grid_spec(mech, "home", [("x", -0.03, 0.03, 3), ("y", -0.03, 0.03, 3)])
    assert [c for c, _ in spec.held] == ["z", "roll", "pitch", "yaw"] and spec.following == ()
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, spec.q_ref)
    ref = data.oMf[mech.platform_id]
    for k in range(spec.size):  # each target is the full pose a grid always asked for: the same assembly as before
        kind, target = spec.target(k)
        x, y = -0.03 + 0.03 * (k // 3), -0.03 + 0.03 * (k % 3)
        want = pin.SE3(ref.rotation, np.array([x, y, ref.translation[2]]))
        assert kind == "pose" and np.allclose(target.homogeneous, want.homogeneous, atol=1e-12)
    for row in scan(mech, spec):
        assert row["reachable"]
        np.testing.assert_allclose([row["z"], row["roll"], row["pitch"], row["yaw"]],
                                   [ref.translation[2], *pin.rpy.matrixToRpy(ref.rotation)], atol=1e-12)  # fmt: skip


def test_constant_coordinates_reads_the_generic_states_only_while_a_coordinate_may_be_constant(monkeypatch):
    """The 3-PUU's rotations (a translational platform) move at no configuration: constant, found at the reference
    and at every generic state. The 3-RPS's x, y and yaw follow its roll and pitch (parasitic motions): at the
    symmetric 'home' they are stationary to first order (their rates vanish), at the first generic state they
    move, so none of the other states is read (each costs a closed chain's null space); at 'generic' they move
    already, and no generic state is made or read."""
    import pinmob.scan.coordinates as coordinates
    from pinmob.analysis import Configuration, generic_states

    rates = coordinates.coordinate_rates
    read: list[Configuration] = []

    def counted(conf, names, rtol=coordinates.RTOL):
        read.append(conf)
        return rates(conf, names, rtol)

    monkeypatch.setattr(coordinates, "coordinate_rates", counted)
    puu = pinmob.load("3-PUU")
    conf = Configuration(puu, closed_configuration(puu, "generic"))
    assert coordinates.constant_coordinates(puu, conf, ["roll", "pitch", "yaw"]) == ["roll", "pitch", "yaw"]
    assert len(read) == 1 + len(generic_states(puu))
    read.clear()
    rps = pinmob.load("3-RPS")
    conf = Configuration(rps, closed_configuration(rps, "home"))
    assert coordinates.constant_coordinates(rps, conf, ["x", "y", "yaw"]) == []
    assert np.linalg.norm(rates(conf, ["x", "y", "yaw"]), axis=1).max() < 1e-12  # stationary at 'home'
    assert read == [conf, generic_states(rps)[0]] and len(generic_states(rps)) > 2
    read.clear()
    rps = pinmob.load("3-RPS")  # a new mechanism: no generic state made yet
    conf = Configuration(rps, closed_configuration(rps, "generic"))

    def none(*args, **kwargs):
        raise AssertionError("the generic states are not needed")

    monkeypatch.setattr(coordinates, "generic_states", none)
    assert np.linalg.norm(rates(conf, ["x", "y", "yaw"]), axis=1).min() > 0.01  # each moves at 'generic'
    assert coordinates.constant_coordinates(rps, conf, ["x", "y", "yaw"]) == [] and read == [conf]


def test_a_grid_over_coordinates_the_platform_cannot_move_says_which_are_free():
    mech = pinmob.load("3-RPS")
    with pytest.raises(ConfigurationError) as err:
        grid_spec(mech, "home", [("x", -0.01, 0.01, 3), ("y", -0.01, 0.01, 3)])
    message = str(err.value)
    assert "cannot vary independently" in message and "3 DoF" in message and "z, roll, pitch" in message


def test_an_unknown_grid_coordinate_lists_pose_coordinates_and_joints(capsys):
    assert main(["scan", "Delta", "--grid", "A_mot:-1:1:3", "B_motor:-1:1:3"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "'A_mot'" in err and "roll" in err and "'A_motor'" in err and "'C_motor'" in err


def _closure_check(mech: pinmob.Mechanism, q: np.ndarray, pairs: list[tuple[str, str]]) -> float:
    """Largest closure residual at q [m, rad]: every limb tip against the platform frame, and the ball closures."""
    model, data = mech.model, mech.model.createData()
    pin.framesForwardKinematics(model, data, q)
    platform = data.oMf[mech.platform_id]
    worst = max(np.max(np.abs(pin.log6(platform.actInv(data.oMf[b.tip_id])).vector)) for b in mech.limbs)
    for a, b in pairs:
        pa, pb = (data.oMf[model.getFrameId(f)].translation for f in (a, b))
        worst = max(worst, float(np.max(np.abs(pa - pb))))
    return float(worst)


def _platform_dof(mech: pinmob.Mechanism, q: np.ndarray, pairs: list[tuple[str, str]]) -> tuple[int, float]:
    """The platform's DoF by plain SVDs: rank of ``J_platform null(K)``, and the gap ratio of that rank decision.

    K stacks every limb tip's world twist minus the platform's, and each ball closure's point velocity difference.
    """
    model, data = mech.model, mech.model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)

    def jac(frame: int, ref: pin.ReferenceFrame) -> np.ndarray:
        return pin.getFrameJacobian(model, data, frame, ref)

    jp = jac(mech.platform_id, pin.WORLD)
    rows = [jac(b.tip_id, pin.WORLD) - jp for b in mech.limbs]
    for a, b in pairs:
        ia, ib = model.getFrameId(a), model.getFrameId(b)
        rows.append(jac(ia, pin.LOCAL_WORLD_ALIGNED)[:3] - jac(ib, pin.LOCAL_WORLD_ALIGNED)[:3])
    k = np.vstack(rows)
    _, s, vt = np.linalg.svd(k)
    null = vt[int(np.sum(s > 1e-9 * s[0])) :].T
    sp = np.linalg.svd(jac(mech.platform_id, pin.LOCAL_WORLD_ALIGNED) @ null, compute_uv=False)
    dof = int(np.sum(sp > 1e-7 * sp[0]))
    return dof, float(sp[dof] / sp[dof - 1]) if dof < sp.size else 0.0


DELTA_BALLS = [(f"{n}_b_pf", f"{n}_b_end") for n in "ABC"]


@pytest.mark.parametrize(
    ("model", "axes", "pairs", "dof", "held"),
    [
        ("Delta", ["A_motor:-0.3:0.3:4", "B_motor:-0.3:0.3:4"], DELTA_BALLS, 3, ["C_motor"]),
        ("Delta", ["A_motor:-0.2:0.2:3", "B_motor:-0.2:0.2:3", "C_motor:-0.2:0.2:3"], DELTA_BALLS, 3, []),
        ("five-bar", ["A_r1:-0.2:0.2:5", "B_r1:-0.2:0.2:5"], [], 2, []),
    ],
    ids=["delta-2-motors", "delta-3-motors", "five-bar"],
)
def test_joint_grid_in_the_cli_holds_the_grid_and_closes(model, axes, pairs, dof, held, tmp_path, capsys):
    """Each sample's gridded joints equal the grid, its loops close (Pinocchio), its DoF is right (plain SVD)."""
    out = tmp_path / "g.csv"
    assert main(["scan", model, "--grid", *axes, "--csv", str(out), "--no-progress"]) == 0
    printed = capsys.readouterr().out
    assert (f"held: {', '.join(held)}" in printed) == bool(held)
    mech = pinmob.load(model)
    rows = [r for r in _rows(out) if r["refined"] == "False"]
    grids = [(a.split(":")[0], np.linspace(float(a.split(":")[1]), float(a.split(":")[2]), int(a.split(":")[3])))
             for a in axes]  # fmt: skip
    assert len(rows) == int(np.prod([g.size for _, g in grids]))
    at = closed_configuration(mech, next(iter(mech.configurations)))
    for k, row in enumerate(rows):
        assert row["reachable"] == "True", row["reason"]
        index = np.unravel_index(k, [g.size for _, g in grids])
        for (name, values), i in zip(grids, index):
            assert float(row[f"grid_{name}"]) == pytest.approx(values[i], abs=1e-15)
            assert float(row[f"q_{name}"]) == pytest.approx(values[i], abs=1e-12)  # held exactly
        q = _q_of(mech, row)
        for name in held:  # held at --at
            assert q[mech.model.joints[mech.model.getJointId(name)].idx_q] == pytest.approx(
                at[mech.model.joints[mech.model.getJointId(name)].idx_q], abs=1e-9
            )
        assert _closure_check(mech, q, pairs) < 1e-9
        platform_dof, gap = _platform_dof(mech, q, pairs)
        assert gap < 1e-4  # a clear rank decision
        assert int(row["dof"]) == platform_dof == dof


def _template(tmp_path: Path, model: str) -> None:
    """A template of a built-in model: its file with the length scale a placeholder (every design the same robot)."""
    stem = {"Delta": "delta", "five-bar": "five_bar"}[model]
    shutil.copy(ROOT / "models" / f"{stem}.urdf", tmp_path / f"{stem}.urdf")
    text = (ROOT / "models" / f"{stem}.toml").read_text().replace("name = ", "length_scale = {L}\nname = ", 1)
    (tmp_path / "robot.toml").write_text(text)


@pytest.mark.parametrize(
    ("model", "grid", "pairs", "dof"),
    [
        ("Delta", ["A_motor:-0.2:0.2:3", "B_motor:-0.2:0.2:3"], DELTA_BALLS, 3),
        ("five-bar", ["A_r1:-0.2:0.2:3", "B_r1:-0.2:0.2:3"], [], 2),
    ],
    ids=["delta", "five-bar"],
)
def test_joint_grid_in_a_sweep_spec(model, grid, pairs, dof, tmp_path):
    """A sweep spec's scan.grid over motors: records of every sample, and the design's rows hold the grid and close."""
    _template(tmp_path, model)
    axes = ", ".join(f'"{a}"' for a in grid)
    (tmp_path / "s.toml").write_text(
        f'template = "robot.toml"\n[design]\nmethod = "table"\nrows = [{{L = 0.3}}, {{L = 0.5}}]\n'
        f"[scan]\ngrid = [{axes}]\n"
    )
    records = list(pinmob.sweep(tmp_path / "s.toml"))
    assert [r["status"] for r in records] == ["ok", "ok"], [r["reason"] for r in records]
    assert all(r["samples"] == 9 and r["assembled"] == 1.0 and r["dof"] == dof for r in records)
    spec = pinmob.load_spec(tmp_path / "s.toml")
    mech = spec.source.mechanism(spec.values(0), tmp_path / "design")
    rows = [r for r in scan(mech, spec.scan.spec(mech)) if not r["refined"]]
    names = [a.split(":")[0] for a in grid]
    values = np.linspace(-float(grid[0].split(":")[2]), float(grid[0].split(":")[2]), 3)
    for k, row in enumerate(rows):
        for name, i in zip(names, np.unravel_index(k, (3, 3))):
            assert row[f"q_{name}"] == pytest.approx(values[i], abs=1e-12)
        q = _q_of(mech, row)
        assert _closure_check(mech, q, pairs) < 1e-9
        assert row["dof"] == _platform_dof(mech, q, pairs)[0] == dof


def test_a_sweep_spec_takes_joint_values_as_path_ends(tmp_path):
    """A path between joint values (before: refused as neither a configuration nor a pose)."""
    _template(tmp_path, "five-bar")
    (tmp_path / "s.toml").write_text(
        'template = "robot.toml"\n[design]\nmethod = "table"\nrows = [{L = 0.3}]\n'
        '[scan]\nfrom = "A_r1=0,B_r1=0"\nto = "A_r1=-0.3,B_r1=0.3"\nsamples = 4\n'
    )
    (record,) = list(pinmob.sweep(tmp_path / "s.toml"))
    assert record["status"] == "ok" and record["samples"] == 4 and record["assembled"] == 1.0


def test_a_sweep_spec_refuses_an_unknown_grid_joint(tmp_path):
    _template(tmp_path, "five-bar")
    (tmp_path / "s.toml").write_text(
        'template = "robot.toml"\n[design]\nmethod = "table"\nrows = [{L = 0.3}]\n'
        '[scan]\ngrid = ["A_r9:-0.3:0.3:3", "B_r1:-0.3:0.3:3"]\n'
    )
    with pytest.raises(ConfigurationError) as err:
        pinmob.load_spec(tmp_path / "s.toml")
    assert "'A_r9'" in str(err.value) and "'A_r1'" in str(err.value) and "pitch" in str(err.value)


def test_a_delta_motor_grid_across_its_workspace_edge_keeps_its_parallelograms(tmp_path):
    """Over three motors in [-0.5, 0.5] (a corner is out of reach) every assembled sample keeps both rods of each
    parallelogram parallel and pointing the same way (plain Pinocchio placements), and is 3T.

    Before the predicted warm start, the walk's 1-rad jumps in the motors landed 89 of 125 samples on the
    anti-parallelogram branch (3H).
    """
    mech = pinmob.load("Delta")
    spec = grid_spec(mech, "generic", [(f"{n}_motor", -0.5, 0.5, 5) for n in "ABC"])
    rows = [r for r in scan(mech, spec) if not r["refined"]]
    assembled = [r for r in rows if r["reachable"]]
    assert len(rows) == 125 and len(assembled) >= 120
    model, data = mech.model, mech.model.createData()
    for row in assembled:
        pin.forwardKinematics(model, data, _q_of(mech, row))
        pin.updateFramePlacements(model, data)
        for n in "ABC":
            top_a, bot_a, top_b = (
                data.oMi[model.getJointId(f"{n}_{j}")].translation for j in ("a_topa", "a_bota", "b_topa")
            )
            end_b = data.oMf[model.getFrameId(f"{n}_b_end")].translation
            rod_a, rod_b = bot_a - top_a, end_b - top_b
            assert np.linalg.norm(np.cross(rod_a, rod_b)) < 1e-9 and rod_a @ rod_b > 0
        assert (row["dof"], row["motion_type"]) == (3, "3T")
    unreachable = [r for r in rows if not r["reachable"]]
    assert all("no convergence" in r["reason"] and "open by" in r["reason"] for r in unreachable)


def test_a_three_coordinate_pose_grid_and_an_unreachable_sample_says_why():
    """The 3-PUU (3T) over x, y and z: its rotations, which no motion changes, are held; a far sample says
    which coordinates it missed."""
    mech = pinmob.load("3-PUU")
    spec = grid_spec(mech, "generic", [("x", -0.02, 0.02, 3), ("y", -0.02, 0.02, 3), ("z", -0.02, 0.0, 2)])
    assert [c for c, _ in spec.held] == ["roll", "pitch", "yaw"] and spec.following == () and spec.size == 18
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, spec.q_ref)
    ref = data.oMf[mech.platform_id]
    rows = [r for r in scan(mech, spec) if not r["refined"]]
    for k, row in enumerate(rows):
        i, j, m = np.unravel_index(k, (3, 3, 2))
        want = [-0.02 + 0.02 * i, -0.02 + 0.02 * j, -0.02 + 0.02 * m]
        assert row["reachable"] and row["dof"] == 3
        np.testing.assert_allclose([row["grid_x"], row["grid_y"], row["grid_z"]], want, atol=1e-15)
        np.testing.assert_allclose([row["x"], row["y"], row["z"]], want, atol=1e-9)
        np.testing.assert_allclose(
            [row["roll"], row["pitch"], row["yaw"]], pin.rpy.matrixToRpy(ref.rotation), atol=1e-9
        )
    far = grid_spec(mech, "generic", [("x", 0.5, 0.5, 1)])  # half a metre off: out of reach
    (row,) = list(scan(mech, far))
    assert not row["reachable"] and row["reason"].startswith("no convergence")
    assert "platform pose off by" in row["reason"] and "limb " in row["reason"]


def test_an_unreachable_coordinate_target_names_the_coordinates_it_missed():
    """One solver iteration from home cannot reach roll = pitch = 0.2: the reason names roll and pitch, by how much."""
    from pinmob.assembly.partial_pose import assemble_coordinates
    from pinmob.exceptions import ClosureError
    from pinmob.scan.unreachable import unreachable_reason

    mech = pinmob.load("3-RPS")
    with pytest.raises(ClosureError) as err:
        assemble_coordinates(
            mech, {"z": 0.3, "roll": 0.2, "pitch": 0.2}, {}, closed_configuration(mech, "home"), max_iter=1
        )
    misses = err.value.residuals
    assert misses["coordinate roll"][1] > 1e-3 and misses["coordinate pitch"][1] > 1e-3
    reason = unreachable_reason(err.value, mech)
    assert "roll off by" in reason or "pitch off by" in reason


def test_a_joint_grid_map_labels_its_axes_with_the_joints_and_their_units(tmp_path, capsys):
    from pinmob.scan.coordinates import coordinate_unit
    from pinmob.scan.results.output import header, read_columns
    from pinmob.scan.results.workspace_map import MAP_COLUMNS, map_figure

    out = tmp_path / "g.csv"
    args = ["scan", "3-RPS", "--grid", "A_leg:-0.02:0.02:3", "B_leg:-0.02:0.02:3", "--no-progress"]
    assert main([*args, "--csv", str(out), "--plot", str(tmp_path / "g.png")]) == 0
    capsys.readouterr()
    keys = [k for k in header(out) if k.startswith("grid_")]
    mech = pinmob.load("3-RPS")
    units = {k[5:]: coordinate_unit(mech, k[5:]) for k in keys}  # what the CLI passes to the map
    assert (units, coordinate_unit(mech, "A_r"), coordinate_unit(mech, "yaw")) == (
        {"A_leg": "m", "B_leg": "m"},
        "rad",
        "rad",
    )
    fig = map_figure(read_columns(out, keys + MAP_COLUMNS), keys, units=units)
    assert (fig.axes[0].get_xlabel(), fig.axes[0].get_ylabel()) == ("joint A_leg [m]", "joint B_leg [m]")
    three = ["scan", "3-RPS", "--grid", "A_leg:-0.02:0.02:3", "B_leg:-0.02:0.02:3", "C_leg:0:0:1"]
    assert main([*three, "--plot", str(tmp_path / "h.png")]) == 2
    assert "--plot maps a grid over two coordinates" in capsys.readouterr().err


def test_a_coordinate_path_lets_the_parasitic_coordinates_follow(tmp_path, capsys):
    """``--from home --to roll=0.2,pitch=0.2``: a path in roll and pitch, z held, x, y, yaw as scipy finds them."""
    out = tmp_path / "p.csv"
    assert main(["scan", "3-RPS", "--from", "home", "--to", "roll=0.2,pitch=0.2", "-n", "5", "--csv", str(out)]) == 0
    assert "coordinate (roll, pitch) path" in capsys.readouterr().out
    mech = pinmob.load("3-RPS")
    data = mech.model.createData()
    home = closed_configuration(mech, "home")
    pin.framesForwardKinematics(mech.model, data, home)
    z0 = data.oMf[mech.platform_id].translation[2]
    u = np.concatenate([home, np.zeros(3)])
    rows = [r for r in _rows(out) if r["refined"] == "False"]
    assert len(rows) == 5
    for row, s in zip(rows, np.linspace(0, 1, 5)):
        u = _rps_solve(mech, z0, 0.2 * s, 0.2 * s, u)
        got = [float(row[c]) for c in POSE]
        np.testing.assert_allclose(got, [u[-3], u[-2], z0, 0.2 * s, 0.2 * s, u[-1]], atol=1e-9)


def test_a_sweep_spec_takes_a_coordinate_path(tmp_path):
    shutil.copy(ROOT / "models" / "3rps.urdf", tmp_path / "3rps.urdf")
    text = (ROOT / "models" / "3rps.toml").read_text().replace("name = ", "length_scale = {L}\nname = ", 1)
    (tmp_path / "robot.toml").write_text(text)
    (tmp_path / "s.toml").write_text(
        'template = "robot.toml"\n[design]\nmethod = "table"\nrows = [{L = 0.3}]\n'
        '[scan]\nfrom = "home"\nto = "roll=0.2,pitch=0.2"\nsamples = 5\n'
    )
    (record,) = list(pinmob.sweep(tmp_path / "s.toml"))
    assert (
        record["status"] == "ok" and record["samples"] == 5 and record["assembled"] == 1.0
    )  # before: unknown joint .roll.


def test_a_sample_whose_legs_leave_their_stroke_says_so():
    """The 3-RPS raised to z = 1.6 m: its legs (stroke [-1, 1] m in the URDF) extend beyond 1 m."""
    mech = pinmob.load("3-RPS")
    with pytest.warns(UserWarning, match="outside their position limits"):
        (row,) = list(scan(mech, grid_spec(mech, "home", [("z", 1.6, 1.6, 1)])))
    legs = [row[f"q_{n}_leg"] for n in "ABC"]
    upper = [mech.model.upperPositionLimit[mech.model.joints[mech.model.getJointId(f"{n}_leg")].idx_q] for n in "ABC"]
    assert row["reachable"] and all(v > u for v, u in zip(legs, upper))
    assert row["reason"].startswith("joints outside their limits: ") and all(f"{n}_leg" in row["reason"] for n in "ABC")
    (inside,) = list(scan(mech, grid_spec(mech, "home", [("z", 1.0, 1.0, 1)])))
    assert inside["reachable"] and inside["reason"] == ""


def test_the_rule_and_the_rows_do_not_depend_on_the_unit_of_length():
    """The 3-RPS in millimetres over roll x pitch: z held, the same rows with x, y, z and the legs times 1000."""
    from millimetres import in_units

    mech = pinmob.load("3-RPS")
    mm = in_units(mech, 1000.0, configurations=True)
    axes = [("roll", -0.2, 0.2, 3), ("pitch", -0.2, 0.2, 3)]
    a, b = grid_spec(mech, "home", axes), grid_spec(mm, "home", axes)
    assert [c for c, _ in a.held] == [c for c, _ in b.held] == ["z"] and a.following == b.following == ("x", "y", "yaw")
    for ra, rb in zip(scan(mech, a), scan(mm, b)):
        for c in ("x", "y", "z", "q_A_leg", "q_B_leg"):
            assert rb[c] == pytest.approx(1000 * ra[c], abs=1e-9)
        for c in ("roll", "pitch", "yaw", "q_A_r"):
            assert rb[c] == pytest.approx(ra[c], abs=1e-12)
        assert (ra["dof"], ra["motion_type"]) == (rb["dof"], rb["motion_type"])
