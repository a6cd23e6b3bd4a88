"""Singularity classes at one configuration, the analyze JSON section, and the batch path."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.batch import analyze_batch
from pinmob.cli import main
from pinmob.mechanism_file import builtin_models
from pinmob.singularity import analyze_singularity, generic_constraint_rank


def test_three_puu_generic_is_not_singular():
    mech = pinmob.load("3-PUU")
    # seed paper, eq. 19/38: one couple per limb, three independent couples
    assert generic_constraint_rank(mech) == 3
    for config in mech.configurations:
        sing = analyze_singularity(mech, config)
        assert sing.classes == () and sing.label == "none"
        assert sing.locked_dof == 0 and sing.uncontrolled == ()
        assert 0.05 < sing.distance <= 1.0


def test_vertical_links_are_a_constraint_singularity():
    # beta = pi/2: the three couples t_i x n_i are all along z (rank 1 < 3), the platform gains 2 rotations
    mech = pinmob.load("3-PUU-vertical")
    sing = analyze_singularity(mech, "vertical")
    assert sing.constraint and sing.constraint_rank == 1 and sing.generic_rank == 3
    assert sing.rank_gap["constraint"] == 2
    assert sing.dependent_limbs == ("A", "B", "C")
    assert sing.distances["constraint"] < 1e-12


def test_flat_is_a_limb_singularity_of_every_limb():
    # beta = 0: the slider (along z) is the difference of the two parallel horizontal U axes t_i (a
    # translation along z), so each limb's twist rank drops from 5 to 4 and its slider cannot act
    mech = pinmob.load("3-PUU-flat")
    sing = analyze_singularity(mech, "flat")
    assert sing.limbs == ("A", "B", "C")
    for limb in "ABC":
        assert set(sing.limb_joints[limb]) == {f"{limb}_slider", f"{limb}_u1a", f"{limb}_u2b"}
    assert sing.actuation is True and sing.locked_dof == 2
    assert sorted(m.kind.value for m in sing.uncontrolled) == ["R", "T"]


def test_analyze_json_has_the_singularity_section(capsys):
    assert main(["analyze", "6-UPS", "-c", "type2", "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    s = out["singularity"]
    for key in ("constraint", "actuation", "limbs", "locked_dof", "uncontrolled", "distance", "generic_rank"):
        assert key in s
    assert s["constraint"] is False and s["actuation"] is True and s["limbs"] == []
    assert s["locked_dof"] == 1 and len(s["uncontrolled"]) == 1 and s["generic_rank"] == 0
    assert s["uncontrolled"][0]["kind"] in ("R", "H")
    assert main(["analyze", "3-PUU"]) == 0
    text = capsys.readouterr().out
    assert "singularity: none" in text and "actuation (Type II): no" in text


def test_declared_generic_rank_is_used(tmp_path):
    src = builtin_models()["3-PUU"]
    shutil.copy(src.with_suffix(".urdf"), tmp_path / src.with_suffix(".urdf").name)
    text = src.read_text().replace('platform = "platform"', 'platform = "platform"\ngeneric_rank = 4')
    (tmp_path / "m.toml").write_text(text)
    mech = pinmob.load(tmp_path / "m.toml")
    assert mech.generic_rank == 4
    sing = analyze_singularity(mech, "generic")
    assert sing.generic_rank == 4 and sing.constraint  # rank 3 < declared 4
    (tmp_path / "bad.toml").write_text(text.replace("generic_rank = 4", "generic_rank = 7"))
    with pytest.raises(pinmob.PinmobError, match="generic_rank"):
        pinmob.load(tmp_path / "bad.toml")


@pytest.mark.parametrize("name", pinmob.builtin_models())
def test_batch_agrees_with_single_analyses(name):
    """The compiled batch loop gives the ranks, DoF and singular values of the per-configuration SVDs."""
    mech = pinmob.load(name)
    rng = np.random.default_rng(7)
    qs = [mech.configuration(c) for c in mech.configurations]
    q0 = qs[0]
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, q0)
    base = pin.SE3(data.oMf[mech.platform_id])
    for _ in range(6 if name in ("3-PUU", "6-UPS") else 0):
        delta = np.concatenate(
            [rng.uniform(-0.02, 0.02, 3), rng.uniform(-0.05, 0.05, 3) if name == "6-UPS" else np.zeros(3)]
        )
        qs.append(pinmob.assemble_pose(mech, base * pin.exp6(delta), q0))
    qs = np.array(qs)
    batch = analyze_batch(mech, qs, singular_values=True)
    for i, q in enumerate(qs):
        mob = pinmob.analyze(mech, q)
        sing = analyze_singularity(mech, q)
        assert batch.dof[i] == mob.dof
        assert list(batch.limb_twist_rank[i]) == [limb.twist_rank for limb in mob.limbs]
        assert batch.locked_dof[i] == sing.locked_dof
        assert_allclose(batch.singular_values[i], mob.singular_values, atol=1e-9)
        assert_allclose(batch.actuation_singular_values[i], sing.actuation_singular_values, atol=1e-9)
