"""The compiled batch kernel's pieces against LAPACK: the column Jacobi SVD, its rank, the Householder complement.

``pinmob.analysis.batch.batch_kernel`` ranks a limb's screws (and the stacked wrenches) by orthogonalising them as
columns (one-sided Jacobi, no right singular vectors), the complement of their span by Householder reflections,
and, when the unit columns prove full column rank, the complement of the screws by Householder reflections
alone. Fails on the old code: no ``orthogonalize``, ``column_rank`` or ``complete``.
"""

from __future__ import annotations

import numpy as np
import pytest
from numpy.testing import assert_allclose

pytest.importorskip("numba")


def _matrices(rng):
    """(6, n) matrices of every width and rank, scaled from 1e-3 to 1e3, a few with columns of very different lengths."""
    for _ in range(400):
        n, rank = int(rng.integers(0, 7)), int(rng.integers(0, 7))
        rank = min(rank, n)
        a = rng.normal(size=(6, rank)) @ rng.normal(size=(rank, n)) if rank else np.zeros((6, n))
        if n and rng.random() < 0.2:
            a *= 10.0 ** rng.uniform(-4, 4, size=n)
        yield a * 10.0 ** rng.uniform(-3, 3)


def test_orthogonalised_columns_are_lapacks_svd_and_their_complement_is_orthonormal():
    """Singular values and rank (the rank rule at 1e-9) of the orthogonalised columns equal LAPACK's, also when the
    columns are added to ones orthogonalised before (the kernel's locked screws, then the actuated ones); the
    complement is orthonormal and orthogonal to every column; the complement of full-rank columns taken as they
    are (the certified path) too."""
    from pinmob.screw.jacobi import column_rank, complete, orthogonalize

    rng = np.random.default_rng(12)
    rtol = 1e-9
    for a in _matrices(rng):
        n = a.shape[1]
        ref = np.zeros(6)
        if n:
            ref[: min(n, 6)] = np.linalg.svd(a, compute_uv=False)
        scale = max(float(ref[0]), 1e-300)
        true_rank = int(np.sum(ref > rtol * ref[0])) if ref[0] > 0 else 0
        for start in {0, n // 2}:
            g, sv, order = np.zeros((6, 6)), np.zeros(6), np.zeros(6, np.int64)
            g[:, :n] = a
            orthogonalize(g, 0, start)
            orthogonalize(g, start, n)
            rank = column_rank(g, n, rtol, sv, order)
            assert_allclose(sv, ref, atol=1e-13 * scale)
            assert rank == true_rank
            out = np.zeros((6, 6))
            assert complete(g, order, rank, out, 0, True) == 6 - rank
            w = out[: 6 - rank]
            assert_allclose(w @ w.T, np.eye(6 - rank), atol=1e-13)
            assert np.abs(w @ a).max(initial=0.0) <= 1e-12 * scale
        if n and true_rank == n and ref[n - 1] > 1e-6 * ref[0]:  # full column rank: Householder on the columns
            g = np.zeros((6, 6))
            g[:, :n] = a
            out = np.zeros((6, 6))
            assert complete(g, np.arange(6), n, out, 0, False) == 6 - n
            w = out[:, : 6 - n]
            assert_allclose(w.T @ w, np.eye(6 - n), atol=1e-13)
            assert np.abs(a.T @ w).max(initial=0.0) <= 1e-12 * scale


def test_the_kernels_free_twists_span_the_numpy_engines():
    """The free twists of analyze_batch (the null space of the stacked wrenches, built from the limbs'
    complements) span the numpy engine's (LAPACK's) at every built-in platform model's named configurations
    (singular ones among them, where the kernel's limbs take the Jacobi path) and at generic ones nearby."""
    import pinocchio as pin

    import pinmob
    from pinmob.analysis.batch.batch_analysis import analyze_batch

    rng = np.random.default_rng(13)
    checked = 0
    for name in pinmob.builtin_models():
        mech = pinmob.load(name)
        if not mech.has_platform or not mech.limbs or mech.coupling_closures or any(b.closures for b in mech.limbs):
            continue
        qs = [pinmob.closed_configuration(mech, c) for c in mech.configurations]
        try:
            qs.append(pinmob.project(mech, pin.integrate(mech.model, qs[0], rng.normal(0.0, 0.02, mech.model.nv))).q)
        except pinmob.ClosureError:
            pass
        ref = analyze_batch(mech, np.array(qs), engine="numpy", twists=True, singular_values=True)
        for values in (True, False):  # without the limb ratios no limb is proven full rank: every SVD made
            fast = analyze_batch(mech, np.array(qs), engine="numba", twists=True, singular_values=values)
            assert np.array_equal(fast.dof, ref.dof) and np.array_equal(fast.locked_dof, ref.locked_dof), name
            assert np.array_equal(fast.limb_twist_rank, ref.limb_twist_rank), name
            for i, d in enumerate(ref.dof):
                a, b = fast.free_twists[i][:, :d], ref.free_twists[i][:, :d]
                assert_allclose(a.T @ a, np.eye(d), atol=1e-12)
                assert_allclose(a @ a.T, b @ b.T, atol=1e-10, err_msg=f"{name} {i}")  # the same projector: same span
                assert np.isnan(fast.free_twists[i][:, d:]).all()
                checked += 1
    assert checked > 60


def test_the_round_robin_sweeps_every_pair_once_in_rounds_of_disjoint_pairs():
    """The order of orthogonalize's rotations: every pair j < k of n columns exactly once, consecutive pairs of a
    round sharing no column (the table of up to six columns is the function's)."""
    from pinmob.screw.jacobi import PAIRS, round_robin

    for n in range(10):
        first, second = round_robin(n)
        pairs = list(zip(first.tolist(), second.tolist()))
        assert sorted(pairs) == [(j, k) for j in range(n) for k in range(j + 1, n)]
        per_round = n // 2
        for r in range(0, len(pairs), max(per_round, 1)):
            columns = [c for pair in pairs[r : r + per_round] for c in pair]
            assert len(columns) == len(set(columns)), (n, pairs)
        if n <= 6:
            assert pairs == list(zip(PAIRS[0, n, : len(pairs)].tolist(), PAIRS[1, n, : len(pairs)].tolist()))


def test_more_than_six_stacked_wrenches_are_reduced_to_six_columns_with_their_svd():
    """stack_columns: up to six rows become the columns as they are; more (the 3-RRR's nine, the 3-UR5's eighteen
    locked wrenches) the six rows of R of their QR factorisation: LAPACK's singular values of all the rows, and a
    complement orthogonal to every row."""
    from pinmob.analysis.batch.batch_kernel import stack_columns
    from pinmob.screw.jacobi import column_rank, complete, orthogonalize

    rng = np.random.default_rng(14)
    for _ in range(200):
        used, rank = int(rng.integers(0, 19)), int(rng.integers(0, 7))
        rows = rng.normal(size=(used, rank)) @ rng.normal(size=(rank, 6)) if rank else np.zeros((used, 6))
        rows *= 10.0 ** rng.uniform(-3, 3)
        ref = np.zeros(6)
        if used:
            ref[: min(used, 6)] = np.linalg.svd(rows, compute_uv=False)
        scale = max(float(ref[0]), 1e-300)
        g, sv, order = np.zeros((6, 6)), np.zeros(6), np.zeros(6, np.int64)
        work = np.zeros((18, 6))
        work[:used] = rows
        count = stack_columns(work, used, g)
        assert count == min(used, 6)
        orthogonalize(g, 0, count)
        r = column_rank(g, count, 1e-9, sv, order)
        assert_allclose(sv, ref, atol=1e-13 * scale)
        assert r == (int(np.sum(ref > 1e-9 * ref[0])) if ref[0] > 0 else 0)
        null = np.zeros((6, 6))
        complete(g, order, r, null, 0, False)
        assert np.abs(rows @ null[:, : 6 - r]).max(initial=0.0) <= 1e-12 * scale


def test_the_kernel_takes_the_jacobians_as_given_scaling_them_as_numpy_does(monkeypatch):
    """analyze_jacobians hands the compiled loop the world Jacobians as the caller gave them, and the loop scales
    each column (L on prismatic rates) as it reads it: the same products as the stack scaled first (the loop given
    ``full * rate_scale`` and unit scales), so the same bits in every output; and the same for a Fortran-ordered
    copy, a strided view and a nested list (each made contiguous float64 first, as the loop is compiled for)."""
    from dataclasses import fields

    import pinmob
    import pinmob.analysis.batch.batch_analysis as batch_analysis
    from pinmob.analysis.limbs import rate_scale

    mech = pinmob.load("3-PUU")  # prismatic sliders: the scale is not all ones
    scale = rate_scale(mech)
    assert not np.all(scale == 1.0)
    rng = np.random.default_rng(5)
    q0 = pinmob.closed_configuration(mech, "generic")
    qs = np.array([q0 + rng.normal(0.0, 0.01, q0.size) for _ in range(6)])
    full, origin = batch_analysis.world_jacobians(mech, qs)

    def analysed(given: object) -> list[object]:
        res = batch_analysis.analyze_jacobians(mech, given, origin, singular_values=True, twists=True, engine="numba")
        return [getattr(res, f.name) for f in fields(res)]

    ref = analysed(full)
    wide = np.zeros((full.shape[0], 6, 2 * full.shape[2]))
    wide[:, :, ::2] = full
    outputs = [analysed(given) for given in (np.asfortranarray(full), wide[:, :, ::2], full.tolist())]
    monkeypatch.setattr(batch_analysis, "rate_scale", lambda mech: np.ones_like(scale))
    outputs.append(analysed(full * scale))  # the stack scaled first, the loop's scales all ones
    for out in outputs:
        for a, b in zip(out, ref):
            assert a == b if isinstance(a, str) or a is None else np.array_equal(a, b, equal_nan=True)
