"""Every built-in model at every named configuration: finite and instantaneous mobility agree where the
configuration is regular, the tracer confirms every verdict, and every finite DoF (platform, closed chain,
platform with the actuators held) is decided and equals a second method's: the local dimension of closed
samples near q, measured with Pinocchio alone (:mod:`closed_samples`).

Regular: the singularity report finds no constraint and no limb (Type I) singularity; then the closed set
near q is a manifold with the instantaneous DoF (constant rank), so the finite DoF must equal it, for the
platform and the whole mechanism, and every instantaneous motion must be finite. With the actuators held,
the same holds where there is no actuation (Type II) singularity. At the special configurations the
expected finite DoF is derived by hand below (the cases with more to say have their own tests in
``tests/test_finite.py``).
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest
from closed_samples import sampled_dimensions
from finite_cases import platform_follows

import pinmob
from pinmob.analysis.finite.verdicts import Verdict
from pinmob.assembly.assemble import joint_velocity_indices

MODELS = Path(__file__).resolve().parent.parent / "models"
CASES = [
    (tomllib.loads(p.read_text())["name"], config)
    for p in sorted(MODELS.glob("*.toml"))
    for config in tomllib.loads(p.read_text())["configurations"]
]

#: (platform, mechanism) finite DoF at the special configurations, by hand:
#: - a limb at a serial singularity (stretched or flat): the platform is on that limb's workspace boundary
#:   and moves into the workspace with the generic DoF (the lost freedom returns at second order);
#: - the Sarrus and the Delta with straight limbs: likewise (tests/test_finite.py);
#: - the flat 3-PUU: only the translation along z (tests/test_finite.py);
#: - constraint singularities of the 3-UPU, Delta-3RUU, 3-PUU-vertical and 4-RUU: two operation modes
#:   meet, each with the generic DoF of its mode (the largest is reported; tests/test_finite.py checks the
#:   4-RUU's 4 and 2 away from q);
#: - the Delta with horizontal rods: its 3T mode (9 with the rods' spins) and a tilting mode of the same
#:   dimension meet (tests/test_finite.py).
SPECIAL = {
    ("3-PRRR", "limb-A-flat"): (3, 3),
    ("3-RRR-planar", "limb-A-stretched"): (3, 3),
    ("3-RRR-spherical", "limb-A-stretched"): (3, 3),
    ("3-UR5", "wrist-singular"): (6, 6),
    ("five-bar", "limb-B-stretched"): (2, 2),
    ("Sarrus", "stretched"): (1, 1),
    ("Delta", "arms-stretched"): (3, 9),
    ("3-PUU-flat", "flat"): (1, 1),
    ("3-PUU-flat", "flat-raised"): (1, 1),
    ("3-UPU", "constraint-singular"): (3, 3),
    ("Delta-3RUU", "constraint-singular"): (3, 3),
    ("3-PUU-vertical", "vertical"): (3, 3),
    ("4-RUU", "parallel-axes"): (4, 4),
    ("Delta", "rods-horizontal"): (3, 9),
}


@pytest.mark.parametrize(("name", "config"), CASES)
def test_finite_mobility_of_every_built_in_configuration(name: str, config: str) -> None:
    report = pinmob.analyze(pinmob.load(name), config, finite=True)
    fm, sing = report.finite, report.singularity
    regular = sing is not None and not sing.constraint and not sing.limbs
    if regular:
        assert (fm.finite_dof, fm.finite_mechanism_dof) == (fm.free.dof, fm.free.mechanism_dof)
        assert all(v.verdict is Verdict.FINITE for v in fm.motions + fm.free.internal)
        assert len(fm.free.branches) == 1 and not fm.free.notes
        if fm.locked is not None and not sing.actuation:
            assert fm.finite_dof_locked == fm.locked.dof
    else:
        assert (fm.finite_dof, fm.finite_mechanism_dof) == SPECIAL[(name, config)]
    assert report.mobility is not None and fm.free.dof == report.dof  # the closed chain's platform DoF, again
    assert [v.label for v in fm.motions] == [m.label for m in report.motions]
    if fm.locked is not None and report.singularity.actuation is not None and len(fm.locked.motions):
        assert [v.label for v in fm.locked.motions] == [m.label for m in report.singularity.uncontrolled]
    # each platform verdict against a trace done without the finite analysis (finite_cases.platform_follows)
    held = tuple(int(i) for i in joint_velocity_indices(report.state.mechanism, list(report.state.mechanism.actuated)))
    sides = [((), fm.motions)] + ([(held, fm.locked.motions)] if fm.locked is not None else [])
    for joints_held, verdicts in sides:
        for v in verdicts:
            follows = platform_follows(report.state.mechanism, report.state.q, v.motion.twist, joints_held)
            if v.verdict is Verdict.FINITE:
                assert min(follows) > 0.5, (v.label, follows)
            if v.verdict is Verdict.BLOCKED:
                assert max(abs(f) for f in follows) < 0.05, (v.label, follows)
    for v in fm.motions + fm.free.internal + (fm.locked.motions if fm.locked else ()):
        assert v.verdict is not Verdict.UNDECIDED, v
    for branch in fm.free.branches:
        assert branch.traced > 0 or branch.test is None  # a mode seen at closed samples (the Delta's tilting one)
        if regular:  # constant rank: the platform moves on the branch at q as at its other points
            assert branch.where == "q", branch
    # every finite DoF decided, and equal to the local dimension of closed samples near q (a second method)
    mech, q = report.state.mechanism, report.state.q
    assert None not in (fm.finite_dof, fm.finite_mechanism_dof, fm.finite_dof_locked)
    assert (fm.finite_dof, fm.finite_mechanism_dof) == sampled_dimensions(mech, q)
    assert fm.finite_dof_locked == sampled_dimensions(mech, q, tuple(mech.actuated))[0]
