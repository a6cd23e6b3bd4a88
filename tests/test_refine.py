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


def _analysing_every_trial(monkeypatch, chunk):
    """``_Chunk.trial`` analysing every point, the edge searches' bisections' too (as before they were not)."""
    trial = chunk._Chunk.trial
    monkeypatch.setattr(chunk._Chunk, "trial", lambda self, t, seed, analysed=True: trial(self, t, seed))


def test_an_edge_search_analyses_only_the_last_point_its_bisections_assembled(monkeypatch):
    """Towards a neighbour that does not assemble, a search bisects on whether the mechanism assembles, then
    minimises the distance from the last point that did: the bisections' other points are assembled, never
    analysed. Counted on the 3-PUU's wide grid (its edges of the reachable set): every point the minimisations
    assemble is analysed (:func:`pinmob.scan.sample.examine`), and at most one per edge search besides, while the
    bisections assembled more than one point per edge search. The rows are those of a scan whose every trial
    point is analysed."""
    import pinmob
    import pinmob.scan.chunk as chunk
    from pinmob.scan import grid_spec
    from pinmob.scan.scan_run import scan_in_process

    mech = pinmob.load("3-PUU")
    spec = grid_spec(mech, "generic", [("x", -0.3, 0.3, 9), ("y", -0.3, 0.3, 9)])
    counts = {"edges": 0, "minimised": 0, "bisected": 0, "analysed in": 0, "analysed out": 0}
    inside = [False]  # in a minimisation's evaluation
    examine, search, minimised, assemble = chunk.examine, chunk._Chunk._search, chunk.minimise, chunk._Chunk.assemble

    def counted_examine(*args, **kwargs):
        counts["analysed in" if inside[0] else "analysed out"] += 1
        return examine(*args, **kwargs)

    def counted_search(self, k, done, key, towards=0):
        counts["edges"] += bool(towards)
        return search(self, k, done, key, towards)

    def counted_minimise(f, *args, **kwargs):
        def g(t):
            inside[0] = True
            try:
                return f(t)
            finally:
                inside[0] = False

        return minimised(g, *args, **kwargs)

    def counted_assemble(self, t, seed, max_iter=chunk.MAX_ITER, stall_window=None, **kwargs):
        sample = assemble(self, t, seed, max_iter, stall_window, **kwargs)
        if max_iter == chunk.REFINE_ITER and sample.q is not None:  # a search's trial point that assembled
            counts["minimised" if inside[0] else "bisected"] += 1
        return sample

    with monkeypatch.context() as patched:
        patched.setattr(chunk, "examine", counted_examine)
        patched.setattr(chunk._Chunk, "_search", counted_search)
        patched.setattr(chunk, "minimise", counted_minimise)
        patched.setattr(chunk._Chunk, "assemble", counted_assemble)
        rows = list(scan_in_process(mech, spec))
    assert any(r["refined"] for r in rows) and counts["edges"] > 0
    assert counts["bisected"] > counts["edges"], counts  # more than the one a search analyses
    assert counts["analysed in"] == counts["minimised"], counts
    assert counts["analysed out"] <= counts["edges"], counts
    _analysing_every_trial(monkeypatch, chunk)
    assert [repr(list(r.items())) for r in scan_in_process(mech, spec)] == [repr(list(r.items())) for r in rows]
