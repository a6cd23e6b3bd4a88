"""Scans of a file whose loops close only to CAD accuracy, with ``--closure-tol``: the rows of ``pinmob analyze``.

The fixture is the built-in 3-PUU with limb C's tip frame turned by rpy = (1e-5, 1e-5, 1e-5) rad (a CAD gap of
1.73e-5 rad at ``generic``): ``pinmob analyze --closure-tol 2e-5`` accepts it (3 DoF 3T, rank tolerance raised
to 10 x the residual). ``pinmob scan`` refused it at any ``--closure-tol`` (the reference was closed at the
default tolerance); threading the tolerance alone let the solver close the gap elsewhere (limb C turned by
~1e-5 rad, an exact closure of the perturbed file where the mobility is 2T1R or 2T1H). Now the reference's gaps
are held (:mod:`pinmob.assembly.cad_gaps`); the checks here are the test's own: a Newton solve of each limb tip
at the sample's pose with the gap it measured at the reference, and an SVD count of the platform's motions.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

import pinmob
from pinmob.assembly.cad_gaps import frame_gaps
from pinmob.exceptions import ArgumentError
from pinmob.model.actuated_joints import with_actuated
from pinmob.scan import grid_spec, path_spec, scan
from pinmob.viewer.workspace import sample_configuration

MODELS = Path(__file__).parent.parent / "models"
SPHERICAL = Path(__file__).parent / "data" / "cad_gaps" / "spherical_3rrr" / "robot.urdf"
TOL = 2e-5  # the value pinmob's refusal names for this gap
GRID = [("x", -0.02, 0.02, 5), ("y", -0.02, 0.02, 5)]


@pytest.fixture(scope="module")
def cad_copy(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """models/3puu.toml and a copy of its URDF whose ``C_tip_fixed`` origin has rpy = 1e-5 1e-5 1e-5."""
    folder = tmp_path_factory.mktemp("cad_3puu")
    shutil.copy(MODELS / "3puu.toml", folder / "3puu.toml")
    urdf = (MODELS / "3puu.urdf").read_text()
    turned, n = re.subn(
        r'(<joint name="C_tip_fixed".*?<origin [^>]*rpy=")0 0 0(")', r"\g<1>1e-5 1e-5 1e-5\g<2>", urdf, flags=re.S
    )
    assert n == 1
    (folder / "3puu.urdf").write_text(turned)
    return folder / "3puu.toml"


def q_of(mech: pinmob.Mechanism, row: dict) -> np.ndarray:
    """The configuration a row gives (every joint is one-degree here: its ``q_<name>`` columns)."""
    model = mech.model
    q = np.zeros(model.nq)
    for j in range(1, model.njoints):
        q[model.joints[j].idx_q] = row[f"q_{model.names[j]}"]
    return q


def residual(mech: pinmob.Mechanism, q: np.ndarray) -> float:
    """The largest miss of a limb tip against the platform frame, max(|p| / L, |r|), computed here."""
    model, data = mech.model, mech.model.createData()
    pin.framesForwardKinematics(model, data, q)
    errors = [pin.log6(data.oMf[mech.platform_id].actInv(data.oMf[limb.tip_id])).vector for limb in mech.limbs]
    return max(max(np.linalg.norm(e[:3]) / mech.length_scale, np.linalg.norm(e[3:])) for e in errors)


def tip_newton(mech: pinmob.Mechanism, q: np.ndarray, targets: dict[int, pin.SE3]) -> np.ndarray:
    """Each limb tip at its target pose: Newton steps (least squares) on ``log6(target^-1 oM_tip)`` per limb."""
    model, data = mech.model, mech.model.createData()
    q = q.copy()
    for _ in range(50):
        pin.computeJointJacobians(model, data, q)
        pin.updateFramePlacements(model, data)
        step = np.zeros(model.nv)
        worst = 0.0
        for limb in mech.limbs:
            m = targets[limb.tip_id].actInv(data.oMf[limb.tip_id])
            e = pin.log6(m).vector
            jac = pin.Jlog6(m) @ pin.getFrameJacobian(model, data, limb.tip_id, pin.LOCAL)
            cols = np.flatnonzero(np.abs(jac).sum(axis=0) > 0)
            step[cols] -= np.linalg.lstsq(jac[:, cols], e, rcond=None)[0]
            worst = max(worst, float(np.abs(e).max()))
        if worst < 1e-14:
            break
        q = pin.integrate(model, q, step)
    return q


def platform_motions(mech: pinmob.Mechanism, q: np.ndarray, rtol: float) -> tuple[int, bool]:
    """(DoF, all free motions translations) counted here: each limb's twists (its tip's Jacobian at the platform
    origin, world axes, v / L), their reciprocal wrenches, the twists reciprocal to all of them; ranks at rtol
    times the largest singular value."""
    model, data = mech.model, mech.model.createData()
    pin.computeJointJacobians(model, data, q)
    pin.updateFramePlacements(model, data)
    scale = np.r_[np.full(3, 1 / mech.length_scale), np.ones(3)][:, None]
    wrenches = []
    for limb in mech.limbs:
        jac = scale * pin.getFrameJacobian(model, data, limb.tip_id, pin.LOCAL_WORLD_ALIGNED)
        u, s, _ = np.linalg.svd(jac)
        wrenches.append(u[:, int(np.sum(s > rtol * s[0])) :])
    u, s, _ = np.linalg.svd(np.hstack(wrenches))
    rank = int(np.sum(s > rtol * s[0]))
    free = u[:, rank:]
    return 6 - rank, bool(np.linalg.norm(free[3:]) <= rtol)


def check_rows(mech: pinmob.Mechanism, rows: list[dict]) -> None:
    """Every row: assembled, its residual and rank tolerance those computed here, 3 DoF 3T by the count here and
    by ``pinmob.analyze`` at its joint values and the same closure tolerance (as ``analyze --closure-tol``)."""
    for row in rows:
        assert row["reachable"], row["reason"]
        q = q_of(mech, row)
        res = residual(mech, q)
        assert row["residual"] == pytest.approx(res, rel=1e-6)
        assert res == pytest.approx(np.linalg.norm([1e-5] * 3), rel=1e-3)  # the gap, held
        assert row["rank_rtol"] == pytest.approx(10 * res, rel=1e-6)
        assert platform_motions(mech, q, 10 * res) == (3, True)
        report = pinmob.analyze(mech, q, closure_tol=TOL)
        assert (
            (row["dof"], row["motion_type"], row["constraint_rank"], row["singularity"])
            == (
                report.dof,
                report.motion_type,
                report.constraint_rank,
                report.singularity.label,
            )
            == (3, "3T", 3, "none")
        )


def test_cad_copy_grid_scans_with_the_closure_tolerance_analyze_takes(cad_copy: Path, tmp_path: Path):
    """The brief's repro through the CLI: it used to refuse, naming the flag it was given."""
    out = tmp_path / "scan.json"
    args = ["--grid", "x:-0.02:0.02:5", "y:-0.02:0.02:5", "--at", "generic", "--closure-tol", str(TOL)]
    done = subprocess.run(
        [sys.executable, "-m", "pinmob", "scan", str(cad_copy), *args, "--json", str(out), "--no-progress"],
        capture_output=True, text=True, timeout=600, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert (
        "25 x 3 DoF 3T" in done.stdout
        and "closure tolerance 2e-05 (CAD gaps of the reference held; rank tolerance 0.00017)" in done.stdout
    )
    doc = json.loads(out.read_text())
    assert doc["scan"]["closure_tol"] == TOL
    assert doc["scan"]["rank_rtol"] == pytest.approx(10 * np.linalg.norm([1e-5] * 3), rel=1e-3)  # at generic
    rows = [r for r in doc["samples"] if not r["refined"]]
    assert len(rows) == 25
    check_rows(pinmob.load(cad_copy), rows)


def test_cad_grid_holds_the_gap_measured_at_the_reference(cad_copy: Path):
    """Each sample's configuration is the test's own Newton solve of the tips at the sample's pose, limb C's tip
    at that pose times its gap at ``generic`` (measured here); the batched and the single-sample engines agree."""
    mech = pinmob.load(cad_copy)
    spec = grid_spec(mech, "generic", GRID, closure_tol=TOL)
    model, data = mech.model, mech.model.createData()
    pin.framesForwardKinematics(model, data, spec.q_ref)
    platform = data.oMf[mech.platform_id]
    gaps = {limb.tip_id: platform.actInv(data.oMf[limb.tip_id]) for limb in mech.limbs}
    assert np.linalg.norm(pin.log3(gaps[mech.limbs[2].tip_id].rotation)) > 1e-5  # limb C's, the others ~0
    rows = [r for r in scan(mech, spec) if not r["refined"]]
    single = [r for r in scan(mech, replace(spec, engine="single")) if not r["refined"]]
    assert len(rows) == 25
    check_rows(mech, rows)
    for row, other in zip(rows, single):
        assert (row["dof"], row["motion_type"]) == (other["dof"], other["motion_type"])
        np.testing.assert_allclose(q_of(mech, row), q_of(mech, other), atol=1e-9)
        pose = pin.SE3(platform.rotation, np.array([row["grid_x"], row["grid_y"], platform.translation[2]]))
        q = tip_newton(mech, q_of(mech, row), {tip: pose * gap for tip, gap in gaps.items()})
        np.testing.assert_allclose(q_of(mech, row), q, atol=1e-9)
        np.testing.assert_allclose([row["x"], row["y"], row["z"]], pose.translation, atol=1e-12)
    shown = sample_configuration(mech, rows, 3, spec.q_ref, TOL)  # what scan --show/--html --sample 3 draws
    np.testing.assert_allclose(shown.q, q_of(mech, rows[3]), atol=0)


def test_cad_paths_scan_with_the_closure_tolerance(cad_copy: Path):
    """A pose path and an actuated-joint path from ``generic`` to ``offset``: the rows of analyze at that tolerance."""
    mech = pinmob.load(cad_copy)
    for joints in (False, True):
        spec = path_spec(mech, "generic", "offset", 5, joints=joints, closure_tol=TOL)
        rows = [r for r in scan(mech, spec) if not r["refined"]]
        assert len(rows) == 5
        check_rows(mech, rows)


def test_default_tolerance_adds_no_column_and_holds_no_gap():
    """At the default closure tolerance nothing changes: no gaps, no ``residual``/``rank_rtol`` column; a tolerance
    out of range is refused in one line."""
    mech = pinmob.load("3-PUU")
    spec = grid_spec(mech, "generic", GRID)
    assert spec.gaps == () and not spec.cad and spec.assembly_mechanism(mech) is mech
    row = next(iter(scan(mech, spec)))
    assert "residual" not in row and "rank_rtol" not in row
    for bad in (0.1, float("nan")):  # refused as analyze refuses it (at most 1e-3: beyond, not a CAD gap)
        with pytest.raises(ArgumentError, match="closure_tol must be a finite number in"):
            grid_spec(mech, "generic", GRID, closure_tol=bad)
        with pytest.raises(ArgumentError, match="closure_tol must be a finite number in"):
            path_spec(mech, "generic", "offset", 3, closure_tol=bad)


def test_cad_closed_chain_joint_path_scans_with_the_closure_tolerance():
    """A mechanism without a platform whose point closures can never meet better than 1.0 and 0.6 um (the
    spherical 3-RRR of ``tests/data/cad_gaps``, :mod:`test_cad_gaps`): a joint path with ``--closure-tol 2e-5``
    was refused (the generic closure rank was taken at its ends at the default tolerance). Each row is now the
    count by hand of ``test_cad_gaps`` (nv 7, DoF 3, closure rank 4, 2 redundant equations), as ``analyze`` at the
    row's joint values and that tolerance says, with the miss held at its 1.0 um (1.37e-5 L)."""
    mech = with_actuated(pinmob.load(SPHERICAL), ["a1", "a2", "a3"])
    spec = path_spec(mech, "a1=0,a2=0,a3=0", "a1=0.2,a2=0.1,a3=0", 5, closure_tol=TOL)
    rows = [r for r in scan(mech, spec) if not r["refined"]]
    assert len(rows) == 5
    for row in rows:
        assert row["reachable"], row["reason"]
        assert (row["dof"], row["closure_rank"], row["redundant_constraints"]) == (3, 4, 2)
        assert row["residual"] * mech.length_scale == pytest.approx(1.0e-6, rel=1e-3)
        q = q_of(mech, row)
        mm = pinmob.analyze(mech, q, closure_tol=TOL).mechanism_mobility
        assert (mm.mechanism_dof, mm.rank, mm.redundant_constraints) == (3, 4, 2)


def test_a_pose_reference_without_a_closed_configuration_holds_no_gap(tmp_path: Path):
    """A pose ``--at`` on a file whose named configurations are gone is assembled from the neutral configuration:
    its misses (open loops, 0.47 m and 2.6 rad for the 3-UR5) are not CAD gaps and are not held.

    Three UR5 arms rigidly holding one object, away from their singularities: the object has 6 DoF (3T3R), each arm
    a 6R chain of full rank. On the old code the neutral configuration's misses were held as gaps and the grid at
    ``--closure-tol 2e-5`` was refused ("could not assemble '3-UR5' at platform pose ...")."""
    toml = (MODELS / "3ur5.toml").read_text()
    toml = toml[: toml.index("[configurations.")].replace("[[limbs]]", "generic_rank = 0\n\n[[limbs]]", 1)
    (tmp_path / "3ur5.toml").write_text(toml)
    shutil.copy(MODELS / "3ur5.urdf", tmp_path / "3ur5.urdf")
    mech = pinmob.load(tmp_path / "3ur5.toml")
    assert not mech.configurations
    with pytest.raises(pinmob.ClosureError, match="does not close"):
        frame_gaps(mech, mech.neutral(), TOL)
    spec = grid_spec(mech, "0,0,0.35,0,0,0", [("x", -0.02, 0.02, 3)], closure_tol=TOL)
    assert spec.gaps == ()
    rows = [r for r in scan(mech, spec) if not r["refined"]]
    assert [(r["dof"], r["motion_type"]) for r in rows] == [(6, "3T3R")] * 3
