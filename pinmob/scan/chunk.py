"""One chunk of a scan: its samples assembled warm-started along a line, analysed, and refined.

See :mod:`pinmob.scan.scan_run` for the order of the samples and the refinement rule. :meth:`_Chunk.run` is the
single-sample path (each sample assembled by :func:`assemble_target` and analysed by :func:`evaluate`, or by
the batch of :mod:`pinmob.scan.batch_rows`); :mod:`pinmob.scan.lockstep` runs many chunks' assemblies
together and completes each chunk with :meth:`_Chunk.complete` (refinements on the single-sample path). With the spec's
``finite_order`` each row kept (a sample, or a refined point; not the trial points of a refinement)
adds its finite DoF (``FINITE_COLUMNS``).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterator, Mapping, Sequence
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from pinmob.analysis import NEAR_FACTOR, Configuration, finite_mobility
from pinmob.assembly import STALL_WINDOW as SOLVER_STALL
from pinmob.assembly import check_closed, format_worst
from pinmob.exceptions import ClosureError, PinmobError
from pinmob.model import Mechanism, outside_limits
from pinmob.scan.batch_rows import Analysed, BatchRows, analyse_stack
from pinmob.scan.chain_scan import evaluate_chain, joint_row, unreachable_chain, value_columns
from pinmob.scan.group_rows import BatchRow, Head, head_dict
from pinmob.scan.refine import minimise, vertex_below
from pinmob.scan.row_columns import values_and_limits
from pinmob.scan.sample import MAX_ITER, Examined, _evaluate, examine
from pinmob.scan.sample import STALL_WINDOW as STALL_WINDOW  # re-exported: defined here before sample.py
from pinmob.scan.sample import assemble_target as assemble_target
from pinmob.scan.sample import evaluate as evaluate
from pinmob.scan.scan_spec import ScanSpec
from pinmob.scan.unreachable import unreachable_reason, unreachable_row
from pinmob.screw import Array

#: Evaluations per refinement, and bracket width (in samples) at which it stops.
REFINE_EVALS, REFINE_XTOL = 60, 1e-12
#: Bisections on whether the mechanism assembles that locate an edge of the reachable set to 1/64 of a sample
#: before the distance is minimised there.
EDGE_STEPS = 6
#: Refined points closer than this [samples] are one (two questions' searches stop ~1e-6 apart at one point).
SAME_POINT = 1e-4

#: The columns a scan with ``finite_order`` adds: the platform's and the closed chain's finite DoF.
FINITE_COLUMNS = ("finite_dof", "finite_mechanism_dof")

#: Iterations per assembly while refining (the solver converges slowly next to a singularity).
REFINE_ITER = 100
#: Trial points of a search that keep what they examined (the lowest): the point kept is nearly always one of
#: them; its row reuses it (another's is computed again, the same numbers). A Configuration holds a pin.Data
#: (megabytes for a large model), and a search makes up to ``REFINE_EVALS`` trial points.
HELD = 8


@dataclass(slots=True)
class _Sample:
    """A sample or trial point of a chunk: its row, configuration (None: unreachable) and distances.

    Assembled and not analysed yet (:meth:`_Chunk.assemble`): ``known`` holds the joint values its target gave,
    ``kinematics`` the world joint Jacobians and platform placement at q when the predictor computed them. A
    sample the batch decided may keep its row as a :class:`~pinmob.scan.group_rows.BatchRow` (:meth:`_Chunk.complete`).
    A refinement's trial point (:meth:`_Chunk.trial`) has its distances and ``examined``, not its row yet (on a
    closed chain's scan, its row); an edge search's bisection points are assembled only (:meth:`_Chunk._search`
    keeps them apart and analyses the last one that assembled).
    """

    row: dict[str, Any] | BatchRow | Head
    q: Array | None
    distances: Mapping[str, float]
    known: dict[str, float] | None = None
    kinematics: tuple[Array, Array] | None = None
    examined: Examined | None = None

    @property
    def distance(self) -> float:
        return min(self.distances.values(), default=1.0) if self.q is not None else math.inf


class _Chunk:
    """Runs one chunk: its samples, their two neighbours on the line, and the refinements."""

    def __init__(self, mech: Mechanism, spec: ScanSpec) -> None:
        self.mech, self.spec = mech, spec
        self.solver = spec.assembly_mechanism(mech)  # mech, or with the reference's CAD gaps held (spec.cad)
        self.rtol = spec.reference_rtol(mech)  # spec.rtol; with spec.cad, raised for the gaps (refinement's)
        self.band = NEAR_FACTOR * self.rtol
        #: A configuration closed elsewhere (the lockstep's predictor) and no target to read is the sample as it is:
        #: nothing to check (:meth:`opened`) nor to report (:meth:`assemble`).
        self.takes_closed = spec.platform and not spec.cad

    def trial(self, t: float, seed: Array, analysed: bool = True) -> _Sample:
        """A refinement's trial point t, assembled from ``seed``: its distances only, on the platform's scans.

        Its row (:meth:`finish`, which reuses what the distances computed) is made for the point a search keeps.
        ``analysed`` False: assembled only (:meth:`with_distances` gives its distances when they are asked for).
        """
        pending = self.assemble(t, seed, REFINE_ITER, SOLVER_STALL)
        return self.with_distances(pending) if analysed else pending

    def with_distances(self, pending: _Sample) -> _Sample:
        """A trial point assembled by :meth:`trial` with its distances (on a closed chain's scan, its row)."""
        if pending.q is None or not self.spec.platform:
            return self.finish(pending)
        examined = examine(self.mech, pending.q, self.spec.rtol, self.spec.generic_rank, self.spec.closure_tol)
        return replace(pending, distances=examined[2].distances, examined=examined)

    def assemble(self, t: float, seed: Array, max_iter: int = MAX_ITER, stall_window: int | None = None,
                 closed: Array | None = None, target: tuple[str, Any] | None = None,
                 params: dict[str, float] | Head | None = None) -> _Sample:  # fmt: skip
        """Sample t assembled from ``seed``: a finished row when it does not assemble, else its head and q.

        ``closed``: its closed configuration, already found (:mod:`pinmob.scan.lockstep`'s predictor, whose
        targets give no joint value: without ``target`` and ``spec.cad``, the target is not built);
        ``target``, ``params``: ``spec.target(t)`` and ``spec.params(t)``, already computed (None: computed here;
        a :class:`~pinmob.scan.group_rows.Head`: sample t's head, kept as the row of an assembled sample of a
        platform scan until :meth:`finish`).
        """
        if closed is not None and target is None and self.takes_closed:
            head = params if isinstance(params, Head) else self._head(t, params)
            return _Sample(head, closed, {}, {})  # nothing to check (opened) nor to report
        kept = params if isinstance(params, Head) and self.spec.platform else None  # an assembled sample's head
        params = params.line_params() if isinstance(params, Head) else params
        params = self.spec.params(t) if params is None else params
        head = self._head(t, params)
        target = self.spec.target(t, params) if target is None else target
        known = target[1] if target[0] == "joints" else target[1][1] if target[0] == "coords" else {}

        def values() -> dict[str, float]:  # the joint values of a row not assembled: NaN, the given ones known
            row = joint_row(self.mech, self.spec.values, None)
            row.update({k: v for k, v in zip(value_columns(list(known)), known.values()) if k in row})
            return row

        if not self.spec.platform:  # the whole closed chain (pinmob.scan.chain_scan)
            head.update(values())
        try:
            q = (
                closed
                if closed is not None
                else assemble_target(self.solver, target, seed, max_iter, self.spec.closure_tol, stall_window)
            )
            reason = self.opened(q)
        except PinmobError as exc:
            reason = str(exc) if not self.spec.platform else unreachable_reason(exc, self.mech, self.spec.closure_tol)
        if reason is None:
            return _Sample(head if kept is None else kept, q, {}, dict(known))
        if not self.spec.platform:
            return _Sample(head | unreachable_chain(reason), None, {})
        return _Sample(head | unreachable_row(target, reason) | values(), None, {})

    def _head(self, t: float, params: dict[str, float] | None) -> dict[str, Any]:
        """Sample t's head as a dict: ``index``, its line parameters (``params``, or computed here), ``refined``."""
        params = self.spec.params(t) if params is None else params
        return {"index": int(math.floor(t + 1e-9)), **params, "refined": False}

    def opened(self, q: Array) -> str | None:
        """Why q is refused, or None: assembled with CAD gaps held (``spec.cad``), the file's loops open too far.

        The gaps held are the reference's; where they grew beyond the closure tolerance the sample is not analysed.
        """
        if not self.spec.cad:
            return None
        try:
            check_closed(self.mech, q, self.spec.closure_tol)
        except ClosureError as exc:
            worst = format_worst(exc.residuals, self.mech.length_scale, self.spec.closure_tol)
            return f"assembled with the CAD gaps of the reference held, the loops open beyond closure_tol: {worst}"
        return None

    def finish(self, pending: _Sample, analysed: Analysed | int | None = None, values: dict[str, float] | None = None,
               limits: tuple[str, ...] | None = None, batch: BatchRows | None = None) -> _Sample:  # fmt: skip
        """The row of an assembled sample (:meth:`assemble`), from ``analysed`` (the batch's) or on its own.

        ``values``, ``limits``: its :func:`~pinmob.scan.chain_scan.joint_row` and
        :func:`~pinmob.model.joints.outside_limits`, already computed (None: computed here). ``analysed`` a
        whole number: the sample's entry in ``batch``, which decided it; its row is then a
        :class:`~pinmob.scan.group_rows.BatchRow` (its verdicts left in the batch's columns).
        """
        q, known = pending.q, pending.known
        if q is None or known is None:
            return pending
        assert not isinstance(pending.row, BatchRow)  # an assembled sample's head
        head = pending.row
        values = joint_row(self.mech, self.spec.values, q, known) if values is None else values
        if not self.spec.platform:
            head = head_dict(head)
            head.update(values)
            row, distances = evaluate_chain(self.mech, q, self.spec.rtol, self.spec.generic_rank, self.spec.closure_tol)
        else:
            tol = self.spec.closure_tol
            limits = outside_limits(self.mech.model, q) if limits is None else limits
            reason = f"joints outside their limits: {', '.join(limits)}" if limits else ""
            if isinstance(analysed, (int, np.integer)):
                assert batch is not None  # the entry's batch
                return _Sample(BatchRow(int(analysed), head, reason, values), q, batch.distance_row(int(analysed)))
            row, distances = analysed or _evaluate(self.mech, q, self.spec.rtol, self.spec.generic_rank, tol,
                                                   pending.examined)  # fmt: skip
            return _Sample({**head_dict(head), **row, "reason": reason, **values}, q, distances)  # one dict built
        return _Sample(head | row, q, distances)

    def analysed(self, samples: list[_Sample]) -> list[Analysed | None]:
        """The batch's rows of the assembled ``samples`` (None where it cannot decide; all None with ``single``)."""
        batch, where = self.batch_analysis(samples)
        return [None] * len(samples) if batch is None else batch.analysed(where)

    def batch_analysis(self, samples: list[_Sample]) -> tuple[BatchRows | None, list[int | None]]:
        """The batch's analysis of the assembled ``samples`` (None: not run) and each one's entry where it decides.

        The entry of a sample the batch does not decide (or did not analyse: ``single``, ``cad``) is None.
        """
        if self.spec.engine != "batch" or not self.spec.platform or self.spec.cad:  # cad: a tolerance per sample
            return None, [None] * len(samples)
        closed = [i for i, s in enumerate(samples) if s.q is not None]
        batch = analyse_stack(self.mech, [q for q in (samples[i].q for i in closed) if q is not None], self.spec.rtol,
                              self.spec.generic_rank, [samples[i].kinematics for i in closed])  # fmt: skip
        where: list[int | None] = [None] * len(samples)
        if batch is not None:
            for at, (i, decided) in enumerate(zip(closed, batch.decided.tolist())):
                where[i] = at if decided else None
        return batch, where

    def run(self, start: int, stop: int, seed: Array) -> list[dict[str, Any]]:
        """The rows of samples ``start .. stop - 1`` (one after the other; :mod:`pinmob.scan.lockstep` runs many)."""
        pending: dict[int, _Sample] = {}
        q = seed
        for k in self.line_samples(start, stop):
            pending[k] = self.assemble(k, q)
            q = _seed(pending[k], q)
        if self.spec.line(start)[0] < start:
            pending[start - 1] = self.assemble(start - 1, _seed(pending[start], seed))
        return [
            _dict(row) for row in self.complete(start, stop, self.done(pending, self.analysed(list(pending.values()))))
        ]

    def line_samples(self, start: int, stop: int) -> range:
        """The samples a chunk assembles in order: its own and the next one on its line (its right neighbour)."""
        return range(start, min(stop, self.spec.line(start)[1]) + 1)

    def done(self, pending: dict[int, _Sample], analysed: Sequence[Analysed | int | None],
             columns: list[tuple[Any, Any]] | None = None, batch: BatchRows | None = None) -> _Done:  # fmt: skip
        """The assembled samples (``pending``, with the batch's rows of them), each finished when first read.

        ``columns``: :func:`~pinmob.scan.row_columns.values_and_limits` of ``pending``'s samples, already computed.
        Where ``analysed`` gives a sample's entry in ``batch`` (a whole number; not with ``spec.finite_order``,
        whose columns are added to row dicts), its row is a :class:`~pinmob.scan.group_rows.BatchRow`.
        """
        if columns is None:
            columns = values_and_limits(self.mech, self.spec.values, list(pending.values()))
        return _Done(self, pending, analysed, columns, batch)

    def complete(self, start: int, stop: int, done: _Done,
                 refine: list[int] | None = None) -> list[dict[str, Any] | BatchRow]:  # fmt: skip
        """The rows of samples ``start .. stop - 1`` from the assembled ones (:meth:`done`): refined, in order.

        ``refine``: the samples :meth:`refine` may refine, screened already for many chunks at once
        (:func:`to_refine`); None: screened here.
        """
        first, last = self.spec.line(start)
        if refine is None:
            refine = to_refine([(start, stop, first, last, done.entries)], done.batch, self.rtol)[0]
        extra: list[_Sample] = []
        for k in refine:
            extra += self.refine(k, done, first, last)
        kept = _distinct(extra)
        if not kept and self.spec.finite_order is None and (decided := done.batch_rows(start, stop)) is not None:
            return list(decided)  # every sample's row the batch's, in order: none finished on its own
        if self.spec.finite_order is not None:
            for sample in [done[k] for k in range(start, stop)] + kept:
                assert isinstance(sample.row, dict)  # no batch rows with finite DoF (lockstep.run_group)
                sample.row.update(self.finite(sample.q))
        rows: list[tuple[float, bool, dict[str, Any] | BatchRow]] = [(float(k), False, _finished(done[k].row))
                                                                    for k in range(start, stop)]  # fmt: skip
        if kept:  # the samples' rows are in order
            rows += [(float(_dict(e.row)["_t"]), True, _dict(e.row)) for e in kept]
            rows.sort(key=lambda r: (r[0], r[1]))
        for *_, row in rows:
            if isinstance(row, dict):
                row.pop("_t", None)
        return [row for *_, row in rows]

    def finite(self, q: Array | None) -> dict[str, int | None]:
        """The finite DoF of a row (None: not assembled, or the analysis cannot decide)."""
        if q is None:
            return dict.fromkeys(FINITE_COLUMNS)
        order = self.spec.finite_order
        assert order is not None  # asked for
        conf = Configuration(self.mech, q, closure_tol=self.spec.closure_tol)
        fm = finite_mobility(conf, conf.rank_rtol(self.spec.rtol) if self.spec.cad else self.spec.rtol, order)
        return {"finite_dof": fm.finite_dof, "finite_mechanism_dof": fm.finite_mechanism_dof}

    def refine(self, k: int, done: Mapping[int, _Sample], first: int, last: int) -> list[_Sample]:
        """Refined points around sample k (see the module docstring)."""
        here = done[k]
        if here.q is None or here.distance <= self.rtol:
            return []
        left, right = done.get(k - 1) if k > first else None, done.get(k + 1) if k < last else None
        out = []
        for side in (left, right):  # towards a neighbour that did not assemble: an edge of the reachable set
            if side is not None and side.q is None:  # (the distance may rise before it falls to 0 at the edge)
                out.append(self._search(k, done, "", towards=-1 if side is left else 1))
        if left is not None and right is not None and left.q is not None and right.q is not None:
            for key, d in here.distances.items():
                dl, dr = left.distances[key], right.distances[key]
                if d <= self.rtol or not (min(dl, dr) >= d and max(dl, dr) > d):  # not a local minimum
                    continue
                if d < self.band or vertex_below(k, d, dl, dr, 0.5 * d):
                    out.append(self._search(k, done, key))
        return [s for s in out if s.q is not None and s.distance < self.band]

    def _search(self, k: int, done: Mapping[int, _Sample], key: str, towards: int = 0) -> _Sample:
        """Minimise the distance (of question ``key``; of all questions when empty) around sample k.

        With ``towards`` (-1 or 1), towards that neighbour, which did not assemble: the edge of the reachable
        set is first located by ``EDGE_STEPS`` bisections on whether the mechanism assembles, then the
        distance is minimised between the last point that assembled and the first that did not.
        """
        trials: dict[float, _Sample] = {float(j): s for j, s in done.items() if s.q is not None}
        assembled: dict[float, Array] = {u: s.q for u, s in trials.items() if s.q is not None}

        def value(s: _Sample) -> float:
            return (s.distances.get(key, math.inf) if key else s.distance) if s.q is not None else math.inf

        held: list[float] = []  # the trial points that keep what they examined: the HELD lowest

        def keep(t: float, trial: _Sample) -> float:
            trials[t] = trial
            if trial.examined is not None:  # a few Configurations (each holds a pin.Data) per search, not one a trial
                held.append(t)
                if len(held) > HELD:
                    high = max(held, key=lambda u: value(trials[u]))
                    held.remove(high)
                    trials[high] = replace(trials[high], examined=None)  # its row, if kept, computed again
            return value(trial)

        def assembles(t: float, analysed: bool = True) -> _Sample:
            near = min(assembled, key=lambda u: abs(u - t))
            trial = self.trial(t, assembled[near], analysed)  # warm-started at the nearest
            if trial.q is not None:
                assembled[t] = trial.q
            return trial

        def f(t: float) -> float:
            return keep(t, assembles(t))

        if towards:  # the edge first, by bisection on whether the mechanism assembles: the distance need not
            # fall all the way from sample k to the edge (it may rise first), but it falls to 0 right at a fold;
            # only the last point that assembled is analysed (the minimisation starts there): the others are kept
            # apart from ``trials``, whose points all have their distances
            near, far, bisected = float(k), float(k + towards), dict[float, _Sample]()
            for _ in range(EDGE_STEPS):
                mid = 0.5 * (near + far)
                bisected[mid] = assembles(mid, analysed=False)
                near, far = (near, mid) if bisected[mid].q is None else (mid, far)
            f_near = value(done[k]) if near == k else keep(near, self.with_distances(bisected[near]))
            a, c = (near, far) if towards > 0 else (far, near)
            fa, fc = (f_near, math.inf) if towards > 0 else (math.inf, f_near)
            best = minimise(f, a, near, c, fa, f_near, fc,
                            stop=0.1 * self.rtol, xtol=REFINE_XTOL, max_eval=REFINE_EVALS)  # fmt: skip
        else:
            lo = k - 1 if (k - 1) in done else k
            hi = k + 1 if (k + 1) in done else k
            best = minimise(f, lo, k, hi, value(done[lo]), value(done[k]), value(done[hi]),
                            stop=0.1 * self.rtol, xtol=REFINE_XTOL, max_eval=REFINE_EVALS)  # fmt: skip
        if best.t == k:
            return _Sample({}, None, {})
        return self._mark(self.finish(trials[best.t]), best.t)  # a trial point's row (a sample's: finished)

    @staticmethod
    def _mark(s: _Sample, t: float) -> _Sample:
        _dict(s.row).update(refined=True, _t=t)
        return s


class _Done(Mapping[int, _Sample]):
    """A chunk's assembled samples by index, each finished (:meth:`_Chunk.finish`) when first read.

    A refinement reads a sample and its neighbours (a search, every sample); the rows the batch decided are read
    off its entries (:meth:`entries`, :meth:`batch_rows`) without finishing the samples.
    """

    def __init__(self, chunk: _Chunk, pending: dict[int, _Sample], analysed: Sequence[Analysed | int | None],
                 columns: list[tuple[Any, Any]], batch: BatchRows | None) -> None:  # fmt: skip
        self._chunk, self._pending, self._analysed, self._columns, self._batch = (
            chunk,
            pending,
            analysed,
            columns,
            batch,
        )
        self._index = {k: i for i, k in enumerate(pending)}
        self._made: dict[int, _Sample] = {}

    @property
    def batch(self) -> BatchRows | None:
        """The batch whose entries the rows it decided keep (None: every sample finished on its own)."""
        return self._batch

    def __getitem__(self, k: int) -> _Sample:
        made = self._made.get(k)
        if made is None:
            i = self._index[k]
            made = self._made[k] = self._chunk.finish(self._pending[k], self._analysed[i], *self._columns[i],
                                                      self._batch)  # fmt: skip
        return made

    def __contains__(self, k: object) -> bool:
        return k in self._index

    def __iter__(self) -> Iterator[int]:
        return iter(self._index)

    def __len__(self) -> int:
        return len(self._index)

    def entries(self, lo: int, hi: int) -> list[int]:
        """Each sample's entry in the batch (samples ``lo .. hi - 1``), else -1.

        The entry where the sample's row is the batch's (a :class:`BatchRow` once finished).
        """
        if self._batch is None or not self._chunk.spec.platform:
            return [-1] * (hi - lo)
        index, analysed, pending = self._index, self._analysed, self._pending
        out = []
        for k in range(lo, hi):
            a, sample = analysed[index[k]], pending[k]
            if isinstance(a, (int, np.integer)) and sample.q is not None and sample.known is not None:
                out.append(int(a))
            else:
                out.append(-1)
        return out

    def batch_rows(self, start: int, stop: int) -> list[BatchRow] | None:
        """The rows of samples ``start .. stop - 1`` when the batch decided every one, else None.

        :meth:`_Chunk.finish`'s :class:`BatchRow` of each, made without finishing the sample.
        """
        ats = self.entries(start, stop)
        if not ats or min(ats) < 0:
            return None
        rows = []
        for k, at in zip(range(start, stop), ats):
            made = self._made.get(k)
            if made is not None:  # finished already (a refinement read it): its row
                assert isinstance(made.row, BatchRow)
                rows.append(made.row)
                continue
            values, limits = self._columns[self._index[k]]
            head = self._pending[k].row
            assert not isinstance(head, BatchRow)  # an assembled sample's head
            reason = f"joints outside their limits: {', '.join(limits)}" if limits else ""
            rows.append(BatchRow(at, head, reason, values))
        return rows


def to_refine(chunks: Sequence[tuple[int, int, int, int, Callable[[int, int], list[int]]]], batch: BatchRows | None,
              rtol: float) -> list[list[int]]:  # fmt: skip
    """Per chunk ``(start, stop, first, last, entries)``, the samples :meth:`_Chunk.refine` may refine.

    All but those it would leave, screened with numpy over the batch's distances, every chunk of a group in one pass:
    a sample the batch decided whose neighbours on the line were decided too (assembled: no edge of the reachable set
    next to it), where no question's distance (above ``rtol``, as every decided one is) has a local minimum;
    :meth:`_Chunk.refine` gives no point there. ``first``, ``last``: the chunk's line's first and last samples;
    ``entries``: the samples' entries in the batch where the batch decided them, else -1 (:meth:`_Done.entries`).
    """
    if batch is None or not chunks:
        return [list(range(start, stop)) for start, stop, *_ in chunks]
    at: list[int] = []  # each chunk's entries of its samples and their neighbours, lo .. min(stop, last), in turn
    where: list[int] = []  # where each chunk's run of entries starts, less its lo
    for start, stop, first, last, entries in chunks:
        lo = max(start - 1, first)
        where.append(len(at) - lo)
        at += entries(lo, min(stop, last) + 1)
    counts = np.array([stop - start for start, stop, *_ in chunks])
    chunk = np.repeat(np.arange(len(chunks)), counts)  # each sample's chunk
    before = np.cumsum(counts) - counts
    k = np.repeat([start for start, *_ in chunks], counts) + np.arange(counts.sum()) - np.repeat(before, counts)
    entry = np.array(at)
    pos = np.array(where)[chunk] + k  # each sample's entry in ``entry``
    has_left = k > np.array([first for _, _, first, _, _ in chunks])[chunk]
    has_right = k < np.array([last for _, _, _, last, _ in chunks])[chunk]
    here = entry[pos]
    left = np.where(has_left, entry[np.maximum(pos - 1, 0)], 0)
    right = np.where(has_right, entry[np.minimum(pos + 1, len(entry) - 1)], 0)
    quiet = (here >= 0) & (left >= 0) & (right >= 0)  # decided, and each neighbour decided or off the line
    both = quiet & has_left & has_right
    d, dl, dr = (batch.distances[np.where(both, i, 0)] for i in (here, left, right))
    minimum = ((d > rtol) & (np.minimum(dl, dr) >= d) & (np.maximum(dl, dr) > d)).any(axis=1)
    kept = ~quiet | (both & minimum)
    out: list[list[int]] = [[] for _ in chunks]
    for c, sample in zip(chunk[kept].tolist(), k[kept].tolist()):
        out[c].append(sample)
    return out


def _seed(sample: _Sample, fallback: Array) -> Array:
    """The sample's configuration, or ``fallback`` when it did not assemble."""
    return fallback if sample.q is None else sample.q


def _dict(row: dict[str, Any] | BatchRow | Head) -> dict[str, Any]:
    """A row that is a dict (a trial point's; any row without a batch given to :meth:`_Chunk.complete`)."""
    assert isinstance(row, dict), "a row dict"
    return row


def _finished(row: dict[str, Any] | BatchRow | Head) -> dict[str, Any] | BatchRow:
    """A finished row (:meth:`_Chunk.finish`): a dict or a batch's row, not a head alone."""
    assert not isinstance(row, Head), "a finished row"
    return row


def _distinct(points: list[_Sample]) -> list[_Sample]:
    """Refined points, one per location (within ``SAME_POINT`` sample): the one with the smallest distance."""
    out: list[_Sample] = []
    for p in sorted(points, key=lambda s: s.distance):
        if all(abs(_dict(p.row)["_t"] - _dict(o.row)["_t"]) > SAME_POINT for o in out):
            out.append(p)
    return out


def run_chunk(mech: Mechanism, spec: ScanSpec, start: int, stop: int, seed: Array) -> list[dict[str, Any]]:
    """Rows of samples ``start .. stop - 1`` warm-started from ``seed``, with their refined points."""
    return _Chunk(mech, spec).run(start, stop, seed)
