"""Classification of twist systems that hold free translations: invariant under a change of reference point.

Adding a free translation t to a screw changes its pitch by (w . t) / (w . w); the pitch is defined modulo
the free translations only for directions normal to them, and a motion reported with its axis point must
stay in the system. Both were wrong before the model library exposed them (3-UR5 wrist-singular reported
2T1R2H for a system spanned by 2T and three rotations; the five-bar's rotation was reported about the
platform origin, outside the free space).
"""

from __future__ import annotations

import numpy as np
import pytest

from pinmob.screw.algebra import shift_twists
from pinmob.screw.bases import subspace_gap
from pinmob.screw.classify import classify_twists


def _system(rng: np.random.Generator, n_trans: int, n_other: int) -> np.ndarray:
    trans = [np.concatenate([rng.normal(size=3), np.zeros(3)]) for _ in range(n_trans)]
    other = [rng.normal(size=6) for _ in range(n_other)]
    return np.column_stack(trans + other)


@pytest.mark.parametrize("seed", range(6))
@pytest.mark.parametrize("n_trans,n_other", [(1, 2), (2, 1), (2, 3), (1, 1), (0, 2)])
def test_label_and_pitches_do_not_depend_on_the_reference_point(seed, n_trans, n_other):
    rng = np.random.default_rng(seed)
    twists = _system(rng, n_trans, n_other)
    r = rng.normal(size=3)
    a = classify_twists(twists, 1.0)
    b = classify_twists(shift_twists(twists, r), 1.0)
    assert (len(a.free_vectors), len(a.lines), len(a.screws)) == (len(b.free_vectors), len(b.lines), len(b.screws))
    np.testing.assert_allclose([s.pitch for s in a.screws], [s.pitch for s in b.screws], atol=1e-9)
    for system, basis in ((a, twists), (b, shift_twists(twists, r))):
        assert subspace_gap(system.basis(), basis) < 1e-6  # every reported motion lies in the system


def test_force_constraint_leaves_two_translations_and_three_rotations():
    """Twists reciprocal to one force along x through (0, 1, 0): 2T (y, z) and three rotations about lines
    meeting the force line, whatever the reference point."""
    f = np.array([1.0, 0, 0, 0, 0, -1.0])  # [f; p x f] with p = (0, 1, 0): p x f = (0, 0, -1)
    free = np.linalg.svd(f[None, :])[2][1:].T
    system = classify_twists(free, 1.0)
    assert (len(system.free_vectors), len(system.lines), len(system.screws)) == (2, 3, 0)
    for s in system.lines:  # each rotation axis meets the force line {(s, 1, 0)}
        p, u = s.point, s.direction
        normal = np.cross(u, [1.0, 0, 0])
        if np.linalg.norm(normal) > 1e-9:
            assert abs(np.dot(p - [0, 1, 0], normal)) < 1e-9
