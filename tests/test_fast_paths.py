"""Each faster computation against the straightforward one it replaces, on random matrices and the built-in models."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.linalg
from numpy.testing import assert_allclose

from pinmob.screw.classify import _generalised_eigh
from pinmob.screw.rank import singular_values, svd


@pytest.mark.parametrize("shape", [(5, 6), (6, 6), (6, 3), (18, 15), (30, 36), (4, 5, 6)])
def test_svd_is_numpys(shape):
    """rank.svd calls the LAPACK gufunc behind np.linalg.svd: bit for bit the same, one matrix or a stack."""
    a = np.random.default_rng(3).normal(size=shape)
    for full in (True, False):
        for mine, ref in zip(svd(a, full_matrices=full), np.linalg.svd(a, full_matrices=full)):
            assert np.array_equal(mine, ref)
    assert np.array_equal(singular_values(a), np.linalg.svd(a, compute_uv=False))


def test_svd_of_a_stack_is_the_svd_of_each():
    a = np.random.default_rng(4).normal(size=(7, 5, 6))
    stacked = svd(a)
    for i in range(a.shape[0]):
        for s, one in zip(stacked, svd(a[i])):
            assert np.array_equal(s[i], one)


def test_svd_of_a_matrix_with_nan_raises():
    with pytest.raises(np.linalg.LinAlgError), np.errstate(invalid="ignore"):
        svd(np.full((3, 3), np.nan))


@pytest.mark.parametrize("size", [1, 2, 3])
def test_generalised_eigh_is_scipys(size):
    """The Cholesky reduction gives SciPy's eigenvalues and, up to sign, its B-orthonormal eigenvectors."""
    rng = np.random.default_rng(size)
    for _ in range(20):
        m = rng.normal(size=(size, size))
        a = m + m.T
        g = rng.normal(size=(size, size))
        b = g @ g.T + 0.1 * np.eye(size)
        vals, vecs = _generalised_eigh(a, b)
        ref_vals, ref_vecs = scipy.linalg.eigh(a, b)
        assert_allclose(vals, ref_vals, rtol=1e-10, atol=1e-12)
        assert_allclose(vecs.T @ b @ vecs, np.eye(size), atol=1e-10)
        assert_allclose(np.abs(vecs.T @ b @ ref_vecs), np.eye(size), atol=1e-8)  # distinct eigenvalues


HEAVY = ("numba", "scipy", "yaml", "matplotlib", "meshcat", "mujoco", "dask")


def test_import_pinmob_loads_no_optional_package():
    """``import pinmob`` (and a whole analysis, as ``pinmob analyze`` runs it) loads none of the heavy packages."""
    import subprocess
    import sys

    code = (
        "import sys, pinmob\n"
        f"heavy = {HEAVY!r}\n"
        "print(sorted(m for m in heavy if m in sys.modules))\n"
        "r = pinmob.analyze(pinmob.load('3-PUU'), 'generic'); r.to_dict(); str(r)\n"
        "print(sorted(m for m in heavy if m in sys.modules))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split("\n")
    assert out[0] == "[]", out[0]
    assert out[1] == "[]", out[1]
