"""MJCF files whose mesh (or texture) files are missing, Git LFS pointers, or outside the model's folders (issue 22).

MuJoCo refuses to compile a model whose mesh file it cannot open; kinematics needs no mesh. pinmob compiles
such a model without those meshes, with one warning, and its kinematics must be MuJoCo's for the complete
model: the truth is MuJoCo's own compile of the file with its meshes (body and site placements ``xpos``,
``xmat``, ``site_xpos`` at its reference pose) and the analysis of the complete model.
"""

from __future__ import annotations

import os
import shutil
import struct
import warnings
from pathlib import Path

import mujoco
import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.cli import main
from pinmob.exceptions import MechanismFileError
from pinmob.io.mjcf import compile_mjcf
from pinmob.model.joints import frame_id

HAND = Path(__file__).parent / "data" / "third_party" / "menagerie_xarm7_hand"
COUNTS = (
    "nv",
    "closure_rows",
    "closure_rank",
    "mechanism_dof",
    "idle_dof",
    "redundant_constraints",
    "redundant_by_closure",
    "grubler",
    "configuration",
)


def load_warned(path: Path) -> tuple[pinmob.Mechanism, list[str]]:
    """The mechanism and the warnings its loading and drawing gave (the drawing has no mesh)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mech = pinmob.load(path)
        visual = mech.visual_model  # the drawing (from the model compiled at load): no second warning
    assert visual is None or not any(g.meshPath for g in visual.geometryObjects)  # no mesh drawn
    return mech, [str(w.message) for w in caught]


def hand_without_meshes(tmp_path: Path, lfs: bool = False) -> Path:
    """hand.xml copied alone (no assets folder), or with each mesh replaced by a Git LFS pointer."""
    shutil.copy(HAND / "hand.xml", tmp_path / "hand.xml")
    if lfs:
        (tmp_path / "assets").mkdir()
        for stl in (HAND / "assets").glob("*.stl"):
            (tmp_path / "assets" / stl.name).write_text(
                "version https://git-lfs.github.com/spec/v1\noid sha256:" + "0" * 64 + "\nsize 123456\n"
            )
    return tmp_path / "hand.xml"


@pytest.mark.parametrize("lfs", [False, True], ids=["missing", "lfs-pointers"])
def test_missing_meshes_cost_only_the_drawing(lfs, tmp_path):
    """Without its 7 STL files (or with Git LFS pointers in their place) the xArm7 hand loads with one warning
    naming the count and the first file, and gives the complete model's analysis and MuJoCo's placements of every
    body and site at the reference pose. On the old code: 'MuJoCo cannot compile it: Error opening file'."""
    path = hand_without_meshes(tmp_path, lfs)
    mech, said = load_warned(path)
    assert len(said) == 1, said
    reason = "are Git LFS pointers (run git lfs pull)" if lfs else "missing"
    assert said[0].startswith(f"hand.xml: 7 mesh file(s) {reason}, first 'assets/base_link.stl'")
    full = pinmob.load(HAND / "hand.xml")
    doc, ref = pinmob.analyze(mech).to_dict(), pinmob.analyze(full).to_dict()
    assert {k: doc[k] for k in COUNTS} == {k: ref[k] for k in COUNTS}
    assert doc["actuation"] == ref["actuation"] and doc["joint_values"] == ref["joint_values"]

    m = mujoco.MjModel.from_xml_path(str(HAND / "hand.xml"))  # MuJoCo, with the meshes
    d = mujoco.MjData(m)
    mujoco.mj_forward(m, d)
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, np.array(mech.configurations["reference"].vector))
    for b in range(1, m.nbody):
        placement = data.oMf[frame_id(mech.model, mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b))]
        assert_allclose(placement.translation, d.xpos[b], atol=1e-12)
        assert_allclose(placement.rotation, d.xmat[b].reshape(3, 3), atol=1e-12)
    for s in range(m.nsite):
        placement = data.oMf[frame_id(mech.model, mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_SITE, s))]
        assert_allclose(placement.translation, d.site_xpos[s], atol=1e-12)


def test_cli_warns_once_and_analyses(tmp_path, capsys):
    path = hand_without_meshes(tmp_path)
    assert main(["analyze", str(path)]) == 0
    out, err = capsys.readouterr()
    assert err.count("pinmob: warning: hand.xml: 7 mesh file(s) missing") == 1 and err.count("\n") == 1
    assert "xarm7 hand at 'reference': mechanism DoF 1 (nv 6 - closure rank 5)" in out


def stl(path: Path) -> None:
    """A binary STL tetrahedron (what MuJoCo reads)."""
    v = np.array([[0, 0, 0], [0.1, 0, 0], [0, 0.1, 0], [0, 0, 0.1]], np.float32)
    faces = [(0, 2, 1), (0, 1, 3), (0, 3, 2), (1, 2, 3)]
    body = b"".join(struct.pack("<3f", 0, 0, 0) + v[list(f)].tobytes() + b"\0\0" for f in faces)
    path.write_bytes(b"\0" * 80 + struct.pack("<I", len(faces)) + body)


def pendulum(mesh: str, texture: str = "") -> str:
    """Two hinged links closed by a weld, each drawn with ``mesh`` (and a material with ``texture``)."""
    material = f'<texture name="t" type="2d" file="{texture}"/><material name="mat" texture="t"/>' if texture else ""
    geom = f'<geom type="mesh" mesh="m"{" material=" + chr(34) + "mat" + chr(34) if texture else ""}/>'
    return (
        f'<mujoco model="pendulum"><asset><mesh name="m" file="{mesh}"/>{material}</asset><worldbody>'
        f'<body name="a"><joint name="ja" axis="0 0 1"/>{geom}'
        f'<body name="b" pos="0.1 0 0"><joint name="jb" axis="0 0 1"/>{geom}<site name="tip" pos="0.1 0 0"/>'
        "</body></body></worldbody>"
        '<equality><connect name="pin" site1="tip" site2="anchor"/></equality>'
        '<worldbody><site name="anchor" pos="0.2 0 0"/></worldbody></mujoco>'
    )


@pytest.mark.parametrize("where", ["absolute", "climbing", "symlink"])
def test_a_mesh_outside_the_models_folder_is_not_read(where, tmp_path):
    """A mesh whose file resolves outside the model's folder (an absolute path, ``../``, a symbolic link) is
    never given to MuJoCo: the compiled model has no mesh (on the old code it had the outside file's), the
    warning says why, the analysis is the one of the same model with the mesh inside."""
    (tmp_path / "secret").mkdir()
    (tmp_path / "model").mkdir()
    stl(tmp_path / "secret" / "key.stl")
    mesh = {"absolute": str(tmp_path / "secret" / "key.stl"), "climbing": "../secret/key.stl", "symlink": "link.stl"}
    if where == "symlink":
        os.symlink(tmp_path / "secret" / "key.stl", tmp_path / "model" / "link.stl")
    path = tmp_path / "model" / "pendulum.xml"
    path.write_text(pendulum(mesh[where]))
    with pytest.warns(UserWarning, match=r"1 mesh file\(s\) outside the model's folders \(not read\)") as caught:
        m = compile_mjcf(path)
    assert len(caught) == 1 and m.nmesh == 0 and m.ngeom == 2  # the geoms are kept, without a mesh
    stl(tmp_path / "model" / "inside.stl")
    (tmp_path / "model" / "inside.xml").write_text(pendulum("inside.stl"))
    assert compile_mjcf(tmp_path / "model" / "inside.xml").nmesh == 1  # a mesh in the folder is read
    with pytest.warns(UserWarning):
        doc = pinmob.analyze(pinmob.load(path)).to_dict()
    ref = pinmob.analyze(pinmob.load(tmp_path / "model" / "inside.xml")).to_dict()
    assert {k: doc[k] for k in COUNTS if k != "configuration"} == {k: ref[k] for k in COUNTS if k != "configuration"}


def test_a_garbage_file_outside_is_not_read(tmp_path):
    """Outside the folder, a file MuJoCo cannot parse as a mesh does not stop the load (it is not opened)."""
    (tmp_path / "model").mkdir()
    (tmp_path / "notes.stl").write_text("not a mesh")
    path = tmp_path / "model" / "pendulum.xml"
    path.write_text(pendulum("../notes.stl"))
    with pytest.warns(UserWarning, match="outside the model's folders"):
        assert pinmob.load(path).model.nq == 2


def test_missing_texture_is_left_out(tmp_path):
    """A missing texture file (also refused by MuJoCo) is left out like a missing mesh; a mesh there is read."""
    stl(tmp_path / "m.stl")
    path = tmp_path / "pendulum.xml"
    path.write_text(pendulum("m.stl", texture="textures/wood.png"))
    with pytest.raises(ValueError, match="wood.png"):
        mujoco.MjModel.from_xml_path(str(path))  # MuJoCo refuses it
    with pytest.warns(UserWarning, match=r"1 texture file\(s\) missing, first 'textures/wood.png'"):
        m = compile_mjcf(path)
    assert m.nmesh == 1 and m.ntex == 0


def test_a_broken_mesh_file_is_still_an_error(tmp_path):
    """A mesh file that is there but is no mesh is MuJoCo's error, as before (only missing files are left out)."""
    (tmp_path / "m.stl").write_text("solid nothing")
    path = tmp_path / "pendulum.xml"
    path.write_text(pendulum("m.stl"))
    with pytest.raises(MechanismFileError, match="MuJoCo cannot compile it"):
        pinmob.load(path)


TERRAIN = """<mujoco model="terrain">
  <asset>{field}</asset>
  <worldbody>{floor}
    <body name="a"><joint name="j1" axis="0 0 1"/><geom type="sphere" size="0.01"/>
      <body name="b" pos="1 0 0"><joint name="j2" axis="0 0 1"/><geom type="sphere" size="0.01"/>
        <site name="tip" pos="1 0 0"/></body></body>
    <body name="c" pos="1.5 0.5 0"><joint name="j3" axis="0 0 1"/><geom type="sphere" size="0.01"/>
      <site name="end" pos="0.5 0 0"/>{skin}</body>
  </worldbody>
  <equality><connect site1="tip" site2="end"/></equality>
</mujoco>"""


def test_a_missing_height_field_and_a_skin_outside_cost_only_the_drawing(tmp_path):
    """A height field whose image is missing (MuJoCo: 'Error opening file') and a skin file outside the model's
    folder: compiled without them, one warning naming both, the same analysis as the file without them."""
    field = '<hfield name="ground" file="terrain.png" size="1 1 0.1 0.01"/>'
    (tmp_path / "m").mkdir()
    path = tmp_path / "m" / "terrain.xml"
    path.write_text(
        TERRAIN.format(field=field, floor='<geom type="hfield" hfield="ground"/>', skin="").replace(
            "</asset>", '</asset><deformable><skin name="s" file="../outside.skn"/></deformable>'
        )
    )
    (tmp_path / "outside.skn").write_bytes(b"not read")
    plain = tmp_path / "m" / "plain.xml"
    plain.write_text(TERRAIN.format(field="", floor="", skin=""))
    with pytest.raises(ValueError, match=r"outside\.skn|terrain\.png"):
        mujoco.MjModel.from_xml_path(str(path))  # what MuJoCo says of the file as it is
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mech = pinmob.load(path)
    said = [str(w.message) for w in caught]
    assert len(said) == 1 and "1 height-field file(s) missing, first 'terrain.png'" in said[0], said
    assert "1 skin file(s) outside the model's folders (not read)" in said[0], said
    got, ref = pinmob.analyze(mech).to_dict(), pinmob.analyze(pinmob.load(plain)).to_dict()
    for key in ("mechanism_dof", "redundant_constraints", "joint_values"):
        assert got[key] == ref[key], key


def test_an_mjcf_is_compiled_once_when_loaded_and_drawn(monkeypatch: pytest.MonkeyPatch) -> None:
    """Loading the four-bar and drawing it compiles the file once (MuJoCo's MjSpec.compile counted); the old code
    compiled it again to draw it (2). A pickled copy (a Dask worker's) holds no compiled model: it compiles once
    when it draws, and draws the same geoms."""
    import pickle

    calls = {"compile": 0}
    real = mujoco.MjSpec.compile

    def counted(spec: mujoco.MjSpec) -> mujoco.MjModel:
        calls["compile"] += 1
        return real(spec)

    monkeypatch.setattr(mujoco.MjSpec, "compile", counted)
    path = Path(__file__).parent / "data" / "fourbar_connect.xml"
    mech = pinmob.load(path)
    copy = pickle.loads(pickle.dumps(mech))
    visual = mech.visual_model
    assert visual is not None and calls["compile"] == 1
    assert mujoco.MjModel.from_xml_path(str(path)).ngeom == visual.ngeoms == 3  # MuJoCo's geoms, one per capsule
    assert copy.visual_model is not None and calls["compile"] == 2
    assert [g.name for g in copy.visual_model.geometryObjects] == [g.name for g in visual.geometryObjects]
