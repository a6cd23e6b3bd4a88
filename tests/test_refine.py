"""The one-dimensional refinement on functions whose minimum is known in closed form."""

from __future__ import annotations

import math

import pytest

from pinmob.scan.refine import STALL, fold_root, minimise, v_vertex, v_zero


def test_v_models_are_exact_on_a_v():
    """f = 0.3 |t - 0.37|: the steeper secant through b and its neighbour is a branch of the V."""
    f = lambda t: 0.3 * abs(t - 0.37)  # noqa: E731
    assert v_zero(0, 0.25, 1, f(0), f(0.25), f(1)) == pytest.approx(0.37)
    assert v_vertex(0, 0.25, 1, f(0), f(0.25), f(1)) == pytest.approx((0.37, 0.0))
    # a smooth dip 0.3 + (t - 0.25)^2 sampled symmetrically: the V vertex keeps the level of the dip
    g = lambda t: 0.3 + (t - 0.25) ** 2  # noqa: E731
    assert v_vertex(0, 0.25, 0.5, g(0), g(0.25), g(0.5))[1] == pytest.approx(0.3)


def test_fold_root_is_exact_on_a_square_root():
    """f = sqrt(2 (0.8 - t)) for t < 0.8: f^2 is linear and vanishes at 0.8."""
    f = lambda t: math.sqrt(2 * (0.8 - t))  # noqa: E731
    assert fold_root(0.1, 0.5, f(0.1), f(0.5)) == pytest.approx(0.8)
    assert fold_root(0.5, 0.1, f(0.5), f(0.1)) is None  # not decreasing towards the fold


def test_minimise_converges_on_a_curved_crossing():
    """|sin(3 (t - 0.4123))| between samples 0, 0.5, 1: a crossing that is a V only to first order."""
    calls = []

    def f(t: float) -> float:
        calls.append(t)
        return abs(math.sin(3 * (t - 0.4123)))

    best = minimise(f, 0.0, 0.5, 1.0, f(0.0), f(0.5), f(1.0), stop=1e-12, xtol=1e-14)
    assert best.t == pytest.approx(0.4123, abs=1e-12) and best.value < 1e-12
    assert best.evaluations <= 8  # golden section alone would need about 55


def test_minimise_walks_up_to_a_fold():
    """f = sqrt(0.8 - t) below t* = 0.8 and no value beyond (cannot be assembled): the best point closes in
    on t* from below, mostly without stepping past it."""
    beyond = []

    def f(t: float) -> float:
        if t > 0.8:
            beyond.append(t)
            return math.inf
        return math.sqrt((0.8 - t) * (1 + (0.8 - t)))  # not exactly a square root

    best = minimise(f, 0.0, 0.5, 1.0, f(0.0), f(0.5), math.inf, stop=1e-7, xtol=1e-15)
    assert 0.8 - 1e-13 < best.t <= 0.8 and best.value <= 1e-7
    assert best.evaluations <= 12 and len(beyond) <= 3


def test_minimise_gives_up_on_a_dip_that_is_not_a_zero():
    """A smooth dip to 0.3 (no singularity): after STALL evaluations that do not halve the best value the search
    stops, with an honest value (the scan then reports nothing there)."""
    g = lambda t: 0.3 + (t - 0.61) ** 2  # noqa: E731
    best = minimise(g, 0.0, 0.5, 1.0, g(0.0), g(0.5), g(1.0), stop=1e-7, xtol=1e-12, max_eval=60)
    assert best.evaluations == STALL and 0.3 <= best.value < g(0.5) and abs(best.t - 0.61) < 0.1
