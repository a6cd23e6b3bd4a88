"""Scans of mechanisms without a platform: a path in the actuated joints, the whole closed chain per sample.

The planar five-bar of the fixtures (onshape-to-robot's conventions: MJCF ``<connect site1 site2>`` between
``closing_tip_1/_2`` sites, and a bare URDF with ``closing_tip_1/_2`` frames): hinges about z at
A1 = (-d, 0) and A2 = (d, 0), proximal links l1 driven by a1, a2, distal links l2 (passive p1, p2) whose
tips are pinned together (a point closure, its z row implied in the plane). By hand:

* nv 4, closure rows 3, rank 2: mechanism DoF 2, 1 redundant equation, no idle motion, anywhere;
* elbows B_i = A_i + l1 (cos a_i, sin a_i). The loops close iff |B1 B2| <= 2 l2. With a1, a2 locked the tip
  P can still move iff its two velocities, perpendicular to B1P and to B2P, can be equal, i.e. iff the two
  distal links are aligned: |B1 B2| = 2 l2 (P the midpoint) or 0. That is the actuation singularity, and the
  edge of the actuators' reachable set;
* on the symmetric path a1 = t, a2 = pi - t it lies where B1 = (-l2, l1 sin t): cos t* = (d - l2) / l1,
  there p1 = -t* (distal 1 along +x) and p2 = t* (distal 2 along -x): the keyframe ``aligned``;
* with a2 held, |B1 B2|^2 = l1^2 + D^2 - 2 l1 D cos(a1 - phi), D and phi the length and angle of B2 - A1: the
  edge is at a1 = phi +- alpha, cos alpha = (l1^2 + D^2 - 4 l2^2) / (2 l1 D).

MuJoCo's ``efc_J`` counts the DoF a second way (nv - rank), and with the rows selecting a1, a2 appended, the
motions left with the actuators locked.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import mujoco
import numpy as np
import pytest
from test_third_party import mujoco_counts

import pinmob
from pinmob.cli import main
from pinmob.model.actuated_joints import with_actuated
from pinmob.scan import columns, path_spec, scan

D, L1, L2 = 0.1, 0.1, 0.08
T_STAR = math.acos((D - L2) / L1)  # the symmetric path's actuation singularity


def fivebar_mjcf() -> str:
    """The five-bar in onshape-to-robot's MJCF convention, motors a1, a2, keyframe ``aligned`` (by hand)."""
    geom = '<geom type="capsule" fromto="0 0 0 {} 0 0" size="0.005"/>'
    arms = "".join(
        f'<body name="proximal{i}" pos="{x} 0 0"><joint name="a{i}" axis="0 0 1"/>{geom.format(L1)}'
        f'<body name="distal{i}" pos="{L1} 0 0"><joint name="p{i}" axis="0 0 1"/>{geom.format(L2)}'
        f'<site name="closing_tip_{i}" pos="{L2} 0 0"/></body></body>'
        for i, x in ((1, -D), (2, D))
    )
    key = f"{T_STAR!r} {-T_STAR!r} {math.pi - T_STAR!r} {T_STAR!r}"
    return (
        f'<mujoco model="fivebar"><worldbody>{arms}</worldbody>'
        '<equality><connect site1="closing_tip_1" site2="closing_tip_2"/></equality>'
        '<actuator><position joint="a1"/><position joint="a2"/></actuator>'
        f'<keyframe><key name="aligned" qpos="{key}"/></keyframe></mujoco>'
    )


def fivebar_urdf() -> str:
    """The same five-bar as a bare onshape-to-robot URDF (closing_tip_1/_2 frames; no actuation in the file)."""
    joint = '<joint name="{n}" type="revolute"><parent link="{p}"/><child link="{c}"/><origin xyz="{o} 0 0"/>'
    joint += '<axis xyz="0 0 1"/><limit lower="-7" upper="7" effort="1" velocity="1"/></joint>'
    parts = ['<link name="base"/>']
    for i, x in ((1, -D), (2, D)):
        parts += [f'<link name="proximal{i}"/><link name="distal{i}"/><link name="closing_tip_{i}"/>']
        parts.append(joint.format(n=f"a{i}", p="base", c=f"proximal{i}", o=x))
        parts.append(joint.format(n=f"p{i}", p=f"proximal{i}", c=f"distal{i}", o=L1))
        parts.append(
            f'<joint name="t{i}" type="fixed"><parent link="distal{i}"/><child link="closing_tip_{i}"/>'
            f'<origin xyz="{L2} 0 0"/></joint>'
        )
    return f'<robot name="fivebar">{"".join(parts)}</robot>'


@pytest.fixture
def files(tmp_path):
    (tmp_path / "fivebar.xml").write_text(fivebar_mjcf())
    (tmp_path / "fivebar.urdf").write_text(fivebar_urdf())
    return tmp_path


def locked_by_mujoco(path: Path, values: dict[str, float]) -> int:
    """Motions left with a1, a2 locked, by MuJoCo: nv - rank [efc_J (equality rows); rows selecting a1, a2]."""
    m = mujoco.MjModel.from_xml_path(str(path))
    d = mujoco.MjData(m)
    for name, value in values.items():
        d.joint(name).qpos[:] = value
    mujoco.mj_forward(m, d)
    eq = np.flatnonzero(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    jac = d.efc_J.reshape(d.nefc, m.nv)[eq]
    select = np.zeros((2, m.nv))
    select[0, m.joint("a1").dofadr[0]] = select[1, m.joint("a2").dofadr[0]] = 1.0
    s = np.linalg.svd(np.vstack([jac, select]), compute_uv=False)
    return m.nv - int(np.count_nonzero(s > 1e-9 * s[0]))


def test_symmetric_path_finds_the_aligned_distal_links(files):
    """From the hand-derived singular keyframe to a regular pose: the actuation verdict is NOT valid exactly at
    t*, valid elsewhere; DoF 2 and 1 redundant equation everywhere; MuJoCo counts the same at the samples."""
    path = files / "fivebar.xml"
    mech = pinmob.load(path)
    assert mech.actuated == ("a1", "a2")
    spec = path_spec(mech, "aligned", f"a1=0.9,a2={math.pi - 0.9!r}", 9)
    rows = list(scan(mech, spec, progress=False))
    samples = [r for r in rows if not r["refined"]]
    assert len(samples) == 9 and all(r["reachable"] for r in samples)
    assert list(rows[0]) == columns(spec)
    first = samples[0]
    assert first["q_a1"] == pytest.approx(T_STAR, abs=1e-12) and first["q_p1"] == pytest.approx(-T_STAR, abs=1e-9)
    assert (first["singularity"], first["actuation_valid"], first["locked_dof"]) == ("actuation", False, 1)
    assert first["distance"] <= spec.rtol
    for r in samples[1:]:
        assert (r["singularity"], r["actuation_valid"], r["locked_dof"]) == ("none", True, 0), r["s"]
        assert r["distance"] > 1e3 * spec.rtol
    for r in samples:
        assert (r["dof"], r["closure_rank"], r["redundant_constraints"], r["idle_dof"]) == (2, 2, 1, 0)
    for r in samples[::4]:
        values = {n: r[f"q_{n}"] for n in ("a1", "p1", "a2", "p2")}
        nv, eq_rows, rank, gap = mujoco_counts(path, values)
        assert gap < 1e-9 and (nv - rank, eq_rows - rank) == (r["dof"], r["redundant_constraints"])
        assert locked_by_mujoco(path, values) == r["locked_dof"]


def test_bare_urdf_path_through_the_edge_refines_both_folds(files, capsys):
    """a2 held, a1 turned the long way round: the loops open and close again; the refined points lie on the
    hand-derived edge a1 = phi +- alpha (mod 2 pi), each an actuation singularity."""
    b2 = np.array([D + L1 * math.cos(math.pi - 0.9), L1 * math.sin(math.pi - 0.9)])
    rel = b2 - np.array([-D, 0.0])
    dist, phi = float(np.linalg.norm(rel)), math.atan2(rel[1], rel[0])
    alpha = math.acos((L1**2 + dist**2 - 4 * L2**2) / (2 * L1 * dist))
    start, end = phi + alpha - 0.2, phi - alpha + 0.2 + 2 * math.pi
    a2 = math.pi - 0.9
    mech = with_actuated(pinmob.load(files / "fivebar.urdf"), ["a1", "a2"])
    rows = list(scan(mech, path_spec(mech, f"a1={start!r},a2={a2!r}", f"a1={end!r},a2={a2!r}", 41), progress=False))
    samples = [r for r in rows if not r["refined"]]
    assert samples[0]["reachable"] and samples[-1]["reachable"] and not all(r["reachable"] for r in samples)
    assert all(r["reason"] for r in samples if not r["reachable"])
    refined = [r for r in rows if r["refined"]]
    edges = sorted(r["q_a1"] for r in refined)
    assert len(edges) == 2
    assert edges[0] == pytest.approx(phi + alpha, abs=1e-6) and edges[1] == pytest.approx(
        phi - alpha + 2 * math.pi, abs=1e-6
    )
    assert all(r["singularity"] == "actuation" and r["locked_dof"] == 1 for r in refined)


def test_the_edge_searches_rows_do_not_depend_on_analysing_the_bisections(files, monkeypatch):
    """The closed chain's edge searches (the path above, through both folds) analyse only the last point their
    bisections assembled (:meth:`pinmob.scan.chunk._Chunk._search`); analysing every one gives the same rows."""
    import pinmob.scan.chunk as chunk

    b2 = np.array([D + L1 * math.cos(math.pi - 0.9), L1 * math.sin(math.pi - 0.9)])
    rel = b2 - np.array([-D, 0.0])
    dist, phi = float(np.linalg.norm(rel)), math.atan2(rel[1], rel[0])
    alpha = math.acos((L1**2 + dist**2 - 4 * L2**2) / (2 * L1 * dist))
    start, end, a2 = phi + alpha - 0.2, phi - alpha + 0.2 + 2 * math.pi, math.pi - 0.9
    mech = with_actuated(pinmob.load(files / "fivebar.urdf"), ["a1", "a2"])
    spec = path_spec(mech, f"a1={start!r},a2={a2!r}", f"a1={end!r},a2={a2!r}", 41)
    rows = list(scan(mech, spec, progress=False))
    assert sum(r["refined"] for r in rows) == 2 and not all(r["reachable"] for r in rows)
    trial = chunk._Chunk.trial
    monkeypatch.setattr(chunk._Chunk, "trial", lambda self, t, seed, analysed=True: trial(self, t, seed))
    assert [repr(list(r.items())) for r in scan(mech, spec, progress=False)] == [repr(list(r.items())) for r in rows]


def test_cli_scan_of_mjcf_and_bare_urdf(files, capsys):
    """The CLI: summary lines, the singular sample listed, CSV/JSON/plot written; --actuated for the URDF."""
    out_csv, out_json, png = files / "s.csv", files / "s.json", files / "s.png"
    args = ["--from", "aligned", "--to", f"a1=0.9,a2={math.pi - 0.9!r}", "-n", "5", "--no-progress"]
    code = main(["scan", str(files / "fivebar.xml"), *args, "--csv", str(out_csv), "--json", str(out_json),
                 "--plot", str(png)])  # fmt: skip
    out = capsys.readouterr().out
    assert code == 0
    assert "1 x mechanism DoF 2, closure rank 2, 0 idle, actuation NOT valid" in out
    assert "4 x mechanism DoF 2, closure rank 2, 0 idle, actuation valid" in out
    assert "#0 (s = 0; a1 = 1.36944, a2 = 1.77215" in out and "locked: 1 motion(s) left (p1:+1 p2:-1)" in out
    doc = json.loads(out_json.read_text())
    assert doc["scan"]["generic_closure_rank"] == 2 and len(doc["samples"]) == 5
    assert out_csv.read_text().splitlines()[0].startswith("index,s,refined,q_a1,q_a2,q_p1,q_p2,reachable,reason")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    urdf = str(files / "fivebar.urdf")
    ends = ["--from", "a1=0.9,a2=2.2", "--to", "a1=1,a2=2.1", "-n", "3"]
    assert main(["scan", urdf, "--actuated", "a1,a2", *ends]) == 0
    assert "3 x mechanism DoF 2, closure rank 2, 0 idle, actuation valid" in capsys.readouterr().out
    # --finite: the five-bar moves in 2 DoF at finite amplitude everywhere, the aligned pose included (by hand)
    assert main(["scan", str(files / "fivebar.xml"), *args[:4], "-n", "3", "--finite", "--no-progress"]) == 0
    assert "finite DoF of the mechanism at the assembled samples: 3 x 2 DoF" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "words"),
    [
        (["--from", "a1=0.9,a2=2.2", "--to", "a1=1,a2=2.1"], ["declares no actuated joint", "--actuated a,b"]),
        (["--actuated", "a1,a2", "--from", "a1=0.9,a2=2.2", "--to", "a1=1,b2=2.1"], ["unknown joint 'b2'", "'p2'"]),
        (["--actuated", "a1,a2", "--from", "a1=0.9,a2=2.2", "--to", f"a1={math.pi},a2=0"], ["do not close"]),
        (["--actuated", "a1,a2", "--from", "a1=0.9,a2=2.2", "--to", "a1=1,a2"], ["is not name=value"]),
        (["--actuated", "a1,a2", "--from", "0,0,0,0,0,0", "--to", "a1=1,a2=2"], ["has none"]),
        (["--actuated", "a1,a2", "--grid", "x:0:1:2", "y:0:1:2"], ["platform frame", "--from A --to B"]),
    ],
)
def test_cli_errors_are_one_line(files, capsys, extra, words):
    assert main(["scan", str(files / "fivebar.urdf"), *extra, "--no-progress"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("pinmob: error: ")
    assert all(w in err for w in words), err


def test_workers_give_the_same_rows(files, dask_cluster):
    """On a Dask LocalCluster of two worker processes (through the scheduler, whatever the pace), the rows of one."""
    mech = pinmob.load(files / "fivebar.xml")
    spec = path_spec(mech, "aligned", f"a1=0.9,a2={math.pi - 0.9!r}", 70)
    here = list(scan(mech, spec, progress=False))
    run = scan(mech, spec, workers=2, progress=False, scheduler=dask_cluster.scheduler_address)
    there = list(run)
    assert "Dask cluster at" in run.where
    assert [(r["index"], r["refined"]) for r in there] == [(r["index"], r["refined"]) for r in here]
    for a, b in zip(here, there):
        assert {k: v for k, v in a.items() if isinstance(v, (str, bool, int))} == {
            k: v for k, v in b.items() if isinstance(v, (str, bool, int))
        }
        np.testing.assert_allclose([a["distance"], a["q_p1"]], [b["distance"], b["q_p1"]], atol=1e-9)


def test_platform_joint_path_from_joint_values_is_the_joints_flag_path(capsys):
    """On a platform mechanism, joint values in --from/--to give the path that --joints gives between the
    named configurations holding those values (the flag still works)."""
    mech = pinmob.load("3-PUU-flat")
    q = pinmob.closed_configuration(mech, "flat-raised")
    model = mech.model
    values = ",".join(f"{n}={float(q[model.joints[model.getJointId(n)].idx_q])!r}" for n in mech.actuated)
    by_flag = path_spec(mech, "flat", "flat-raised", 5, joints=True)
    by_values = path_spec(mech, "flat", values, 5)
    assert by_values.kind == by_flag.kind == "joints" and by_values.platform
    np.testing.assert_allclose(by_values.b, by_flag.b, atol=0)
    rows = list(scan(mech, by_values, progress=False))
    assert [r["z"] for r in rows] == pytest.approx([0.0, 0.025, 0.05, 0.075, 0.1], abs=1e-9)
    assert main(["scan", "3-PUU-flat", "--from", "flat", "--to", values, "-n", "3", "--no-progress"]) == 0
    assert "actuated-joint path" in capsys.readouterr().out


def test_a_joint_path_in_continuous_joints_gives_their_angles():
    """The Bennett linkage (tests/data/bennett.toml: continuous joints J1..J4, twists alpha = 30 deg and
    beta = 60 deg): its closure by hand is theta3 = -theta1 and tan(theta1 / 2) tan(theta2 / 2) =
    sin((beta + alpha) / 2) / sin((beta - alpha) / 2). A continuous joint stores (cos, sin): the path
    interpolated J1's cosine as an angle (J1 went 0.955 -> 0.697 for 0.3 -> 0.8) and the rows gave the cosine
    of the result; the other joints were missing from the rows."""
    mech = pinmob.load(Path(__file__).parent / "data" / "bennett.toml")
    rows = list(scan(mech, path_spec(mech, "J1=0.3", "J1=0.8", 3), progress=False))
    alpha, beta = math.radians(30), math.radians(60)
    ratio = math.sin((beta + alpha) / 2) / math.sin((beta - alpha) / 2)
    assert [r["q_J1"] for r in rows] == pytest.approx([0.3, 0.55, 0.8], abs=1e-9)
    for r in rows:
        assert r["q_J3"] == pytest.approx(-r["q_J1"], abs=1e-7)
        assert math.tan(r["q_J1"] / 2) * math.tan(r["q_J2"] / 2) == pytest.approx(ratio, rel=1e-6)
    # an end beyond pi is interpolated towards the value given, not towards its angle in (-pi, pi], and the
    # rows read the values asked for (3.5 at the end, not 3.5 - 2 pi)
    far = [r["q_J1"] for r in scan(mech, path_spec(mech, "J1=0.3", "J1=3.5", 5), progress=False)]
    assert far == pytest.approx([0.3, 1.1, 1.9, 2.7, 3.5], abs=1e-9)
