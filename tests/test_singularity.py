"""Singularity classes at one configuration, the analyze JSON section, and the batch path."""

from __future__ import annotations

import dataclasses
import json
import shutil
from collections import Counter
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest
from millimetres import in_millimetres
from numpy.testing import assert_allclose
from scipy.linalg import null_space

import pinmob
from pinmob import analyze_singularity
from pinmob.analysis.batch.batch_analysis import analyze_batch
from pinmob.analysis.generic import (
    dependent_limbs,
    generic_configurations,
    generic_constraint_rank,
    generic_twist_ranks,
)
from pinmob.analysis.limbs import limb_decisions, limb_twists
from pinmob.analysis.mobility import platform_mobility
from pinmob.analysis.singularity.classification import singularity
from pinmob.analysis.singularity.result import NEAR_FACTOR
from pinmob.cli import main
from pinmob.exceptions import ConfigurationError
from pinmob.io.builtin import builtin_models
from pinmob.model.mechanism import NamedConfiguration
from pinmob.screw.algebra import twist_scaling
from pinmob.screw.rank import RTOL


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
    qs = [pinmob.closed_configuration(mech, c) for c in mech.configurations]
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
        assert_allclose(batch.actuation_singular_values[i], np.nan_to_num(sing.actuation_singular_values), atol=1e-9)
        assert_allclose(batch.limb_ratio[i], [sing.distances[f"limb {b.name}"] for b in mech.limbs], atol=1e-9)
        # the scan's single kinematics computation gives the same two results
        conf = pinmob.Configuration(mech, q)
        mob2, sing2 = platform_mobility(conf, RTOL), singularity(conf, RTOL, sing.generic_rank)
        assert (mob2.dof, mob2.motion_type, sing2.label, sing2.distances) == (
            mob.dof,
            mob.motion_type,
            sing.label,
            sing.distances,
        )


def _tsai_at(x: float, y: float, z: float) -> tuple[pinmob.Mechanism, np.ndarray]:
    mech = pinmob.load("3-UPU")
    pose = pin.SE3(np.eye(3), np.array([x, y, z]))
    return mech, pinmob.assemble_pose(mech, pose, pinmob.closed_configuration(mech, "generic"))


def test_dependent_limbs_of_tsai_3upu_by_hand():
    """Tsai's 3-UPU translated to p: limb i exerts one couple c_i ~ (p.e_i - 0.15) e_i + p_z z (derivation in
    test_scan._tsai_couples). With p.e_A = p.e_B = 0.15, i.e. p_x = 0.15, p_y = 0.225 / (sqrt(3) / 2), the
    couples of A and B are both along z: the pair {A, B} lost a rank (1 instead of its generic 2), while
    {A, C} and {B, C} keep rank 2. The dependent limbs are A and B, not C; the three couples span {z, e_C}
    only (rank 2 < 3), and the platform gains the rotation about the horizontal axis normal to e_C. On the base
    plane (p_z = 0) the three couples are the three horizontal a_i e_i, pairwise independent: the only
    minimal deficient set is {A, B, C}."""
    mech, q = _tsai_at(0.15, 0.225 / (np.sqrt(3) / 2), 0.33)
    sing = analyze_singularity(mech, q)
    assert sing.constraint and sing.constraint_rank == 2 and sing.dependent_limbs == ("A", "B")
    assert sing.limbs == () and sing.rank_gap["constraint"] == 1
    free = pinmob.analyze(mech, q)
    rotations = [m for m in free.motions if m.kind.value == "R"]
    assert len(rotations) == 1 and free.dof == 4
    e_c = np.array([np.cos(4 * np.pi / 3), np.sin(4 * np.pi / 3), 0.0])
    assert_allclose(abs(rotations[0].direction @ e_c) + abs(rotations[0].direction[2]), 0.0, atol=1e-9)
    assert analyze_singularity(mech, "constraint-singular").dependent_limbs == ("A", "B", "C")


@pytest.mark.parametrize("name", pinmob.builtin_models())
def test_dependent_limbs_are_empty_at_generic_configurations(name):
    """No limb set of any built-in model is deficient at its 'generic' configuration or at random closed
    configurations (the old null-space rule named A, B, C, D of the 4-RUU, X, Y of Bennett, A, B of Sarrus)."""
    mech = pinmob.load(name)
    qs = generic_configurations(mech)[:3]
    if "generic" in mech.configurations:
        qs.append(pinmob.closed_configuration(mech, "generic"))
    for q in qs:
        twists = limb_twists(pinmob.Configuration(mech, q), RTOL)
        blocks = [d.null_space.T for d in limb_decisions(mech, twists, RTOL)]
        assert dependent_limbs(mech, blocks, RTOL, generic_constraint_rank(mech)) == ()


def _world_screws(model: pin.Model, data: pin.Data, q: np.ndarray, names, point: np.ndarray) -> list[np.ndarray]:
    """Joint screws [v; w] (one per velocity) of the named joints, at ``point``, from Pinocchio's joint
    placements and motion subspaces (not from frame Jacobians): S_j in the world, v += w x point."""
    cols = []
    for name in names:
        j = model.getJointId(name)
        jd = model.joints[j].createData()
        model.joints[j].calc(jd, q)
        for s in np.asarray(jd.S).reshape(6, -1).T:
            m = data.oMi[j].act(pin.Motion(s))
            cols.append(np.concatenate([m.linear + np.cross(m.angular, point), m.angular]))
    return cols


def _independent_screws(mech: pinmob.Mechanism, q: np.ndarray) -> list[tuple[np.ndarray, float]]:
    """Each limb's dimensionless screws U [v / L; w] at the platform origin p, as the limb distance sees them,
    and the ratio sigma_min / sigma_max of its loop rows (1 without loops): a tolerance above it changes which
    rates close the loops, hence U itself.

    A limb without loops: its joint screws (:func:`_world_screws`), unit columns. A limb with loops inside
    it (3d closures): the screws of its joints and loop joints that support its tip, times N, an orthonormal
    basis (scipy's null_space) of the dimensionless rates (prismatic rates times L) that keep every loop's
    two frames at one point to first order: sum over the joints supporting b of (v_j + w_j x x) minus the
    same over a, x the closure point, divided by L."""
    model, data = mech.model, mech.model.createData()
    pin.forwardKinematics(model, data, q)
    pin.updateFramePlacements(model, data)
    p = data.oMf[mech.platform_id].translation
    st = twist_scaling(mech.length_scale)[:, None]
    out = []
    for limb in mech.limbs:
        if not limb.closures:
            a = st * np.array(_world_screws(model, data, q, limb.joints, p)).T
            out.append((a / np.linalg.norm(a, axis=0), 1.0))
            continue
        names = limb.joints + limb.loop_joints
        ids = [model.getJointId(n) for n in names]
        col = np.array(
            [mech.length_scale if model.joints[j].shortname().startswith("JointModelP") else 1.0 for j in ids]
        )

        def supported(frame: str, ids: list[int] = ids) -> np.ndarray:
            chain = set(model.supports[model.frames[model.getFrameId(frame)].parentJoint])
            return np.array([j in chain for j in ids], float)

        rows = []
        for c in mech.closures:
            if c.name not in limb.closures:
                continue
            assert c.type == "3d", "the independent check covers point (3d) closures"
            x = data.oMf[c.frame_b_id].translation
            screws = np.array(_world_screws(model, data, q, names, x)).T[:3]
            rows.append(screws * (supported(c.frame_b) - supported(c.frame_a)) / mech.length_scale)
        k = np.vstack(rows) * col
        null = null_space(k, rcond=1e-9)
        s = np.linalg.svd(k, compute_uv=False)
        tip = np.array(_world_screws(model, data, q, names, p)).T * supported(model.frames[limb.tip_id].name)
        out.append((st * tip @ (col[:, None] * null), float(s[-1] / s[0])))
    return out


@pytest.mark.parametrize("name", pinmob.builtin_models())
def test_each_class_is_present_exactly_when_its_distance_is_at_most_rtol(name):
    """A class is decided on the very matrix its distance is read from (sigma_r / sigma_1 <= rtol <=> rank
    below r); the limb distance is that of the dimensionless screws [v / L; w] with unit columns, recomputed here
    from independent screws. Near-singular: no class, distance below 1e3 rtol. Moving rtol across a limb's
    distance moves its decision with it (a decision on other columns than the distance's was up to 2x off), as
    long as the tolerance stays below the ratio of the limb's own loop rows."""
    mech = pinmob.load(name)
    for config in mech.configurations:
        q = pinmob.closed_configuration(mech, config)
        sing = analyze_singularity(mech, q)
        d = sing.distances
        for limb, r, (u, _) in zip(mech.limbs, generic_twist_ranks(mech), _independent_screws(mech, q)):
            s = np.linalg.svd(u, compute_uv=False)
            assert d[f"limb {limb.name}"] == pytest.approx(s[r - 1] / s[0] if s.size >= r else 0.0, abs=1e-9)
            assert (limb.name in sing.limbs) == (d[f"limb {limb.name}"] <= RTOL)
            assert sing.rank_gap[f"limb {limb.name}"] == max(0, r - int(np.sum(s > RTOL * s[0])))
        assert sing.constraint == (d.get("constraint", 1.0) <= RTOL)
        assert sing.actuation == (d["actuation"] <= RTOL if mech.actuated else None)
        assert sing.near_singular == (not sing.classes and sing.distance < NEAR_FACTOR * RTOL)
    # with the tolerance just above / just below a limb's distance, that limb is flagged / not flagged
    q = pinmob.closed_configuration(mech, next(iter(mech.configurations)))
    base = analyze_singularity(mech, q)
    for limb, (_, loop_ratio) in zip(mech.limbs, _independent_screws(mech, q)):
        value = base.distances[f"limb {limb.name}"]
        if not 1e-9 < value < 0.8:  # a tolerance must lie in (0, 1)
            continue
        for rtol, present in ((1.2 * value, True), (value / 1.2, False)):
            if rtol >= loop_ratio:  # the loops' own decision would change too (the Delta's parallelograms)
                continue
            sing = analyze_singularity(mech, q, rtol=rtol, generic_rank=base.generic_rank)
            assert (limb.name in sing.limbs) == present, (limb.name, value, rtol)
            assert sing.distances[f"limb {limb.name}"] == pytest.approx(value, rel=1e-9)


def _in_millimetres(mech: pinmob.Mechanism, q: np.ndarray) -> tuple[pinmob.Mechanism, np.ndarray]:
    """The mechanism in millimetres (tests/millimetres.py) with its actuation, q with prismatic joints x 1000,
    and its named configurations as joint values (the generic rank is then estimated from the millimetre model)."""
    mm = in_millimetres(mech)
    mm = dataclasses.replace(
        mm, limbs=tuple(dataclasses.replace(b, actuated=a.actuated) for a, b in zip(mech.limbs, mm.limbs))
    )
    model = mech.model
    prismatic = [
        model.joints[j].idx_q for j in range(1, model.njoints) if model.joints[j].shortname().startswith("JointModelP")
    ]

    def scaled(x: np.ndarray) -> np.ndarray:
        x = x.copy()
        x[prismatic] *= 1000
        return x

    configurations = {}
    for name in mech.configurations:
        x = scaled(pinmob.closed_configuration(mech, name))
        joints = {model.names[j]: float(x[model.joints[j].idx_q]) for j in range(1, model.njoints)}
        configurations[name] = NamedConfiguration(name, joints=joints)
    return dataclasses.replace(mm, configurations=configurations), scaled(q)


@pytest.mark.parametrize(
    ("name", "config"),
    [("6-UPS", "type2"), ("6-UPS", "generic"), ("3-PUU", "generic"), ("3-UPU", "constraint-singular"),
     ("3-UPU", "generic"), ("five-bar", "limb-B-stretched"), ("4-RUU", "generic"), ("3-UR5", "wrist-singular")],
)  # fmt: skip
def test_singularity_report_is_unit_invariant(name, config):
    """The same mechanism drawn in millimetres gives the same classes, limbs, joints, uncontrolled motions and
    distances (ratios of singular values of dimensionless matrices), and the same generic rank estimated again
    from the millimetre model. Prismatic joint rates in mm/s make those screws 1000 times shorter relative to the
    revolute ones: the unit columns make the limb decisions blind to that."""
    mech = pinmob.load(name)
    q = pinmob.closed_configuration(mech, config)
    a = analyze_singularity(mech, q)
    mm, q_mm = _in_millimetres(mech, q)
    assert mm.length_scale == pytest.approx(1000 * mech.length_scale)
    b = analyze_singularity(mm, q_mm)
    assert (b.label, b.limbs, b.limb_joints, b.dependent_limbs) == (a.label, a.limbs, a.limb_joints, a.dependent_limbs)
    assert (b.generic_rank, b.locked_dof, b.near_singular) == (a.generic_rank, a.locked_dof, a.near_singular)
    assert [m.label for m in b.uncontrolled] == [m.label for m in a.uncontrolled]
    assert b.distances.keys() == a.distances.keys()
    assert_allclose(list(b.distances.values()), list(a.distances.values()), rtol=1e-6, atol=1e-10)


def test_without_actuated_joints_actuation_does_not_apply(capsys):
    """Bennett with its actuator removed: nothing is locked, so no motion is 'uncontrolled'."""
    mech = pinmob.load("Bennett")
    mech = dataclasses.replace(mech, limbs=tuple(dataclasses.replace(b, actuated=()) for b in mech.limbs))
    sing = analyze_singularity(mech, "generic")
    assert sing.actuation is None and sing.uncontrolled == () and "actuation" not in sing.distances
    assert sing.locked_dof == 1 and sing.to_dict()["actuation"] is None
    assert "not applicable" in str(sing)


def test_generic_ranks_are_cached_per_tolerance():
    """With rtol = 0.1 (loose tolerance 0.32) a 3-PUU limb's twist rank counts 4, two wrenches each: the estimate
    is 5, not the 3 found with the default tolerance, whatever was asked first."""
    mech = pinmob.load("3-PUU")
    assert generic_constraint_rank(mech) == 3
    assert generic_constraint_rank(mech, rtol=0.1) == 5
    assert generic_constraint_rank(mech) == 3


def test_generic_ranks_stop_only_where_the_rest_cannot_change_the_mode():
    """generic_set_ranks stops ranking once the configurations left cannot change the most frequent rank (ties: the
    larger): over every sequence of up to 6 ranks from 2 to 4, the mode where it stops is the whole sequence's."""
    from itertools import product

    from pinmob.analysis.generic import _decided, _mode

    stopped_early = 0
    for n in range(1, 7):
        for ranks in product((2, 3, 4), repeat=n):
            counts: Counter[int] = Counter()
            for i, r in enumerate(ranks):
                counts[r] += 1
                if _decided(counts, n - 1 - i):
                    stopped_early += i < n - 1
                    break
            whole = Counter(ranks)
            assert _mode(counts) == max(whole, key=lambda r: (whole[r], r)), ranks
    assert stopped_early > 0


def test_mechanisms_without_platform_are_refused_clearly():
    mech = pinmob.load(Path(__file__).parent / "data" / "fivebar" / "robot.yaml")
    with pytest.raises(ConfigurationError, match="platform frame.*Extended URDF, MJCF"):
        analyze_singularity(mech, mech.neutral())


def _rank(screws: np.ndarray, rtol: float) -> int:
    """Rank by numpy's own SVD count, on unit columns (the joint rates' units removed)."""
    if screws.size == 0:
        return 0
    unit = screws / np.maximum(np.linalg.norm(screws, axis=0), 1e-300)
    s = np.linalg.svd(unit, compute_uv=False)
    return int(np.sum(s > rtol * s[0])) if s[0] > 0 else 0


def test_actuation_wrenches_count_what_locking_the_actuators_adds():
    """Each actuated limb adds as many actuation wrenches as locking its actuators lowers its twist rank.

    Reciprocity: the limb's wrench space has dimension 6 - r, with its actuators locked 6 - r_locked; the
    actuation wrenches span what locking adds, r - r_locked of them (ranks counted here by numpy's SVD of
    the unit-column screws), each reciprocal to the limb's locked screws. Where an actuator's screw depends
    on the others (3-PUU-flat at flat, the Delta with stretched arms, a stretched five-bar limb...), locking
    it adds nothing: the difference of the two bases is round-off (5e-16) and was once decided relative to
    itself, giving up to two noise wrenches per limb.
    """
    checked = singular = 0
    for name in builtin_models():
        mech = pinmob.load(name)
        if not mech.limbs or not mech.actuated or mech.coupling_closures or not mech.has_platform:
            continue
        if any(limb.closures for limb in mech.limbs):
            continue  # screws per loop-closing rate combination, not per joint: no unit columns to count on
        st = twist_scaling(mech.length_scale)[:, None]
        sw = np.array([mech.length_scale] * 3 + [1.0] * 3)[:, None]
        for config in mech.configurations:
            conf = pinmob.Configuration(mech, config)
            rtol = conf.rank_rtol(RTOL)
            wrenches = sw * singularity(conf, rtol).actuation_wrenches  # dimensionless [f L; tau]
            free, locked = limb_twists(conf, rtol), limb_twists(conf, rtol, lock_actuated=True)
            start = 0
            for limb, t, lt in zip(mech.limbs, free, locked):
                if not limb.actuated:
                    continue
                count = _rank(st * t, rtol) - _rank(st * lt, rtol)
                own = wrenches[:, start : start + count]
                assert own.shape[1] == count, (name, config, limb.name)
                assert_allclose(own.T @ (st * lt), 0.0, atol=1e-8)  # reciprocal to the limb's locked screws
                singular += count == 0
                start += count
            assert wrenches.shape[1] == start, (name, config)
            checked += 1
    assert checked > 20 and singular > 5


def test_a_distance_at_a_singularity_prints_as_at_most_the_tolerance():
    """At a singularity the distance is round-off (1.34e-15 or 1.06e-15 for the 6-UPS turned 90 degrees, by the BLAS
    kernel): the text prints ``<= 1e-06`` (the tolerance), as the scan's rows do, and the JSON keeps the figure."""
    report = pinmob.analyze(pinmob.load("6-UPS"), "type2")
    sing = report.to_dict()["singularity"]
    assert sing["distance"] <= 1e-6 and sing["distances"]["actuation"] <= 1e-6
    text = str(report)
    assert "singularity: actuation (distance <= 1e-06, closest: actuation;" in text
    assert ", actuation <= 1e-06" in text and "e-15" not in text and "e-16" not in text


def test_tests_singular_together_tie_whatever_their_round_off():
    """At the 3-UPU's constraint singularity the constraint and the actuation are both singular: their distances
    are round-off (~1e-15, in an order round-off decides), so both are closest and a scan row names the first,
    ``constraint``; a distance 1e-12 or 1e-5 of itself above the smallest does not tie."""
    from pinmob.analysis import tied

    mech = pinmob.load("3-UPU")
    sing = pinmob.analyze_singularity(mech, pinmob.closed_configuration(mech, "constraint-singular"))
    assert sing.closest_all == ("constraint", "actuation")
    assert tied(2.9e-15, 1.3e-15) and tied(1.3e-15, 2.9e-15) and tied(0.1 * (1 + 5e-7), 0.1)
    assert not tied(1e-12, 0.0) and not tied(0.1 * (1 + 1e-5), 0.1)
