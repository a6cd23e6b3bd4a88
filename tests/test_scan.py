"""Scans find singularities where the literature puts them; workers == serial; CSV/JSON/PNG outputs."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.cli import main
from pinmob.scan import grid_spec, path_spec, scan

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


def _same(a: list[dict], b: list[dict]) -> bool:
    def norm(r: dict) -> dict:
        return {k: ("nan" if isinstance(v, float) and math.isnan(v) else v) for k, v in r.items()}

    return [norm(r) for r in a] == [norm(r) for r in b]


def test_workers_give_the_serial_results():
    mech = pinmob.load("3-PUU")
    spec = path_spec(mech, "generic", "-0.09,0.05,-0.18,0,0,0", 70)  # three chunks
    serial = list(scan(mech, spec, workers=1, progress=False))
    parallel = list(scan(mech, spec, workers=2, progress=False))
    assert len(serial) == 70 and _same(serial, parallel)
    grid = grid_spec(mech, "generic", [("x", -0.1, 0.14, 7), ("y", -0.2, 0.2, 5)])
    serial = list(scan(mech, grid, workers=1, progress=False))
    parallel = list(scan(mech, grid, workers=2, progress=False))
    assert _same(serial, parallel)
    assert any(not r["reachable"] for r in serial) and any(r["reachable"] for r in serial)


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
    assert main(["scan", "3-PUU", "--grid", "x:-0.1:0.14:7", "y:-0.12:0.12:5", "--plot", str(m), "--no-progress"]) == 0
    out = capsys.readouterr().out
    assert "35 samples" in out and "unreachable" in out
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
        assert_allclose([r["sv4"], r["sv5"], r["sv6"]], 0.0, atol=1e-12)
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
    assert "different files" in capsys.readouterr().err
    # the plot is a PNG: any other name was a matplotlib traceback after the whole scan had run
    assert main(["scan", "3-UPU", "-n", "3", "--plot", str(tmp_path / "p.txt")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "p.txt" in err and ".png" in err and not (tmp_path / "p.txt").exists()
