"""The generic configurations closed by the batched solver's compiled loop or by its numpy steps: the same ranks.

pinmob.analysis.generic closes its random configurations near the named ones by the batched solver in lockstep:
compiled where that loop is loaded already (a scan's process: its spec loads the kernels first), with numpy's steps
and Pinocchio's kinematics otherwise (an analysis does not load numba). The two differ in round-off (and so, where the closures leave
a continuum, in which of its points a start closes to); only ranks are
decided at those configurations. Checked here on every built-in model: each closes the same starts, and every rank
decided at them (the limb sets' generic wrench ranks, the generic
constraint rank, the coordinates a grid holds because no motion changes them) is the same from either.
"""

from __future__ import annotations

import numpy as np
import pytest

import pinmob
from pinmob.analysis import Configuration, generic_configurations
from pinmob.analysis.generic import generic_set_ranks
from pinmob.assembly import CLOSURE_TOL, POSE_COORDS, check_closed
from pinmob.scan.coordinates import constant_coordinates

pytestmark = pytest.mark.needs_numba

MODELS = sorted(pinmob.builtin_models())


def _closed(name: str, compiled: bool):
    """A fresh mechanism (the first configurations computed are kept) and what either engine gives there."""
    mech = pinmob.load(name)
    try:
        qs = generic_configurations(mech, compiled=compiled)
    except pinmob.PinmobError as exc:  # no named configuration closes: the same message either way
        return mech, None, str(exc), None
    held = constant_coordinates(mech, Configuration(mech, qs[0]), list(POSE_COORDS)) if mech.has_platform else None
    return mech, qs, generic_set_ranks(mech), held


@pytest.mark.parametrize("name", MODELS)
def test_either_engine_closes_the_same_configurations_and_decides_the_same_ranks(name):
    """The ranks of every limb set, and the pose coordinates no motion changes, from the configurations either
    engine closed; each closes as many starts, and closes them (not to the same points: the closures leave each a
    continuum of configurations, and the damped steps' null-space drift differs in round-off, 1e-5 on the 3-PRRR)."""
    mech, numpy_qs, numpy_ranks, numpy_held = _closed(name, compiled=False)
    _, compiled_qs, compiled_ranks, compiled_held = _closed(name, compiled=True)
    assert numpy_ranks == compiled_ranks and numpy_held == compiled_held
    assert (numpy_qs is None) == (compiled_qs is None)
    if numpy_qs is None:
        return
    assert len(numpy_qs) == len(compiled_qs)  # the same starts closed
    for q in compiled_qs:
        check_closed(mech, q, CLOSURE_TOL)


def test_the_engine_is_the_compiled_loop_where_it_is_loaded():
    """With the batched solver's compiled loop loaded (a scan's process: its spec loads it first), the generic
    configurations of a platform whose closures are its limb tips are that loop's, to the last bit."""
    import sys

    from pinmob.analysis.generic import KERNEL

    pinmob.scan.grid_spec(pinmob.load("3-PUU"), "generic", [("x", -0.01, 0.01, 2)])
    assert KERNEL in sys.modules
    auto, forced = pinmob.load("3-PUU"), pinmob.load("3-PUU")
    for a, b in zip(generic_configurations(auto), generic_configurations(forced, compiled=True), strict=True):
        assert np.array_equal(a, b)
