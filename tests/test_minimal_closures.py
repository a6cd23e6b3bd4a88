"""Minimal closures (issue 32, item 3): the report's proposal, ``pinmob fix`` in each format, and its refusals.

Independent truths used:

- a planar mechanism (every joint axis along z): a weld's independent equations are the two in-plane
  translations and the turn about z (``planar_weld`` about z); its DoF is the planar count 3 (n - 1) - 2 j
  (3-RRR-planar: n = 8 links, j = 9 hinges: 3), its motion types the file's expected ones (Gosselin & Angeles);
- a spherical mechanism (every axis through one point): a weld's independent equations are the three
  rotations (``orientation``); the 3-RRR-spherical's DoF is 3 (3R, rotations about that point);
- MuJoCo's own rank of the equality rows (``efc_J``) of the files written (and of the files as given);
- the Bennett linkage has 1 DoF (a spatial 4R loop, Bennett 1903).
"""

from __future__ import annotations

import dataclasses
import os
import shutil
import subprocess
import sys
import textwrap
import tomllib
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import pinmob
import pinmob.analysis.fixed_closures
from pinmob.cli import main
from pinmob.io.fixed_files import toml_document
from pinmob.model import ClosureType

DATA = Path(__file__).resolve().parent / "data"
ROBOTS = DATA / "example-parallel-robots"


def fix(capsys, *args):
    """``pinmob fix ...``: (status, stdout, stderr)."""
    status = main(["fix", *map(str, args)])
    out = capsys.readouterr()
    return status, out.out, out.err


def mujoco_rank(path):
    """MuJoCo's equality rows at qpos0 and their rank, and nv (a massless body given MuJoCo's bound mass)."""
    mujoco = pytest.importorskip("mujoco")
    spec = mujoco.MjSpec.from_file(str(path))
    spec.compiler.boundmass, spec.compiler.boundinertia = 1e-9, 1e-12
    m = spec.compile()
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    rows = np.flatnonzero(d.efc_type[: d.nefc] == mujoco.mjtConstraint.mjCNSTR_EQUALITY)
    jac = np.array(d.efc_J).reshape(-1, m.nv)[rows]
    s = np.linalg.svd(jac, compute_uv=False)
    return len(rows), int(np.sum(s > 1e-9 * s[0])), m.nv


def test_planar_3rrr_proposal_in_the_report():
    report = pinmob.analyze(pinmob.load("3-RRR-planar"), "generic")
    minimal = report.minimal_closures
    assert minimal is not None and minimal.complete and (minimal.rows, minimal.rank) == (12, 6)
    changes = {c.name: c for c in minimal.changes}
    assert set(changes) == {"limb B", "limb C"}
    for c in changes.values():
        assert (c.rows, c.needed, str(c.proposed.type)) == (6, 3, "planar_weld")
        np.testing.assert_allclose(np.abs(c.proposed.axis), [0, 0, 1], atol=1e-12)  # the plane's normal
    assert "minimal closures: 12 closure equations of rank 6 -> 6 (full row rank)" in str(report)
    doc = report.to_dict()["minimal_closures"]
    assert doc["proposed_rows"] == 6 and [c["needed"] for c in doc["closures"]] == [3, 3]


def test_no_redundancy_no_proposal(capsys, tmp_path):
    report = pinmob.analyze(pinmob.load("Delta"), "generic")
    assert report.mechanism_mobility.redundant_constraints == 0
    assert report.minimal_closures is None and report.to_dict()["minimal_closures"] is None
    assert "minimal closures" not in str(report)
    status, out, _ = fix(capsys, "Delta", "--output", tmp_path / "delta.toml")
    assert status == 0 and "nothing to fix" in out and not (tmp_path / "delta.toml").exists()


def test_fix_planar_3rrr_toml(capsys, tmp_path):
    target = tmp_path / "3rrr_min.toml"
    status, out, _ = fix(capsys, "3-RRR-planar", "--output", target)
    assert status == 0 and f"wrote {target}" in out
    fixed = pinmob.load(target)
    assert [(c.name, str(c.type)) for c in fixed.closures] == [("limb_B", "planar_weld"), ("limb_C", "planar_weld")]
    assert set(fixed.actuated) == {"A_r1", "B_r1", "C_r1"}  # limb B's and C's actuators kept
    for name, motion in (("generic", "2T1R"), ("limb-A-stretched", "1T1R")):
        report = pinmob.analyze(fixed, name)
        chain = report.mechanism_mobility
        assert (chain.rows, chain.rank, chain.redundant_constraints) == (6, 6, 0), name
        assert chain.mechanism_dof == 3 * (8 - 1) - 2 * 9, name
        assert report.platform_frame.motion_type == motion == fixed.expected[name].motion_type, name
        before = pinmob.analyze(pinmob.load("3-RRR-planar"), name)
        assert report.singularity.label == before.singularity.label, name  # limb A's loops lock B_r1, C_r1 too
        assert report.length_scale == before.length_scale, name


def test_fix_spherical_3rrr_toml(capsys, tmp_path):
    target = tmp_path / "sph.toml"
    assert fix(capsys, "3-RRR-spherical", "--output", target)[0] == 0
    fixed = pinmob.load(target)
    assert {str(c.type) for c in fixed.closures} == {"orientation"}
    for name in fixed.configurations:
        chain = pinmob.analyze(fixed, name).mechanism_mobility
        assert chain.redundant_constraints == 0 and chain.mechanism_dof == 3, name


def test_fix_toml_writes_names_and_text_as_tomllib_reads_them(capsys, tmp_path):
    """A description with every control character, DEL, quotes, backslashes and non-ASCII letters, and configuration
    names TOML must quote (non-ASCII letters, quotes, a backslash, a dot, a space) or may leave bare: the written
    file parses with tomllib to the values the input parses to (tomllib reads both)."""
    description = 'café "quoted" back\\slash ' + "".join(map(chr, range(0x20))) + "\x7f end"
    names = ["é", "x²", 'say "hi"', "back\\slash", "a.b", "two words", "home"]

    def escaped(text):  # written with \\uXXXX escapes only: the input's text does not depend on the writer under test
        return (
            '"'
            + "".join(c if c.isascii() and c.isprintable() and c not in '"\\' else f"\\u{ord(c):04X}" for c in text)
            + '"'
        )

    shutil.copy(DATA / "fourbar.urdf", tmp_path)
    head = (DATA / "fourbar.toml").read_text(encoding="utf-8").split("[configurations.home]")[0].splitlines()
    lines = [f"description = {escaped(description)}" if line.startswith("description = ") else line for line in head]
    text = "\n".join(lines) + "\n"
    text += "".join(f"[configurations.{escaped(name)}]\njoints = {{}}\n\n" for name in names)
    source = tmp_path / "fourbar.toml"
    source.write_text(text, encoding="utf-8")
    given = tomllib.loads(text)
    assert given["description"] == description and list(given["configurations"]) == names  # the input is right
    target = tmp_path / "fixed.toml"
    assert fix(capsys, source, "--output", target)[0] == 0
    written = tomllib.loads(target.read_text(encoding="utf-8"))
    assert written["description"] == description and written["configurations"] == given["configurations"]
    assert pinmob.load(target).description == description


def test_fix_refuses_a_urdf_path_no_toml_can_hold(capsys, tmp_path):
    """The input read through a link (UTF-8) into a folder whose name is not UTF-8 (the byte 0xff, which Python reads
    as the lone surrogate U+DCFF): the written file would name the URDF through that folder, which no TOML (UTF-8)
    can hold. One line naming the path and the cure, status 2, nothing written (before: a raw UnicodeEncodeError)."""
    folder = tmp_path / os.fsdecode(b"in\xff")
    with pytest.raises(UnicodeEncodeError):
        folder.name.encode("utf-8")  # the truth: Python's own codec cannot write this name as UTF-8
    folder.mkdir()
    for name in ("fourbar.toml", "fourbar.urdf"):
        shutil.copy(DATA / name, folder)
    (tmp_path / "link").symlink_to(folder)
    (tmp_path / "out").mkdir()
    status, _, err = fix(capsys, tmp_path / "link" / "fourbar.toml", "--output", tmp_path / "out" / "fixed.toml")
    assert status == 2 and "Traceback" not in err and len(err.strip().splitlines()) == 1
    assert err.startswith("pinmob: error: the URDF's path from the output's folder '../in\\udcff/fourbar.urdf' holds")
    assert "rename it, or write the output in the URDF's folder" in err
    assert list((tmp_path / "out").iterdir()) == []
    target = folder / "fixed.toml"  # written beside the URDF, as the message says: the path is its bare name
    assert fix(capsys, tmp_path / "link" / "fourbar.toml", "--output", tmp_path / "link" / "fixed.toml")[0] == 0
    assert tomllib.loads(target.read_bytes().decode("utf-8"))["urdf"] == "fourbar.urdf"


@pytest.mark.parametrize(
    "doc",
    [
        {"t": {"a": 1, "b": 2}},  # before: [t] declared twice, which tomllib refuses
        {"t": {"a": 1, "s": {"c": 2.5}, "b": "x"}},  # plain values around a sub-table
        {"t": {}, "name": "n"},  # an empty table is kept
        {"configurations": {"home": {"joints": {"a": 0.5}}, "é x": {}}, "limbs": [{"name": "A", "tip": "t"}]},
    ],
)
def test_toml_document_reads_back_as_tomllib_reads_it(doc):
    assert tomllib.loads(toml_document(doc)) == doc


_SCALARS = (
    st.booleans()
    | st.integers(-(2**63), 2**63 - 1)
    | st.floats(allow_nan=False)
    | st.text()  # any Unicode (hypothesis draws no lone surrogates)
)
_VALUES = st.recursive(
    _SCALARS, lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(), inner, max_size=3)
)
_TABLES = st.dictionaries(st.text(), _VALUES, max_size=3)


@settings(max_examples=200, deadline=None)
@given(
    doc=st.dictionaries(
        st.text(),
        _VALUES
        | st.lists(_TABLES, min_size=1, max_size=3)  # [[k]]
        | st.dictionaries(st.text(), _VALUES | _TABLES, max_size=4),  # [k] with plain values and [k.name] tables
        max_size=4,
    )
)
def test_any_document_reads_back_as_tomllib_reads_it(doc):
    """Top-level plain values, arrays of tables and tables holding plain values and sub-tables, keys of any text."""
    assert tomllib.loads(toml_document(doc)) == doc


def test_fix_checks_every_named_configuration():
    mech = pinmob.load("3-RRR-planar")
    fixed = pinmob.fix_closures(mech)
    check = pinmob.check_fixed(mech, fixed)
    assert check.same and check.configurations == ("generic", "limb-A-stretched")
    assert check.rows == ((12, 6, 0), (12, 6, 0)) and not check.redundant_left


def test_fix_check_sees_a_wrong_fix():
    """check_fixed is the comparator the fix tests rely on: a proposal that frees motions is reported. The
    3-RRR-planar's first closure, a planar weld about z (3 equations), swapped for an orientation closure (its
    turns only): the point is free to slide in the plane, 2 more mechanism DoF (3 -> 5), by hand."""
    mech = pinmob.load("3-RRR-planar")
    fixed = pinmob.fix_closures(mech)
    first = fixed.closures[0]
    wrong = dataclasses.replace(
        fixed, closures=(dataclasses.replace(first, type=ClosureType.ORIENTATION, axis=None), *fixed.closures[1:])
    )
    check = pinmob.check_fixed(mech, wrong)
    assert not check.same
    assert any("mechanism DoF 3 before, 5 after" in d for d in check.differences), check.differences


def test_fix_mjcf_bennett_weld_becomes_connect(capsys, tmp_path):
    source = DATA / "bennett_weld.xml"
    assert mujoco_rank(source)[:2] == (6, 3)  # MuJoCo: 6 weld rows of rank 3
    target = tmp_path / "bennett_connect.xml"
    status, out, _ = fix(capsys, source, "--output", target)
    assert status == 0 and "loop: weld -> connect" in out
    text = target.read_text()
    assert '<connect name="loop"' in text and "<weld" not in text and "Bennett linkage" in text
    rows, rank, nv = mujoco_rank(target)
    assert (rows, rank) == (3, 3) and nv - rank == 1  # full row rank in MuJoCo, Bennett's 1 DoF
    chain = pinmob.analyze(pinmob.load(target), "reference").mechanism_mobility
    assert (chain.mechanism_dof, chain.redundant_constraints) == (1, 0)


def test_fix_mjcf_planar_fourbar_weld_is_said_not_written(capsys, tmp_path):
    """A planar four-bar's weld keeps 3 equations (x, y, turn about z): no MuJoCo equality has them.

    MuJoCo itself shows why a connect is no fix: with the weld, 6 rows of rank 3 (4 hinges: 1 DoF); with a
    connect in its place, 3 rows of rank 2 (2 DoF: the rotation about z the weld held is free).
    """
    source = DATA / "fourbar_weld.xml"
    target = tmp_path / "fourbar.xml"
    status, out, _ = fix(capsys, source, "--output", target)
    assert status == 0 and "planar_weld" in out and "left a weld" in out and not target.exists()
    assert mujoco_rank(source) == (6, 3, 4)
    connect = tmp_path / "fourbar_connect_try.xml"
    connect.write_text(source.read_text().replace("<weld ", '<connect anchor="0 0 0" '))
    assert mujoco_rank(connect) == (3, 2, 4)


@pytest.mark.parametrize("robot", ["5bar_linkage", "robot_delta"])
def test_fix_extended_urdf_sidecar(capsys, tmp_path, robot):
    folder = tmp_path / robot
    shutil.copytree(ROBOTS / robot, folder)
    target = folder / "robot_minimal.yaml"
    status, out, _ = fix(capsys, folder / "robot.yaml", "--output", target)
    assert status == 0 and f"wrote {target}" in out and "LAAS tools" in out
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the robots' meshes are not in the tests' data: kinematics only
        before, after = pinmob.load(folder / "robot.yaml"), pinmob.load(target)
    assert {str(c.type) for c in after.closures} == {"planar_weld"}  # planar robots: every axis along z
    a = pinmob.analyze(before).mechanism_mobility
    b = pinmob.analyze(after, pinmob.analyze(before).state.q).mechanism_mobility
    assert b.redundant_constraints == 0 and b.rows == a.rank
    assert (b.mechanism_dof, b.idle_dof) == (a.mechanism_dof, a.idle_dof)


def test_sidecar_types_are_checked(tmp_path):
    folder = tmp_path / "five"
    shutil.copytree(ROBOTS / "5bar_linkage", folder)
    sidecar = folder / "robot.yaml"
    text = sidecar.read_text()
    bad = folder / "bad.yaml"
    bad.write_text(text + "\ntype: [hinge]\n" if "type:" not in text else text.replace("6d", "hinge"))
    with warnings.catch_warnings(), pytest.raises(pinmob.MechanismFileError, match="valid: '3d', '6d'"):
        warnings.simplefilter("ignore")
        pinmob.load(bad)


def test_output_refusals(capsys, tmp_path):
    source = tmp_path / "bennett.xml"
    shutil.copy(DATA / "bennett_weld.xml", source)
    original = source.read_bytes()
    link = tmp_path / "link.xml"
    link.symlink_to(source)
    hard = tmp_path / "hard.xml"
    os.link(source, hard)
    existing = tmp_path / "existing.xml"
    existing.write_text("keep")
    cases = [
        ([source], "is the input file"),
        ([source, "--force"], "is the input file"),
        ([link, "--force"], "is the input file"),
        ([hard, "--force"], "is the input file"),
        ([existing], "exists already"),
        ([tmp_path / "no" / "x.xml"], "does not exist"),
        ([tmp_path / "x.toml"], "needs the suffix .xml or .mjcf"),
    ]
    for args, words in cases:
        status, out, err = fix(capsys, source, "--output", *args)
        assert status == 2 and out == "" and words in err and err.count("\n") == 1, (args, err)
        assert err.startswith("pinmob: error: ") and "--output" in err
    assert source.read_bytes() == original and existing.read_text() == "keep"
    assert not (tmp_path / "no").exists()
    status, _, _ = fix(capsys, source, "--output", existing, "--force")
    assert status == 0 and "<connect" in existing.read_text()


def test_viewer_panel_shows_the_minimal_closures(tmp_path):
    """The panel's document has the report's lines under 'Minimal closures' (None where nothing is redundant)."""
    from pinmob import viewer

    scene = viewer.export_html(pinmob.load("3-RRR-spherical"), "generic", tmp_path / "s.html", steps=2)
    lines = scene.panel["minimal_closures"]
    assert lines[0] == "minimal closures: 12 closure equations of rank 6 -> 6 (full row rank)"
    assert any("limb B: 6d (6 equations) -> orientation" in line for line in lines)
    assert "Minimal closures" in (Path(viewer.__file__).parent / "static" / "panel.js").read_text()
    rigid = viewer.export_html(pinmob.load("Delta"), "generic", tmp_path / "d.html", steps=2)
    assert rigid.panel["minimal_closures"] is None


@pytest.mark.parametrize("name", sorted(pinmob.builtin_models()))
def test_every_builtin_fix_keeps_the_answers(name):
    """Where a built-in model has redundant equations at every named configuration, the fixed mechanism has the
    same DoF, idle motions, output motion types and configurations at each (check_fixed), with full row rank
    where the proposal was computed; where one configuration has none, there is nothing to fix."""
    mech = pinmob.load(name)
    config, minimal = pinmob.analysis.fixed_closures.chosen_proposal(mech)
    if minimal is None:
        assert pinmob.analyze(mech, config).mechanism_mobility.redundant_constraints == 0
        assert pinmob.fix_closures(mech) is mech
        return
    assert minimal.complete and minimal.proposed_rows == minimal.rank
    fixed = pinmob.fix_closures(mech, minimal)
    check = pinmob.check_fixed(mech, fixed)
    assert check.same, check.differences
    assert check.rows[check.configurations.index(config)][2] == 0


def test_redundancy_only_at_a_singular_configuration_is_not_fixed(capsys, tmp_path):
    """The 3-PUU-vertical has 2 redundant equations at 'vertical' (5 DoF, singular) and none at 'generic': dropping
    them would give 5 DoF at 'generic' too, so nothing is written, and the reason is said."""
    mech = pinmob.load("3-PUU-vertical")
    assert pinmob.analyze(mech, "vertical").mechanism_mobility.redundant_constraints == 2
    status, out, _ = fix(capsys, "3-PUU-vertical", "--output", tmp_path / "v.toml")
    assert status == 0 and not (tmp_path / "v.toml").exists()
    assert out == (
        f"3-PUU-vertical at 'generic': no closure equation is redundant (redundant ones only at 'vertical', singular "
        f"there); nothing to fix, {tmp_path / 'v.toml'} not written\n"
    )


def test_a_format_fix_does_not_write_is_refused(capsys, tmp_path):
    """An onshape-to-robot URDF (closing frames) has no closure declarations to rewrite: one line, exit 2."""
    status, out, err = fix(capsys, DATA / "cad_gaps" / "spherical_3rrr" / "robot.urdf", "--output", tmp_path / "x.toml")
    assert status == 2 and out == "" and err.count("\n") == 1
    assert "pinmob fix writes pinmob TOML, Extended URDF sidecars (.yaml) and MJCF (.xml)" in err


@pytest.mark.parametrize(
    ("name", "verdict"),
    [("3-RRR-planar", "3 DoF finite, 2T1R"), ("3-RRR-spherical", "3 DoF finite, 3R"), ("3-PRRR", "3 DoF finite, 3T")],
)
def test_the_finite_verdict_of_the_fixed_mechanism(name, verdict):
    """The fewer-row closures in the finite analysis (their cut chains): the same verdict as the file's (the
    3-RRRs' 2T1R and 3R and the 3-PRRR's 3T are finite motions: planar, spherical, translational)."""
    mech = pinmob.load(name)
    fixed = pinmob.fix_closures(mech)
    assert {str(c.type) for c in fixed.closures} & {"planar_weld", "orientation", "universal"}
    for m in (mech, fixed):
        assert pinmob.analyze(m, finite=True).brief().endswith(f"finite: platform {verdict}")


def test_fix_mjcf_weld_between_sites_becomes_a_connect_between_them(capsys, tmp_path):
    """The Bennett weld written between two sites (placed with MuJoCo at qpos0, where the weld holds): the connect
    keeps the sites (MuJoCo joins their origins), 3 rows of rank 3 in MuJoCo, 1 DoF in pinmob."""
    mujoco = pytest.importorskip("mujoco")
    source = DATA / "bennett_weld.xml"
    m = mujoco.MjModel.from_xml_path(str(source))
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    body = m.body("L4").id
    point = np.array([0.03, 0.02, 0.01])  # the weld's anchor, in the world
    rot = d.xmat[body].reshape(3, 3)
    pos = rot.T @ (point - d.xpos[body])
    quat = np.empty(4)
    mujoco.mju_negQuat(quat, d.xquat[body])  # the world's orientation seen from L4
    text = source.read_text()
    text = text.replace(
        '<geom type="capsule" fromto="0 0 0 -0.121841673465349 -0.0124340905241696 0" size="0.004" mass="0.05"/>',
        '<geom type="capsule" fromto="0 0 0 -0.121841673465349 -0.0124340905241696 0" size="0.004" mass="0.05"/>'
        f'<site name="s4" pos="{" ".join(f"{x:.17g}" for x in pos)}" quat="{" ".join(f"{x:.17g}" for x in quat)}"/>',
    )
    text = text.replace("<worldbody>", '<worldbody><site name="s0" pos="0.03 0.02 0.01"/>')
    text = text.replace(
        '<weld name="loop" body1="L4" body2="world" anchor="0.03 0.02 0.01"/>',
        '<weld name="loop" site1="s4" site2="s0"/>',
    )
    sites = tmp_path / "bennett_sites.xml"
    sites.write_text(text)
    assert mujoco_rank(sites)[:2] == (6, 3)
    target = tmp_path / "bennett_sites_connect.xml"
    status, out, _ = fix(capsys, sites, "--output", target)
    assert status == 0 and "loop: weld -> connect" in out
    assert '<connect name="loop" site1="s4" site2="s0"' in target.read_text()
    assert mujoco_rank(target)[:2] == (3, 3)
    chain = pinmob.analyze(pinmob.load(target), "reference").mechanism_mobility
    assert (chain.mechanism_dof, chain.redundant_constraints) == (1, 0)


def test_fix_mjcf_unnamed_weld(capsys, tmp_path):
    """An unnamed weld (pinmob's label equality#0) is found by its place among MuJoCo's equalities."""
    unnamed = tmp_path / "bennett_unnamed.xml"
    unnamed.write_text((DATA / "bennett_weld.xml").read_text().replace('<weld name="loop" ', "<weld "))
    target = tmp_path / "out.xml"
    status, out, _ = fix(capsys, unnamed, "--output", target)
    assert status == 0 and "equality#0: weld -> connect" in out
    assert '<connect body1="L4"' in target.read_text() and mujoco_rank(target)[:2] == (3, 3)


def test_redundant_couplings_are_kept_and_said(capsys, tmp_path):
    """tests/data/couplings/shaky_couplings.xml: a joint and a tendon coupling implied by the rest (rank 2 of 4);
    pinmob changes no coupling: the proposal says so and nothing is written."""
    status, out, _ = fix(capsys, DATA / "couplings" / "shaky_couplings.xml", "--output", tmp_path / "sc.xml")
    assert status == 0 and not (tmp_path / "sc.xml").exists()
    assert "a_down: joint (1 equation): keep (1 implied by the rest; a coupling is not changed)" in out
    assert "nothing to fix" in out


#: counts the times a process opens one file (an audit hook on ``open``: what the interpreter does, nothing replaced)
OPENS = textwrap.dedent("""
    import contextlib, io, os, sys
    from pathlib import Path

    source, output = Path(sys.argv[1]).resolve(), sys.argv[2]
    opened = []
    sys.addaudithook(
        lambda event, args: opened.append(1)
        if event == "open" and isinstance(args[0], (str, os.PathLike)) and Path(args[0]).resolve() == source
        else None
    )
    import pinmob
    from pinmob.cli import main

    pinmob.load(source)
    loading = len(opened)
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        status = main(["fix", str(source), "--output", output])
    print(status, loading, len(opened) - loading, Path(output).exists())
""")


@pytest.mark.parametrize(
    "files",
    [("models", "3prrr.toml", "3prrr.urdf"), ("example-parallel-robots/5bar_linkage", "robot.yaml", "robot.urdf")],
)
def test_fix_reads_its_input_once_more_than_loading_it(tmp_path, files):
    """``pinmob fix`` reads the pinmob TOML or the Extended URDF sidecar it fixes once more than loading the
    mechanism does: once for the output's checks (the URDF it names) and the writer together. Before, the TOML was
    read twice more (the URDF's path, then fixed_toml), the sidecar three times (sidecar_urdf twice, fixed_sidecar)."""
    folder, name, urdf = files
    src = (Path(pinmob.io.builtin_dir()) if folder == "models" else DATA / folder) / name
    for f in (name, urdf):
        shutil.copy(src.parent / f, tmp_path / f)
    out = tmp_path / ("fixed" + src.suffix)
    done = subprocess.run(
        [sys.executable, "-c", OPENS, str(tmp_path / name), str(out)], capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    status, loading, fixing, written = done.stdout.split()
    assert (status, written) == ("0", "True")  # a file with redundant closures: the writer ran
    assert int(loading) == 1 and int(fixing) == int(loading) + 1, done.stdout
