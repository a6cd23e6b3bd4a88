"""Every answer is invariant under a rigid move of the whole mechanism and a change of length unit (issue 14).

Property tests over the built-in models and their named configurations: the mechanism moved by a
random rigid placement of its base (up to 10 m away, any orientation), or written in a unit of
length from micrometres (lengths x 1e6) to kilometres (x 1e-3), gives the answer of the unmoved,
metre model (the independent truth): DoF, motion type, constraint rank, mechanism DoF, redundant
closure equations, idle motions, singularity classes and generic rank, rank gaps, distances to
singularity; pitches scale with the unit and not with the placement. The length scale L is the
same after a move and scales with the unit. The regressions the issue found are pinned as examples.
"""

from __future__ import annotations

import functools
import sys
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

import pinmob
from pinmob.io.builtin import builtin_models

sys.path.insert(0, str(Path(__file__).parent))
from millimetres import in_units, placed, q_in_units  # noqa: E402

NAMES = sorted(model for model in builtin_models())
SETTINGS = settings(
    max_examples=100, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow], database=None
)


@functools.cache
def model(name: str) -> pinmob.Mechanism:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a model without meshes
        return pinmob.load(name)


@functools.cache
def truth(name: str, config: str) -> dict[str, Any]:
    mech = model(name)
    return pinmob.analyze(mech, config).to_dict()


def answer(mech: pinmob.Mechanism, config: str) -> dict[str, Any]:
    return pinmob.analyze(mech, config).to_dict()


def verdicts(d: dict[str, Any]) -> tuple:
    """What must not change: counts, types, classes."""
    s = d["singularity"]
    return (
        d["dof"],
        d["motion_type"],
        d["constraint_rank"],
        d["mechanism_dof"],
        d["redundant_constraints"],
        d["redundant_by_closure"],
        d["idle_dof"],
        [m["kind"] for m in d["motions"]],
        [(limb["name"], limb["twist_rank"]) for limb in d["limbs"]],
        s["classes"],
        s["generic_rank"],
        s["locked_dof"],
        s["rank_gap"],
        s["near_singular"],
    )


def same_answer(got: dict[str, Any], ref: dict[str, Any], factor: float) -> None:
    assert verdicts(got) == verdicts(ref)
    s, r = got["singularity"], ref["singularity"]
    assert_allclose([s["distances"][k] for k in r["distances"]], list(r["distances"].values()), atol=1e-6)
    pitches = [m["pitch"] if m["pitch"] is not None else 0.0 for m in got["motions"]]
    truth_pitches = [m["pitch"] * factor if m["pitch"] is not None else 0.0 for m in ref["motions"]]
    assert_allclose(pitches, truth_pitches, rtol=1e-6, atol=1e-9 * factor)


@st.composite
def model_and_configuration(draw: st.DrawFn) -> tuple[str, str]:
    name = draw(st.sampled_from(NAMES))
    return name, draw(st.sampled_from(sorted(model(name).configurations)))


placements = st.builds(
    lambda rpy, xyz: pin.SE3(pin.rpy.rpyToMatrix(*rpy), np.array(xyz)),
    st.tuples(*[st.floats(-np.pi, np.pi)] * 3),
    st.tuples(*[st.floats(-10.0, 10.0)] * 3),
)


@SETTINGS
@given(case=model_and_configuration(), placement=placements)
@example(case=("Sarrus", "generic"), placement=pin.SE3(np.eye(3), np.array([0.0, 0.0, 3.0])))
@example(case=("five-bar", "generic"), placement=pin.SE3(np.eye(3), np.array([0.0, 0.0, 3.0])))
def test_a_rigid_move_of_the_whole_mechanism_changes_no_answer(case: tuple[str, str], placement: pin.SE3) -> None:
    name, config = case
    mech = model(name)
    moved = placed(mech, placement)
    assert_allclose(moved.length_scale, mech.length_scale, rtol=1e-9)
    same_answer(answer(moved, config), truth(name, config), 1.0)


@SETTINGS
@given(case=model_and_configuration(), exponent=st.floats(-3.0, 6.0))
@example(case=("6-UPS", "home"), exponent=6.0)
@example(case=("6-UPS", "type2"), exponent=6.0)
@example(case=("3-PUU", "generic"), exponent=6.0)
@example(case=("3-UPU", "generic"), exponent=-3.0)
@example(case=("3-RPS", "home"), exponent=6.0)
@example(case=("3-PRS", "home"), exponent=-3.0)
def test_a_change_of_length_unit_changes_no_answer(case: tuple[str, str], exponent: float) -> None:
    name, config = case
    factor = 10.0**exponent  # micrometres (x 1e6) to kilometres (x 1e-3)
    mech = model(name)
    scaled = in_units(mech, factor, configurations=True)
    assert_allclose(scaled.length_scale, mech.length_scale * factor, rtol=1e-9)
    same_answer(answer(scaled, config), truth(name, config), factor)


@pytest.mark.parametrize("factor", [1e-6, 1e9])
def test_six_ups_far_outside_the_usual_units(factor: float) -> None:
    """Beyond micrometres and kilometres the rank decisions still see the same numbers."""
    mech = model("6-UPS")
    got = answer(in_units(mech, factor, configurations=True), "home")
    assert (got["dof"], got["motion_type"]) == (6, "3T3R")


@pytest.mark.parametrize("engine", ["numpy", "numba"])
def test_the_batch_path_equals_the_single_path_in_micrometres(engine: str) -> None:
    """The scan's batch engines make prismatic columns dimensionless as the single path does."""
    from pinmob.analysis.batch.batch_analysis import analyze_batch

    for name in ("3-PUU", "6-UPS", "3-RPS"):
        mech = model(name)
        scaled = in_units(mech, 1e6, configurations=True)
        qs = np.array([q_in_units(mech, pinmob.Configuration(mech, c).q, 1e6) for c in sorted(mech.configurations)])
        batch = analyze_batch(scaled, qs, engine=engine)
        for i, config in enumerate(sorted(mech.configurations)):
            ref = truth(name, config)
            assert int(batch.dof[i]) == ref["dof"] and int(batch.constraint_rank[i]) == ref["constraint_rank"]
            assert list(batch.limb_twist_rank[i]) == [limb["twist_rank"] for limb in ref["limbs"]]
            assert int(batch.locked_dof[i]) == ref["singularity"]["locked_dof"]
