"""Scans find singularities where the literature puts them; CSV/JSON/PNG outputs."""

from __future__ import annotations

import csv
import json
import math
import tempfile
from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose
from test_six_ups import pluecker, rel_sigma_min

import pinmob
import pinmob.scan.chunk as scan_module
from pinmob.analysis.generic import generic_constraint_rank
from pinmob.cli import main
from pinmob.scan.predictor import Predictor
from pinmob.scan.results import scan_plot as plot
from pinmob.scan.results import workspace_map as plot_map
from pinmob.scan.results.output import RowWriter, read_columns
from pinmob.scan.scan_run import columns, scan
from pinmob.scan.scan_spec import STRIDE, ScanSpec, grid_spec, path_spec

YAW_120 = f"0,0,0.4,0,0,{2 * math.pi / 3!r}"


def test_gough_stewart_type2_found_at_90_degrees_only():
    # Fichter (1986); the hand line-geometry check is in test_six_ups.py
    mech = pinmob.load("6-UPS")
    rows = list(scan(mech, path_spec(mech, "home", YAW_120, 13), progress=False))
    assert all(r["reachable"] and r["dof"] == 6 and r["motion_type"] == "3T3R" for r in rows)
    singular = [r["index"] for r in rows if r["singularity"] != "none"]
    assert singular == [9]  # yaw = 9 * 10 deg
    assert rows[9]["singularity"] == "actuation" and rows[9]["locked_dof"] == 1
    assert rows[9]["yaw"] == pytest.approx(math.pi / 2, abs=1e-9)
    assert rows[9]["distance"] < 1e-9 < min(r["distance"] for r in rows if r["index"] != 9)


def test_three_puu_beta_zero_on_the_flat_model():
    # 3-PUU-flat: links R - r, beta = 0 is the whole workspace: every sample of a slider path is at
    # the limb singularity, with the 2-DoF 1T1R mobility derived by hand for beta = 0
    mech = pinmob.load("3-PUU-flat")
    rows = list(scan(mech, path_spec(mech, "flat", "flat-raised", 5, joints=True), progress=False))
    assert [r["singular_limbs"] for r in rows] == ["A;B;C"] * 5
    assert all((r["dof"], r["motion_type"]) == (2, "1T1R") for r in rows)
    assert [r["z"] for r in rows] == pytest.approx([0.0, 0.025, 0.05, 0.075, 0.1], abs=1e-9)


def test_three_puu_rank_drops_at_the_workspace_boundary_only():
    # 3-PUU (R = 0.3, r = 0.15, links 0.25): limb A's link is horizontal (beta = 0) when the platform
    # centre is |0.15 e_A - p| = 0.25 from its guide, i.e. at x = -0.1 on the x axis
    mech = pinmob.load("3-PUU")
    rows = list(scan(mech, path_spec(mech, "generic", "-0.1,0,-0.2,0,0,0", 11), progress=False))
    assert [r["singularity"] for r in rows] == ["none"] * 10 + ["limb"]
    assert rows[-1]["singular_limbs"] == "A" and rows[-1]["dof"] == 2
    assert all((r["dof"], r["motion_type"]) == (3, "3T") for r in rows[:-1])
    distances = [r["distance"] for r in rows]
    assert all(a > b for a, b in zip(distances, distances[1:]))  # approaching the singularity


def _counting(monkeypatch: pytest.MonkeyPatch) -> dict[str, int]:
    """Count the assemblies a scan asks for (the real solvers still run): single-sample solves and the targets
    given to the batched predictor (pinmob.scan.predictor.Predictor._close, on stacks: each try of
    Predictor.close and Predictor.closed, the second from the seeds too)."""
    calls = {"n": 0}
    real, predict = scan_module.assemble_target, Predictor._close

    def counted(*args, **kwargs):
        calls["n"] += 1
        return real(*args, **kwargs)

    def counted_targets(self, poses, *rest):
        calls["n"] += len(poses)
        return predict(self, poses, *rest)

    monkeypatch.setattr(scan_module, "assemble_target", counted)
    monkeypatch.setattr(Predictor, "_close", counted_targets)
    return calls


@pytest.mark.parametrize("engine", ["batch", "single"])
def test_assemblies_per_sample_stay_bounded(monkeypatch, engine):
    """Each sample is assembled once, the walk seeding the chunks adds one per STRIDE samples and each chunk
    two (its neighbours on the line, for the refinement): about 1.19 per sample whatever the length (walking
    every chunk from the start cost 1.2 per sample at 100 samples, 1.8 at 400, 3.0 at 1000). With the batched
    engine, each by the predictor (none of these targets is out of reach or singular: none goes to the
    single-sample solver as well)."""
    mech = pinmob.load("3-PUU")
    calls = _counting(monkeypatch)
    for n in (100, 400):
        spec = replace(path_spec(mech, "generic", "offset", n), engine=engine)
        calls["n"] = 0
        rows = list(scan(mech, spec, progress=False))
        assert len(rows) == n and not any(r["refined"] for r in rows)
        chunks = len(spec.chunks())
        assert calls["n"] == n + math.ceil(n / STRIDE) + 2 * (chunks - 1)
        assert calls["n"] / n < 1.2
    # a grid of 40 short rows inside the workspace: each row (one chunk) walked at its first sample only
    grid = replace(grid_spec(mech, "generic", [("x", -0.02, 0.02, 40), ("y", -0.02, 0.02, 4)]), engine=engine)
    calls["n"] = 0
    assert len(list(scan(mech, grid, progress=False))) == 160
    assert calls["n"] == 160 + 40 + len(grid.approach())


def _five_bar_elbows(theta_a: float, theta_b: float) -> tuple[np.ndarray, np.ndarray]:
    """Elbow joints of the five-bar (base joints at (-+0.1, 0), proximal links 0.2 m, end point at (0, 0.3)
    at zero crank angles): at zero, the elbow of limb A is the outer intersection of the circles of radius 0.2
    about (-0.1, 0) and 0.25 about (0, 0.3); limb B's is its mirror image. A crank angle turns it about z."""
    base, end = np.array([-0.1, 0.0]), np.array([0.0, 0.3])
    d = np.linalg.norm(end - base)
    along = (0.2**2 - 0.25**2 + d**2) / (2 * d)
    u = (end - base) / d
    elbow_a0 = base + along * u + np.sqrt(0.2**2 - along**2) * np.array([-u[1], u[0]])  # the outer (x < -0.1) one
    elbow_b0 = elbow_a0 * [-1, 1]

    def turn(p: np.ndarray, about: np.ndarray, angle: float) -> np.ndarray:
        c, s = math.cos(angle), math.sin(angle)
        r = p - about
        return about + np.array([c * r[0] - s * r[1], s * r[0] + c * r[1]])

    return turn(elbow_a0, base, theta_a), turn(elbow_b0, -base, theta_b)


def test_warm_starts_keep_the_assembly_mode():
    """Both cranks of the five-bar turned by 3 rad: for each pair of crank angles the end point is one of the
    two intersections of the 0.25 m circles about the elbows. Assembled warm-started along the path it stays on
    the branch it starts on (sign of (e_B - e_A) x (p - e_A) constant), which the hand closure check confirms at
    every sample; assembled from the start configuration at each sample, the solver lands on the other branch
    at s = 0.8 .. 0.9."""
    mech = pinmob.load("five-bar")
    q = pinmob.closed_configuration(mech, "generic")
    idx = [mech.model.joints[mech.model.getJointId(n)].idx_q for n in mech.actuated]
    a = q[idx]
    spec = ScanSpec("joints", q, a, a + 3.0, 21, mech.actuated, generic_rank=generic_constraint_rank(mech))
    rows = [r for r in scan(mech, spec, progress=False) if not r["refined"]]
    assert len(rows) == 21 and all(r["reachable"] for r in rows)
    sides = []
    for r in rows:
        ea, eb = _five_bar_elbows(3.0 * r["s"], 3.0 * r["s"])
        p = np.array([r["x"], r["y"]])
        assert_allclose([np.linalg.norm(p - ea), np.linalg.norm(p - eb)], [0.25, 0.25], atol=1e-9)
        (ux, uy), (vx, vy) = eb - ea, p - ea
        sides.append(np.sign(ux * vy - uy * vx))
    assert set(sides) == {sides[0]}


def test_refinement_finds_the_type2_pose_between_samples():
    """The yaw path to 2.0944 rad (not quite 2 pi / 3) has no sample exactly at yaw = pi/2, Fichter's Type II
    pose (hand line geometry in test_six_ups.py): the sample at s = 0.75 is near-singular only, and the refined
    point is at yaw = pi / 2, where the hand Pluecker matrix of the six legs is singular."""
    mech = pinmob.load("6-UPS")
    rows = list(scan(mech, path_spec(mech, "home", "0,0,0.4,0,0,2.0944", 13), progress=False))
    samples = [r for r in rows if not r["refined"]]
    refined = [r for r in rows if r["refined"]]
    assert len(samples) == 13 and all(r["singularity"] == "none" for r in samples)
    assert [r["index"] for r in samples if r["near_singular"]] == [9]
    assert 1e-6 < samples[9]["distance"] < 1e-3 and samples[9]["closest"] == "actuation"
    assert len(refined) == 1
    (r,) = refined
    assert r["singularity"] == "actuation" and r["uncontrolled"] == "H1 z" and r["index"] == 8
    assert r["yaw"] == pytest.approx(math.pi / 2, abs=1e-9) and r["s"] == pytest.approx(math.pi / 2 / 2.0944, abs=1e-9)
    rotation = pin.rpy.rpyToMatrix(np.array([r["roll"], r["pitch"], r["yaw"]]))
    assert rel_sigma_min(pluecker(rotation, np.array([r["x"], r["y"], r["z"]]))) < 1e-9
    assert [x["index"] for x in rows] == sorted(x["index"] for x in rows)  # refined row between samples 8 and 9


def test_refinement_finds_tsai_constraint_singularity_between_samples():
    """The 3-UPU path from 'generic' (0.04, -0.03, 0.33) to (0.04, -0.03, -0.1) crosses the base plane, where the
    three couples are coplanar (see the test below), at s = 0.33 / 0.43; no sample lands there."""
    mech = pinmob.load("3-UPU")
    rows = list(scan(mech, path_spec(mech, "generic", "0.04,-0.03,-0.1,0,0,0", 12), progress=False))
    assert all(r["singularity"] == "none" for r in rows if not r["refined"])
    (r,) = [r for r in rows if r["refined"]]
    assert r["s"] == pytest.approx(0.33 / 0.43, abs=1e-9) and r["z"] == pytest.approx(0.0, abs=1e-9)
    assert r["singularity"] == "constraint+actuation" and r["dependent_limbs"] == "A;B;C"
    assert (r["dof"], r["motion_type"], r["constraint_rank"]) == (4, "3T1R", 2)


def _disk_gaps(x: float, y: float) -> np.ndarray:
    """Built-in 3-PUU (guides at R = 0.3 m, platform vertices at r = 0.15 m, links l = 0.25 m), platform
    translated to (x, y): limb i's link spans the horizontal distance h_i = |(x, y) - (R - r) e_i| from its guide
    to its vertex, and sin(beta_i) = sqrt(1 - (h_i / l)^2). The pose assembles iff h_i <= l for every limb, and
    beta_i = 0 (the link horizontal, limb i serially singular) on the circle h_i = l. Returns h_i - l [m]."""
    p = np.array([x, y])
    return np.array([np.linalg.norm(p - 0.15 * np.array([math.cos(a), math.sin(a)])) - 0.25
                     for a in (0.0, 2 * math.pi / 3, 4 * math.pi / 3)])  # fmt: skip


def test_three_puu_beta_zero_loci_in_a_workspace_slice():
    """An x-y slice of the built-in 3-PUU at the generic height crossing the beta_i = 0 circles (hand
    derivation in _disk_gaps). Reachability is exactly the hand one; the samples are flagged neither singular
    nor near-singular (the nearest is 5 mm inside a circle, where sin(beta) ~ 0.2); and every pair of
    neighbours on a row with one sample inside and one outside gets one refined point, on the circle of the
    limb it names (to the closure tolerance): a rank drop of that limb (twist rank 5 -> 4, a force along its horizontal link),
    3T -> 2T."""
    mech = pinmob.load("3-PUU")
    grid = grid_spec(mech, "generic", [("x", -0.08, 0.08, 3), ("y", -0.14, 0.14, 8)])
    rows = list(scan(mech, grid, progress=False))
    samples = [r for r in rows if not r["refined"]]
    refined = [r for r in rows if r["refined"]]
    crossings = 0
    for k, r in enumerate(samples):
        inside = bool(np.all(_disk_gaps(r["grid_x"], r["grid_y"]) <= 0))
        assert r["reachable"] == inside
        if inside:
            assert (r["singularity"], r["near_singular"], r["dof"], r["motion_type"]) == ("none", False, 3, "3T")
        if k % 8 < 7 and inside != bool(np.all(_disk_gaps(samples[k + 1]["grid_x"], samples[k + 1]["grid_y"]) <= 0)):
            crossings += 1
    assert crossings == 6 and len(refined) == crossings
    for r in refined:
        gaps = _disk_gaps(r["x"], r["y"])
        limb = "ABC"[int(np.argmin(np.abs(gaps)))]
        assert np.min(np.abs(gaps)) < 1e-6 and np.all(gaps < 1e-6)  # closure tolerance 1e-6 L = 3.7e-7 m
        assert r["singularity"] == "limb" and r["singular_limbs"] == limb and r["distance"] < 1e-6
        assert (r["dof"], r["motion_type"]) == (2, "2T")


def test_cli_writes_csv_json_and_plots(tmp_path, capsys):
    c, j, p = tmp_path / "s.csv", tmp_path / "s.json", tmp_path / "s.png"
    assert (
        main(
            [
                "scan",
                "6-UPS",
                "--from",
                "home",
                "--to",
                YAW_120,
                "-n",
                "13",
                "--csv",
                str(c),
                "--json",
                str(j),
                "--plot",
                str(p),
            ]
        )
        == 0
    )
    out = capsys.readouterr().out
    assert "singular samples: 1" in out and "#9" in out
    with c.open() as fh:
        rows = list(csv.DictReader(fh))
    assert len(rows) == 13 and rows[9]["singularity"] == "actuation"
    doc = json.loads(j.read_text())
    assert doc["scan"]["mechanism"] == "6-UPS" and len(doc["samples"]) == 13
    assert doc["samples"][9]["locked_dof"] == 1
    assert p.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and p.stat().st_size > 20_000

    m = tmp_path / "map.png"
    assert main(["scan", "3-PUU", "--grid", "x:0.1:0.14:3", "y:-0.05:0.05:3", "--plot", str(m), "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "9 samples" in out and "7 x unreachable" in out and "refined singular points: 4" in out
    assert m.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and m.stat().st_size > 20_000


def test_cli_errors_are_one_line(capsys):
    assert main(["scan", "3-PUU", "--grid", "x:0:1", "y:0:1:3"]) == 2
    assert "COORD:LO:HI:N" in capsys.readouterr().err
    assert main(["scan", "3-PUU", "--grid", "w:0:1:3", "y:0:1:3"]) == 2
    assert "valid" in capsys.readouterr().err
    assert main(["scan", "3-PUU", "--from", "nowhere"]) == 2
    assert "nowhere" in capsys.readouterr().err


def _tsai_couples(p: list[float]) -> np.ndarray:
    """(3, 3) unit constraint couples of Tsai's 3-UPU (built-in geometry R = 0.3 m, r = 0.15 m) for a pure
    translation p of the platform centre, derived by hand.

    Limb i (theta_i = 0, 120, 240 deg; e_i radial, t_i tangent, z up): leg d_i = p + (r - R) e_i. The base U's
    first axis t_i is fixed and its second axis n_i is normal to t_i and to the leg, n_i ~ t_i x d_i; the
    platform U repeats n_i then t_i. The couple the limb exerts is normal to both axis directions:
    c_i ~ t_i x n_i ~ -(d_i - (d_i . t_i) t_i) = -((d_i . e_i) e_i + (d_i . z) z)  (Tsai 1996).
    """
    cols = []
    for theta in (0.0, 2 * math.pi / 3, 4 * math.pi / 3):
        e = np.array([math.cos(theta), math.sin(theta), 0.0])
        d = np.asarray(p, float) + (0.15 - 0.3) * e
        c = d[:2] @ e[:2] * e + d[2] * np.array([0.0, 0.0, 1.0])
        cols.append(c / np.linalg.norm(c))
    return np.column_stack(cols)


def test_tsai_3upu_constraint_singularity_where_the_couples_are_coplanar(tmp_path, capsys):
    """Tsai's 3-UPU loses a constraint exactly when its three limb couples are coplanar (Zlatanov, Bonev &
    Gosselin 2002; Di Gregorio & Parenti-Castelli 2002): det[c_A c_B c_C] = 0. On the straight path from
    'generic' (0.04, -0.03, 0.33) down to the base plane, c_i = -(a_i e_i + p_z z) with a_i = p.e_i - 0.15 ~ -0.15:
    the points a_i e_i form a proper triangle, so det ~ p_z * (twice its area) vanishes only at p_z = 0.

    There the couples span the xy plane only (rank 2): the free twists are the reciprocal of {tau_x, tau_y},
    i.e. 3T plus the rotation about z: 4 DoF, 3T1R. With the legs locked each limb adds the force along its leg,
    here -0.15 e_i, horizontal and through the origin: {f_x, f_y at O, tau_x, tau_y} span 4, leaving
    2 uncontrolled motions, the translation along z and the rotation about z through O."""
    j = tmp_path / "upu.json"
    assert main(["scan", "3-UPU", "--from", "generic", "--to", "constraint-singular", "-n", "12",
                 "--json", str(j), "--no-progress"]) == 0  # fmt: skip
    out = capsys.readouterr().out
    assert "singular samples: 1" in out and "#11" in out
    rows = json.loads(j.read_text())["samples"]
    assert len(rows) == 12 and all(r["reachable"] for r in rows)
    for r in rows:
        assert [r["roll"], r["pitch"], r["yaw"]] == pytest.approx([0.0] * 3, abs=1e-9)  # pure translation
        p = [r["x"], r["y"], r["z"]]
        assert_allclose(p, (1 - r["s"]) * np.array([0.04, -0.03, 0.33]), atol=1e-9)
        couples = _tsai_couples(p)
        # the stacked (dimensionless, one unit wrench per limb) constraint matrix is [0; c_i]: same singular values
        assert_allclose([r["sv1"], r["sv2"], r["sv3"]], np.linalg.svd(couples, compute_uv=False), atol=1e-9)
        assert [r["sv4"], r["sv5"], r["sv6"]] == [None] * 3  # three wrenches: three singular values, no padding
        coplanar = abs(np.linalg.det(couples)) < 1e-9
        assert ("constraint" in r["singularity"].split("+")) == coplanar
        assert coplanar == (r["index"] == 11)
    *generic, last = rows
    assert all((r["dof"], r["motion_type"], r["singularity"], r["constraint_rank"], r["locked_dof"])
               == (3, "3T", "none", 3, 0) for r in generic)  # fmt: skip
    assert (last["dof"], last["motion_type"], last["constraint_rank"]) == (4, "3T1R", 2)
    assert last["singularity"] == "constraint+actuation" and last["locked_dof"] == 2
    assert sorted(last["uncontrolled"].split(";")) == ["R1 z", "T1 z"]
    assert last["distance"] < 1e-9 < min(r["distance"] for r in generic)


def test_cli_never_overwrites_outputs_unless_forced(tmp_path, capsys):
    # like `pinmob show --html`: an existing file is kept unless --force, checked before the scan runs
    c, j = tmp_path / "s.csv", tmp_path / "s.json"
    c.write_text("mine\n")
    args = ["scan", "3-UPU", "-n", "3", "--no-progress", "--csv", str(c), "--json", str(j)]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--csv" in err and str(c) in err and "--force" in err
    assert c.read_text() == "mine\n" and not j.exists()
    assert main([*args, "--force"]) == 0
    assert len(c.read_text().splitlines()) == 4 and len(json.loads(j.read_text())["samples"]) == 3
    capsys.readouterr()
    # a missing folder or a folder as file name is one line, exit 2 (it was a traceback)
    missing = tmp_path / "nowhere" / "s.csv"
    assert main(["scan", "3-UPU", "-n", "3", "--csv", str(missing)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "does not exist" in err and str(missing.parent) in err
    assert main(["scan", "3-UPU", "-n", "3", "--plot", str(tmp_path)]) == 2
    assert "is a folder" in capsys.readouterr().err
    assert main(["scan", "3-UPU", "-n", "3", "--csv", str(c), "--json", str(c), "--force"]) == 2
    assert "name the same file" in capsys.readouterr().err
    # the plot is a PNG: any other name was a matplotlib traceback after the whole scan had run
    assert main(["scan", "3-UPU", "-n", "3", "--plot", str(tmp_path / "p.txt")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "p.txt" in err and ".png" in err and not (tmp_path / "p.txt").exists()


def test_cli_grid_and_path_options_are_not_mixed(capsys):
    """A --grid axis has exactly four fields; path options with --grid (or --at without it) are refused by name."""
    cases = [
        (["--grid", "x:-0.1:0.1:3:7", "y:0:1:3"], ["x:-0.1:0.1:3:7", "four fields"]),
        (["--grid", "x:-0.1:0.1:3", "y:0:1:3", "--from", "generic"], ["--from", "--grid"]),
        (["--grid", "x:-0.1:0.1:3", "y:0:1:3", "--to", "offset", "-n", "5"], ["--to, -n"]),
        (["--grid", "x:-0.1:0.1:3", "y:0:1:3", "--joints"], ["--joints"]),
        (["--at", "generic", "-n", "3"], ["--at", "--grid"]),
    ]
    for extra, words in cases:
        assert main(["scan", "3-PUU", *extra]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and all(w in err for w in words), err


def test_cli_lists_refined_and_near_singular_points(capsys):
    assert main(["scan", "6-UPS", "--from", "home", "--to", "0,0,0.4,0,0,2.0944", "-n", "13", "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "singular samples: 0; near-singular samples (distance < 1e-03): 1; refined singular points: 1" in out
    refined = next(line for line in out.splitlines() if "#8+ refined" in line)
    assert refined.startswith("  #8+ refined (s = 0.749998; A_leg = ")  # a refined point prints its actuated joints
    assert all(f"{n}_leg = " in refined for n in "ABCDEF") and "): actuation, uncontrolled H1 z" in refined
    assert "#9 (s = 0.75): near-singular (actuation)" in out


def test_cli_scan_of_a_closed_chain_without_platform_says_why(capsys):
    """An Extended URDF has no platform: pose ends and grids are refused in one line saying why; with no named
    configuration the path's ends must be given; joint values scan the whole closed chain."""
    robot = str(Path(__file__).parent / "data" / "fivebar" / "robot.yaml")
    for extra, words in (
        (["--from", "0,0,0,0,0,0", "--to", "0,0,0,0,0,1", "-n", "3"], ["platform frame", "joint values"]),
        ([], ["give --from and --to"]),
        (["--grid", "x:0:1:2", "y:0:1:2"], ["platform frame", "Extended URDF", "actuated joints"]),
    ):
        assert main(["scan", robot, *extra]) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and all(w in err for w in words), err
    assert main(["scan", robot, "--from", "mot1=0,mot2=0", "--to", "mot1=0.3,mot2=0.2", "-n", "4"]) == 0
    assert "4 x mechanism DoF 2, closure rank 2, 0 idle, actuation valid" in capsys.readouterr().out


def test_all_unreachable_grid_plots_and_leaves_no_temporary_file(tmp_path, monkeypatch, capsys):
    """Nothing assembles 5 m away: the maps say so (it was a BoundaryNorm traceback), and the CSV written for the
    plot alone is removed."""
    scratch = tmp_path / "tmp"
    scratch.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(scratch))
    png = tmp_path / "g.png"
    assert main(["scan", "3-PUU", "--grid", "x:5:6:2", "y:5:6:2", "--plot", str(png), "--no-progress"]) == 0
    assert "4 x unreachable" in capsys.readouterr().out
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and list(scratch.iterdir()) == []


def test_map_cells_are_centred_on_the_samples(tmp_path):
    """Cell edges lie half a spacing around each sample, so the image and the markers share data coordinates,
    also along an axis with a single sample (its cell is as wide as the other axis's spacing)."""
    assert_allclose(plot_map._edges(np.array([0.0, 1.0, 2.0]), 7.0), [-0.5, 0.5, 1.5, 2.5])
    assert_allclose(plot_map._edges(np.array([0.3]), 0.02), [0.29, 0.31])
    mech = pinmob.load("3-PUU")
    c = tmp_path / "row.csv"
    spec = grid_spec(mech, "generic", [("x", -0.1, -0.1, 1), ("y", -0.02, 0.02, 3)])
    with RowWriter(columns(spec), {}, str(c)) as writer:
        for row in scan(mech, spec, progress=False):
            writer.write(row)
    fig = plot_map.map_figure(read_columns(c, ["grid_x", "grid_y", *plot_map.MAP_COLUMNS]), ["grid_x", "grid_y"])
    ax = fig.axes[0]
    assert_allclose(ax.get_xlim(), [-0.11, -0.09]) and assert_allclose(ax.get_ylim(), [-0.03, 0.03])
    (mesh,) = ax.collections
    assert_allclose(mesh.get_coordinates()[[0, -1], [0, -1], :], [[-0.11, -0.03], [-0.09, 0.03]])
    (marks,) = [line for line in ax.lines if line.get_label() == "singular"]  # (-0.1, 0): limb A's link horizontal
    assert_allclose(np.c_[marks.get_xdata(), marks.get_ydata()], [[-0.1, 0.0]], atol=1e-12)


def test_path_plot_draws_only_present_singular_values(tmp_path):
    """The 3-PUU stacks three wrenches: sigma_4..6 are absent (blank in the CSV), not zeros to be drawn at 1e-17;
    the rank threshold rtol is drawn."""
    mech = pinmob.load("3-PUU")
    c = tmp_path / "p.csv"
    spec = path_spec(mech, "generic", "offset", 5)
    with RowWriter(columns(spec), {}, str(c)) as writer:
        for row in scan(mech, spec, progress=False):
            writer.write(row)
    cols = read_columns(c, plot.PATH_COLUMNS)
    assert set(cols) == set(plot.PATH_COLUMNS)  # only what is drawn was read
    assert np.all(np.isnan(cols["sv4"])) and np.all(np.isfinite(cols["sv3"]))
    fig = plot.path_figure(cols, rtol=1e-6)
    constraint = fig.axes[1]
    labels = [line.get_label() for line in constraint.lines]
    assert [lab for lab in labels if lab.startswith("$")] == [f"$\\sigma_{k}/\\sigma_1$" for k in (1, 2, 3)]
    assert any(
        lab.startswith("rank threshold") and line.get_ydata()[0] == 1e-6 for lab, line in zip(labels, constraint.lines)
    )


@pytest.mark.parametrize("start", [0.0, -0.3, -0.6])
@pytest.mark.parametrize("end", [3.0, 2.9, 2.7])
def test_both_edges_of_the_five_bar_reach_are_refined_whatever_the_sampling(start, end):
    """Five-bar (motors at (0, 0) and (0.2, 0) m, proximal links 0.15 m, distal 0.18 m to the shared point):
    moving mot1 = a, mot2 = -a, the elbows are 0.2 + 0.3 sin(a) apart, and the loop closes while that is at
    most the two distal lengths: the reachable stretches end where sin(a) = (2 d - 0.2) / 0.3. A refined
    point lies on each edge whatever the path's ends and samples, also when the distance rises before it
    falls to the edge, or when the samples next to the edge do not assemble (with paths from 0 to 3, 5 and 7
    samples missed one edge or the other; with other ends, 38 of 63 paths missed one, then still 23)."""
    mech = pinmob.load(Path(__file__).parent / "data" / "fivebar" / "robot.yaml")
    distal = math.hypot(0.1, 0.15)
    theta = math.asin((2 * distal - 0.2) / 0.3)
    for samples in (3, 4, 5, 6, 7, 9, 13, 21):
        spec = path_spec(mech, f"mot1={start},mot2={-start}", f"mot1={end},mot2={-end}", samples)
        rows = list(scan(mech, spec, progress=False))
        refined = sorted(r["q_mot1"] for r in rows if r["refined"])
        assert_allclose(refined, [theta, math.pi - theta], atol=1e-6, err_msg=f"{samples} samples")


def test_json_rows_keep_the_csv_columns_in_order(tmp_path):
    """Every JSON row, reachable or not, lists the CSV's columns in the CSV header's order (an unreachable row
    had its reason second, a reachable one after the singular values)."""
    c, j = tmp_path / "s.csv", tmp_path / "s.json"
    argv = ["scan", "3-PUU", "--grid", "x:-0.3:0.3:3", "y:-0.3:0.3:3", "--at", "generic", "--no-progress"]
    assert main([*argv, "--csv", str(c), "--json", str(j)]) == 0
    with c.open() as fh:
        header = next(csv.reader(fh))
    samples = json.loads(j.read_text())["samples"]
    assert {s["reachable"] for s in samples} == {True, False}
    assert all(list(s) == header for s in samples)
