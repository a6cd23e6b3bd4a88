"""A scan gives up on an out-of-reach sample after a few iterations, with the rows of the old stall rule.

The scan's pose assemblies stop when their cost gained less than 0.1% over ``chunk.STALL_WINDOW`` (5)
damped iterations, where the solver elsewhere waits 20 (:data:`pinmob.assembly.solver.STALL_WINDOW`). The
iterates do not depend on the window, only where an unconverged solve stops: on every built-in mechanism with a
platform, over a grid wide enough to leave its reach (unreachable samples, edges refined), the rows equal
those of the scan with the solver's window of 20, but for the figures of the closest configuration an
unreachable sample's reason quotes (where the solver stopped).
"""

from __future__ import annotations

import itertools
import math
import re
import warnings

import numpy as np
import pinocchio as pin
import pytest

import pinmob
import pinmob.scan.chunk as chunk
from pinmob.assembly import solver
from pinmob.exceptions import PinmobError
from pinmob.scan.scan_run import scan_in_process
from pinmob.scan.scan_spec import POSE_COORDS, grid_spec
from pinmob.testing import kinematics_calls

#: Coordinate pairs tried in turn: the first a mechanism's first configuration lets vary independently.
PAIRS = (("x", "y"), ("roll", "pitch"), *itertools.combinations(POSE_COORDS, 2))
PLATFORM_MODELS = [
    "3-PRRR", "3-PRS", "3-PUU", "3-PUU-flat", "3-PUU-vertical", "3-RPS", "3-RRR-planar", "3-RRR-spherical",
    "3-UPU", "3-UPU-wrist", "3-UR5", "4-RUU", "6-UPS", "Delta", "Delta-3RUU",
]  # fmt: skip


def wide_grid(mech: pinmob.Mechanism) -> pinmob.scan.ScanSpec:
    """A 7 x 7 grid over the first free pair, +-0.6 L or +-1 rad around the first configuration."""
    at = next(iter(mech.configurations))
    for pair in PAIRS:
        axes = [(c, -0.6 * mech.length_scale, 0.6 * mech.length_scale, 7) if c in "xyz" else (c, -1.0, 1.0, 7)
                for c in pair]  # fmt: skip
        try:
            spec = grid_spec(mech, at, axes)
        except PinmobError:
            continue
        base = dict(spec.start)
        return grid_spec(mech, at, [(c, base[c] + lo, base[c] + hi, n) for c, lo, hi, n in axes])
    raise AssertionError(f"no pair of {mech.name} can be gridded")


def rows(mech: pinmob.Mechanism, spec: pinmob.scan.ScanSpec, window: int, monkeypatch: pytest.MonkeyPatch) -> list:
    monkeypatch.setattr(chunk, "STALL_WINDOW", window)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return list(scan_in_process(mech, spec))


CLOSEST = re.compile(r"closest found: .*")


def comparable(row: dict) -> dict:
    out = dict(row)
    if not row["reachable"]:
        out["reason"] = CLOSEST.sub("closest found: ...", row["reason"])
    return out


def same_value(a: object, b: object) -> bool:
    if isinstance(a, float) and isinstance(b, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    return a == b


@pytest.mark.parametrize("name", PLATFORM_MODELS)
def test_rows_equal_those_of_the_solvers_window(name, monkeypatch):
    mech = pinmob.load(name)
    spec = wide_grid(mech)
    old = rows(mech, spec, solver.STALL_WINDOW, monkeypatch)
    new = rows(mech, spec, 5, monkeypatch)
    assert len(new) == len(old), (name, len(old), len(new))
    for a, b in zip(old, new):
        a, b = comparable(a), comparable(b)
        assert a.keys() == b.keys()
        differ = {k: (a[k], b[k]) for k in a if not same_value(a[k], b[k])}
        assert not differ, (name, differ)


def test_an_out_of_reach_sample_costs_a_few_iterations():
    """3-PUU half a metre off: unreachable; the assembly computes the kinematics at most 25 times (39 with the window of 20)."""
    mech = pinmob.load("3-PUU")
    spec = grid_spec(mech, "generic", [("x", 0.5, 0.5, 1)])
    target = spec.target(0)
    q0 = np.array(spec.q_ref, float)

    def attempt() -> None:
        with pytest.raises(PinmobError):  # its message (not formatted here) would look for the reach: more solves
            chunk.assemble_target(mech, target, q0)

    calls = kinematics_calls(attempt)
    assert calls <= 25, calls


def test_misses_equal_as_printed_keep_the_residuals_order():
    """An unreachable sample's reason lists its largest misses as printed: round-off (1e-15 here) between equal
    misses does not reorder them (docs/singularities.md's 3-PUU path printed three 9.09e-03 misses in another
    order once the solver stopped elsewhere)."""
    import pinmob
    from pinmob.exceptions import ClosureError
    from pinmob.scan.unreachable import unreachable_reason

    mech = pinmob.load("3-PUU")
    texts = set()
    for eps in (-1e-15, 0.0, 1e-15):
        res = {"B": (9.09e-3, 0.0), "C": (9.09e-3 + eps, 0.0), "pose": (9.09e-3 - eps, 0.0), "A": (1e-3, 0.0)}
        texts.add(unreachable_reason(ClosureError("not closed", res), mech))
    (text,) = texts
    assert text.endswith("limb B open by 9.09e-03 m, limb C open by 9.09e-03 m, platform pose off by 9.09e-03 m"), text
    big = {"B": (1e-3, 0.0), "pose": (2e-3, 0.0), "C": (3e-3, 0.0)}
    assert unreachable_reason(ClosureError("not closed", big), mech).endswith(
        "limb C open by 3.00e-03 m, platform pose off by 2.00e-03 m, limb B open by 1.00e-03 m"
    )


def test_kinematics_calls_counts_each_computation_and_restores_pinocchio():
    """pinmob.testing.kinematics_calls (the benchmark's and these tests' count, once): one per call, counted by hand
    here, and Pinocchio's own function back in place afterwards, also when the counted call raises."""
    from pinmob.testing import kinematics_calls

    mech = pinmob.load("3-PUU")
    data, q = mech.model.createData(), mech.neutral()
    original = pin.computeJointJacobians
    assert kinematics_calls(lambda: [pin.computeJointJacobians(mech.model, data, q) for _ in range(7)]) == 7
    assert pin.computeJointJacobians is original

    def failing() -> None:
        pin.computeJointJacobians(mech.model, data, q)
        raise RuntimeError("stop")

    with pytest.raises(RuntimeError):
        kinematics_calls(failing)
    assert pin.computeJointJacobians is original
