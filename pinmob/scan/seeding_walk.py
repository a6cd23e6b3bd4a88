"""The coarse walk that seeds a scan's chunks: :func:`chunk_seeds`.

One walk, in the process that runs the scan (:mod:`pinmob.scan.scan_run`), goes from the reference configuration
through every ``STRIDE``-th sample of a path, or of a grid's lines up to their last chunk's first sample
(:meth:`pinmob.scan.scan_spec.ScanSpec.waypoints`), and gives each chunk its seed: the closed configuration at its
first sample. The chunks then run from their seeds, in this process or on Dask workers, so the rows do not depend
on where they run. The walk's waypoints are closed by the batched predictor where the move is a continuation
(a secant, or at a turn the move of the line next to it) and by the single-sample solver elsewhere.
"""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import numpy as np

import pinmob.scan.chunk as chunk
from pinmob.assembly import pose_vector
from pinmob.exceptions import PinmobError
from pinmob.model import Mechanism
from pinmob.scan.predictor import Predictor
from pinmob.scan.scan_spec import CHUNK, ScanSpec
from pinmob.screw import Array


def chunk_seeds(mech: Mechanism, spec: ScanSpec) -> Iterator[tuple[int, int, Array]]:
    """``(start, stop, seed)`` of every chunk, in order, from one coarse walk (:meth:`ScanSpec.waypoints`).

    The seed is the walk's configuration at the chunk's first sample (or, when that does not assemble, at the
    last waypoint that did). A waypoint one even step on from the two before it (in sample index or in the
    target's coordinates: the approach from the reference, a grid's first column, a path's every ``STRIDE``-th
    sample), both closed, is closed by the batched predictor from their secant
    (:func:`~pinmob.assembly.moved_stack`), as the chunks' samples are, and kept only when its Newton
    correction was at most ``WALK_SECANT`` of the secant's step (:func:`~pinmob.assembly.off_secants`).
    At a turn of the walk (the first waypoints of a line), where the two before are not in line with it, the
    predictor starts from the last waypoint's configuration moved as the same two samples moved on the line
    before (or after, on a three-coordinate grid's serpentine; :func:`_across_waypoint`), when both were walked
    and closed and the target moves by as much between them, with the same check of the correction against
    that move. Every other waypoint (the first, the turns of the first two lines, one the predictor did not
    close or closed off the secant) is closed by the single-sample solver from the waypoint before: the walk's
    steps can be long, and the predictor from a plain warm start could close them on other joint values (U
    joints turned by pi: the 3-UPU-wrist over yaw and pitch) and so seed the chunks on another assembly branch.
    The walk advances only as far as the chunks asked for so far need (chunks are produced lazily).
    """
    stops = dict(spec.chunks())
    order = list(stops)
    found: dict[int, Array] = {}
    q = np.array(spec.q_ref, float)
    solver = spec.assembly_mechanism(mech)  # mech, or with the reference's CAD gaps held
    predictor = Predictor(solver, spec) if Predictor.applies(mech, spec) else None
    # the last two waypoints and their closed configurations; a grid's walk starts at the reference's coordinates
    here: Walked = (
        None,
        _target_values(spec.coordinates_target(dict(spec.start))) if predictor and spec.start else None,
    )
    behind: list[tuple[Walked, Array | None]] = [((None, None), None), (here, q)]
    n = spec.line_size if spec.kind == "grid" else 0
    walked: dict[int, tuple[Walked, Array | None]] = {}  # the lines' waypoints so far, by sample index
    for target, k in spec.waypoints():
        here = (k, _target_values(target) if predictor else None)  # the moves compared only for the predictor
        closed = _secant_waypoint(predictor, target, here, behind)
        if closed is None and predictor is not None and n and k is not None and behind[1][0][0] is not None:
            closed = _across_waypoint(predictor, target, here, behind[1], walked, n)
        if closed is None:
            try:
                closed = chunk.assemble_target(solver, target, q, tol=spec.closure_tol)
            except PinmobError:
                pass
        if k is not None and n:
            walked[k] = ((None, here[1]), closed)
            if len(walked) > 8 * CHUNK:  # only the lines next to the walk's are read
                walked = {i: w for i, w in walked.items() if abs(i - k) <= 2 * n}
        if closed is not None:
            q = closed
        behind = [behind[1], (here, closed)]
        if k in stops:
            found[k] = q
        while order and order[0] in found:
            start = order.pop(0)
            yield start, stops[start], found.pop(start)


#: A walk's waypoint closed by the predictor is kept when its Newton correction is at most this fraction of the
#: secant's step (joint metric): the walk's steps can be long (a path's 8 samples, a 3-coordinate grid's turn of
#: lines), where a correction of the order of the step closed a 3-RPS's spherical joint on its other Euler triple.
#: Along the benchmark grids' first columns the correction is at most 0.17 of the step.
WALK_SECANT = 0.25

#: Where the walk is: a waypoint's sample index (None: on the approach) and its target's coordinate values.
Walked = tuple[int | None, Array | None]


def _target_values(target: tuple[str, Any]) -> Array:
    """A target's coordinates as a vector (pose coordinates, then joint values), to compare moves."""
    kind, value = target
    if kind == "pose":
        return pose_vector(value)
    if kind == "coords":
        return np.array([*value[0].values(), *value[1].values()], float)
    return np.array(list(value.values()), float)


def _even(here: Walked, mid: Walked, back: Walked) -> bool:
    """True when the move from ``mid`` to ``here`` is the move from ``back`` to ``mid`` (sample index or values)."""
    (k, v), (k2, v2), (k1, v1) = here, mid, back
    if k is not None and k1 is not None and k2 is not None and k - k2 == k2 - k1:
        return True
    return _same_move((v2, v), (v1, v2))


def _same_move(one: tuple[Array | None, Array | None], other: tuple[Array | None, Array | None]) -> bool:
    """True when the target's values move as much from ``one[0]`` to ``one[1]`` as from ``other[0]`` to ``other[1]``."""
    values = [v for v in (*one, *other) if v is not None]
    if len(values) < 4 or any(v.shape != values[0].shape for v in values):
        return False
    a0, a1, b0, b1 = values
    step = float(np.linalg.norm(b1 - b0))
    return step > 0.0 and float(np.linalg.norm((a1 - a0) - (b1 - b0))) <= 1e-9 * step


def _secant_waypoint(
    predictor: Predictor | None, target: tuple[str, Any], here: Walked, behind: list[tuple[Walked, Array | None]]
) -> Array | None:
    """A waypoint closed by the predictor from the secant of the two before it (:func:`chunk_seeds`), else None."""
    (back, q1), (mid, q2) = behind
    if predictor is None or q1 is None or q2 is None or not _even(here, mid, back):
        return None
    return _moved_waypoint(predictor, target, q2, q1, q2)


def _across_waypoint(
    predictor: Predictor,
    target: tuple[str, Any],
    here: Walked,
    last: tuple[Walked, Array | None],
    walked: dict[int, tuple[Walked, Array | None]],
    n: int,
) -> Array | None:
    """A grid's waypoint closed by the predictor from the walk's last one, moved as on a line next to them, or None.

    ``last``: the walk's last waypoint (index and values) and its configuration; ``walked``: the grid's waypoints
    so far by sample index; ``n``: the line size. When the same two samples one line before (or after) were
    walked and closed, and the target moves by as much between them (compared by their values), the start is the
    last configuration moved by their move (:func:`chunk_seeds`).
    """
    (k, v), ((kq, vq), q) = here, last
    if q is None or k is None or kq is None:
        return None
    for side in (-n, n):
        (_, v0), q0 = walked.get(kq + side, ((None, None), None))
        (_, v1), q1 = walked.get(k + side, ((None, None), None))
        if q0 is not None and q1 is not None and _same_move((vq, v), (v0, v1)):
            return _moved_waypoint(predictor, target, q, q0, q1)
    return None


def _moved_waypoint(predictor: Predictor, target: tuple[str, Any], seed: Array, a: Array, b: Array) -> Array | None:
    """``target`` closed by the predictor from ``seed`` moved by ``b - a``, else None.

    None where it did not close or its correction was longer than ``WALK_SECANT`` times that move
    (:func:`~pinmob.assembly.off_secants`, with the move's length as the step).
    """
    (closed,) = predictor.closed([target], [seed], (a[None], b[None], np.ones(1, bool)), WALK_SECANT)
    return closed
