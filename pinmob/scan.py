"""Scans: mobility and singularities along a path or over a workspace slice.

Three kinds of scan, each a sequence of targets assembled one after the other
with warm starts (the previous sample's configuration seeds the closure
solver of the next):

* ``pose path``: platform poses ``M(s) = M_A exp(s log(M_A^-1 M_B))``, s in [0, 1];
* ``joint path``: actuated joint values ``a(s) = (1 - s) a_A + s a_B``, assembled
  by forward kinematics (:func:`pinmob.closure.assemble_joints`);
* ``grid``: two platform pose coordinates (x, y, z [m], roll, pitch, yaw [rad])
  on a grid, the other four fixed at a reference pose. Its *scan lines* are
  the rows (the first coordinate fixed, the second varying).

Samples are numbered ``k = 0 .. size - 1`` along the scan lines; a fractional
``t`` lies between samples of a line (:meth:`ScanSpec.target`). They are run in
chunks of at most ``CHUNK`` samples of a line. One coarse walk
(:func:`chunk_seeds`, in this process) goes from the reference configuration
through every ``STRIDE``-th sample of each line (a grid row by row, in a
serpentine) and gives each chunk its seed; every chunk then runs warm-started
from its seed, in this process or in a worker, so ``workers=N`` gives the rows
of ``workers=1``, and each sample costs ``1 + 1/STRIDE`` assemblies plus two per
chunk (its neighbours on the line, for the refinement).

Refinement (:mod:`pinmob.refine`): a singularity between samples is found
where, along a line, a distance to singularity has a local minimum above
``rtol`` (each question on its own: constraint, actuation, each limb), when
the V through the three samples predicts a value below the near-singular band,
or where a sample borders an unreachable one (the edge of the reachable set,
where a limb's inverse kinematics is singular). The line parameter is refined
(re-assembling warm-started at each trial) and the best point is reported as
an extra row (``refined`` True) when its distance is below the band. The end
samples of a path whose distance is below the band are re-assembled with more
solver iterations (the solver converges slowly at a singularity).

Rows are yielded one at a time, in order of ``t`` (memory flat in the number of
samples); targets that cannot be assembled give a row with ``reachable = False``.
"""

from __future__ import annotations

import math
import multiprocessing as mp
from collections.abc import Iterator
from dataclasses import dataclass, field
from multiprocessing.context import BaseContext
from typing import Any

import numpy as np
import pinocchio as pin

from .closure import assemble_joints, assemble_pose, compute_kinematics
from .exceptions import ConfigurationError, PinmobError, choices
from .mechanism import Mechanism
from .refine import minimise, v_vertex
from .screw import RTOL, Array
from .singularity import NEAR_FACTOR, analyze_both, generic_constraint_rank, require_platform

POSE_COORDS = ("x", "y", "z", "roll", "pitch", "yaw")
KINDS = ("pose", "joints", "grid")
SV_COLUMNS = [f"sv{i}" for i in range(1, 7)] + [f"av{i}" for i in range(1, 7)]

#: Samples per chunk of a line, and coarse step (in samples) of the walk that seeds the chunks.
CHUNK, STRIDE = 32, 8

#: Iterations of the closure solver per sample (warm starts converge in a few; unreachable targets fail fast).
MAX_ITER = 40

#: Iterations per assembly while refining (the solver converges slowly next to a singularity).
REFINE_ITER = 100

#: Evaluations per refinement, and bracket width (in samples) at which it stops.
REFINE_EVALS, REFINE_XTOL = 60, 1e-12


def platform_pose(mech: Mechanism, q: Array, data: pin.Data | None = None) -> pin.SE3:
    """World pose of the platform frame at q."""
    data = mech.model.createData() if data is None else data
    pin.framesForwardKinematics(mech.model, data, q)
    return pin.SE3(data.oMf[mech.platform_id])


def pose_vector(pose: pin.SE3) -> Array:
    """(6,) ``[x, y, z, roll, pitch, yaw]`` [m, rad] of a pose."""
    return np.concatenate([pose.translation, pin.rpy.matrixToRpy(pose.rotation)])


def pose_from_vector(v: Array) -> pin.SE3:
    """Pose from ``[x, y, z, roll, pitch, yaw]`` [m, rad]."""
    v = np.asarray(v, float)
    return pin.SE3(pin.rpy.rpyToMatrix(v[3:]), v[:3])


@dataclass(frozen=True)
class ScanSpec:
    """What to scan (picklable; see the module docstring).

    Attributes:
        kind: ``pose``, ``joints`` or ``grid``.
        q_ref: (nq,) closed configuration the walk starts from.
        a, b: path ends: (4, 4) homogeneous poses for ``pose``, (m,) actuated
            values for ``joints``; unused for ``grid``.
        samples: samples along a path.
        joints: actuated joint names (``joints`` kind).
        base: (6,) reference pose vector of a grid.
        axes: two grid coordinates: (index in POSE_COORDS, low, high, count) each.
        rtol: relative tolerance of rank decisions.
        generic_rank: the mechanism's generic constraint rank.
    """

    kind: str
    q_ref: Array = field(repr=False)
    a: Array | None = field(default=None, repr=False)
    b: Array | None = field(default=None, repr=False)
    samples: int = 0
    joints: tuple[str, ...] = ()
    base: Array | None = field(default=None, repr=False)
    axes: tuple[tuple[int, float, float, int], ...] = ()
    rtol: float = RTOL
    generic_rank: int = 0

    @property
    def size(self) -> int:
        if self.kind == "grid":
            return self.axes[0][3] * self.axes[1][3]
        return self.samples

    @property
    def line_size(self) -> int:
        """Samples per scan line: the whole path, or one grid row."""
        return self.axes[1][3] if self.kind == "grid" else self.samples

    def line(self, k: int) -> tuple[int, int]:
        """First and last sample of the scan line holding sample k."""
        first = k - k % self.line_size
        return first, first + self.line_size - 1

    def params(self, t: float) -> dict[str, float]:
        """Scan parameters at sample t (fractional between samples of a line): ``s``, or ``grid_<coordinate>`` (two)."""
        if self.kind == "grid":
            (i, lo_i, hi_i, n_i), (j, lo_j, hi_j, n_j) = self.axes
            r = int(t // n_j)
            c = t - r * n_j
            return {
                "grid_" + POSE_COORDS[i]: lo_i + (hi_i - lo_i) * r / (n_i - 1) if n_i > 1 else lo_i,
                "grid_" + POSE_COORDS[j]: lo_j + (hi_j - lo_j) * c / (n_j - 1) if n_j > 1 else lo_j,
            }
        return {"s": t / (self.samples - 1) if self.samples > 1 else 0.0}

    def target(self, t: float) -> tuple[str, Any]:
        """``("pose", SE3)`` or ``("joints", {name: value})`` at sample t (fractional between samples of a line)."""
        p = self.params(t)
        if self.kind == "grid":
            v = np.array(self.base, float)
            for name, value in p.items():
                v[POSE_COORDS.index(name[5:])] = value
            return "pose", pose_from_vector(v)
        s = p["s"]
        if self.kind == "joints":
            vals = (1 - s) * np.asarray(self.a) + s * np.asarray(self.b)
            return "joints", dict(zip(self.joints, vals.tolist()))
        ma, mb = pin.SE3(np.asarray(self.a)), pin.SE3(np.asarray(self.b))
        return "pose", ma * pin.exp6(s * pin.log6(ma.actInv(mb)))

    def chunks(self) -> list[tuple[int, int]]:
        """(start, stop) sample ranges: runs of at most CHUNK samples of a line."""
        n = self.line_size
        return [(first + s, first + min(s + CHUNK, n)) for first in range(0, self.size, n) for s in range(0, n, CHUNK)]

    def waypoints(self) -> Iterator[tuple[tuple[str, Any], int | None]]:
        """The coarse walk seeding the chunks: ``(target, sample index or None)``.

        A path: every STRIDE-th sample. A grid: straight from the reference pose
        to the first sample (steps of at most two spacings), then every
        STRIDE-th sample and the last of each row, rows alternately forwards
        and backwards (each move is at most STRIDE spacings).
        """
        if self.kind != "grid":
            for k in range(0, self.samples, STRIDE):
                yield self.target(k), k
            return
        yield from ((target, None) for target in self.approach())
        n = self.line_size
        cols = sorted({*range(0, n, STRIDE), n - 1})
        for r in range(self.axes[0][3]):
            for c in cols if r % 2 == 0 else cols[::-1]:
                yield self.target(r * n + c), r * n + c

    def approach(self) -> list[tuple[str, Any]]:
        """Grid: the targets from the reference pose to the first sample, at most two spacings apart."""
        (i, lo_i, hi_i, n_i), (j, lo_j, hi_j, n_j) = self.axes
        base = np.array(self.base, float)
        first = base.copy()
        first[[i, j]] = lo_i, lo_j
        spacing = np.array([(hi_i - lo_i) / max(1, n_i - 1), (hi_j - lo_j) / max(1, n_j - 1)])
        delta = np.abs(np.array([first[i] - base[i], first[j] - base[j]]))
        steps = int(np.ceil(np.max(delta / np.where(spacing > 0, 2 * spacing, np.inf), initial=0.0)))
        return [("pose", pose_from_vector(base + t * (first - base))) for t in np.arange(1, steps) / steps]


def _assemble(mech: Mechanism, target: tuple[str, Any], seed: Array, max_iter: int = MAX_ITER) -> Array:
    kind, value = target
    if kind == "pose":
        return assemble_pose(mech, value, seed, max_iter=max_iter)
    return assemble_joints(mech, value, seed, max_iter=max_iter)


def chunk_seeds(mech: Mechanism, spec: ScanSpec) -> Iterator[tuple[int, int, Array]]:
    """``(start, stop, seed)`` of every chunk, in order, from one coarse walk (:meth:`ScanSpec.waypoints`).

    The seed is the walk's configuration at the chunk's first sample (or, when
    that does not assemble, at the last waypoint that did).
    """
    stops = dict(spec.chunks())
    order = list(stops)
    found: dict[int, Array] = {}
    q = np.array(spec.q_ref, float)
    for target, k in spec.waypoints():
        try:
            q = _assemble(mech, target, q)
        except PinmobError:
            pass
        if k in stops:
            found[k] = q
        while order and order[0] in found:
            start = order.pop(0)
            yield start, stops[start], found.pop(start)


# --------------------------------------------------------------------------- rows


def evaluate(
    mech: Mechanism, q: Array, rtol: float = RTOL, generic_rank: int | None = None, data: pin.Data | None = None
) -> dict[str, Any]:
    """One scan row at a closed configuration: pose, DoF, motion type, singularity, singular values."""
    return _evaluate(mech, q, rtol, generic_rank, data)[0]


def _evaluate(
    mech: Mechanism, q: Array, rtol: float, generic_rank: int | None, data: pin.Data | None = None
) -> tuple[dict[str, Any], dict[str, float]]:
    """The row and the distance of each question, from one kinematics computation."""
    g = generic_constraint_rank(mech, rtol=rtol) if generic_rank is None else generic_rank
    data = mech.model.createData() if data is None else data
    compute_kinematics(mech.model, data, q)
    mob, sing = analyze_both(mech, data, g, rtol=rtol)
    row: dict[str, Any] = dict(zip(POSE_COORDS, pose_vector(data.oMf[mech.platform_id]).tolist()))
    row.update(
        reachable=True,
        dof=mob.dof,
        motion_type=mob.motion_type,
        constraint_rank=mob.constraint_rank,
        locked_dof=sing.locked_dof,
        singularity=sing.label,
        near_singular=sing.near_singular,
        closest=sing.closest,
        singular_limbs=";".join(sing.limbs),
        dependent_limbs=";".join(sing.dependent_limbs),
        uncontrolled=";".join(m.label for m in sing.uncontrolled),
        distance=sing.distance,
    )
    row.update(zip(SV_COLUMNS, [*sing.constraint_singular_values.tolist(), *sing.actuation_singular_values.tolist()]))
    return row, sing.distances


def _unreachable(pose: Array | None) -> dict[str, Any]:
    row: dict[str, Any] = dict(zip(POSE_COORDS, [float("nan")] * 6 if pose is None else pose.tolist()))
    row.update(reachable=False, dof=-1, motion_type="unreachable", constraint_rank=-1, locked_dof=-1, singularity="",
               near_singular=False, closest="", singular_limbs="", dependent_limbs="", uncontrolled="",
               distance=float("nan"))  # fmt: skip
    row.update(dict.fromkeys(SV_COLUMNS, float("nan")))
    return row


@dataclass
class _Sample:
    """A sample or trial point of a chunk: its row, configuration (None: unreachable) and distances."""

    row: dict[str, Any]
    q: Array | None
    distances: dict[str, float]

    @property
    def distance(self) -> float:
        return min(self.distances.values(), default=1.0) if self.q is not None else math.inf


class _Chunk:
    """Runs one chunk: its samples, their two neighbours on the line, and the refinements."""

    def __init__(self, mech: Mechanism, spec: ScanSpec) -> None:
        self.mech, self.spec = mech, spec
        self.data = mech.model.createData()
        self.band = NEAR_FACTOR * spec.rtol

    def sample(self, t: float, seed: Array, max_iter: int = MAX_ITER) -> _Sample:
        target = self.spec.target(t)
        head = {"index": int(math.floor(t + 1e-9)), **self.spec.params(t), "refined": False}
        try:
            q = _assemble(self.mech, target, seed, max_iter)
        except PinmobError:
            return _Sample(head | _unreachable(pose_vector(target[1]) if target[0] == "pose" else None), None, {})
        row, distances = _evaluate(self.mech, q, self.spec.rtol, self.spec.generic_rank, self.data)
        return _Sample(head | row, q, distances)

    def run(self, start: int, stop: int, seed: Array) -> list[dict[str, Any]]:
        first, last = self.spec.line(start)
        done: dict[int, _Sample] = {}
        q = seed
        for k in range(start, min(stop, last) + 1):
            done[k] = self.sample(k, q)
            q = _seed(done[k], q)
        if start > first:
            done[start - 1] = self.sample(start - 1, _seed(done[start], seed))
        extra: list[_Sample] = []
        for k in range(start, stop):
            extra += self.refine(k, done, first, last)
        rows = [(float(k), done[k].row) for k in range(start, stop)]
        rows += [(float(e.row["_t"]), e.row) for e in _distinct(extra)]
        rows.sort(key=lambda r: (r[0], r[1]["refined"]))
        for _, row in rows:
            row.pop("_t", None)
        return [row for _, row in rows]

    def refine(self, k: int, done: dict[int, _Sample], first: int, last: int) -> list[_Sample]:
        """Refined points around sample k (see the module docstring)."""
        here = done[k]
        if here.q is None or here.distance <= self.spec.rtol:
            return []
        left, right = done.get(k - 1) if k > first else None, done.get(k + 1) if k < last else None
        out = []
        sides = [s for s in (left, right) if s is not None]
        if any(s.q is None for s in sides) and all(s.q is None or s.distance > here.distance for s in sides):
            out.append(self._search(k, done, ""))
        if left is not None and right is not None and left.q is not None and right.q is not None:
            for key, d in here.distances.items():
                dl, dr = left.distances[key], right.distances[key]
                if d <= self.spec.rtol or not (min(dl, dr) >= d and max(dl, dr) > d):  # not a local minimum
                    continue
                if d < self.band or _vertex_below(k, d, dl, dr, 0.5 * d):
                    out.append(self._search(k, done, key))
        return [s for s in out if s.q is not None and s.distance < self.band]

    def _search(self, k: int, done: dict[int, _Sample], key: str) -> _Sample:
        """Minimise the distance (of question ``key``; of all questions when empty) around sample k."""
        trials: dict[float, _Sample] = {float(j): s for j, s in done.items() if s.q is not None}

        def value(s: _Sample) -> float:
            return (s.distances.get(key, math.inf) if key else s.distance) if s.q is not None else math.inf

        def f(t: float) -> float:
            near = min(trials, key=lambda u: abs(u - t))
            trials[t] = self.sample(t, _seed(trials[near], self.spec.q_ref), REFINE_ITER)
            return value(trials[t])

        lo = k - 1 if (k - 1) in done else k
        hi = k + 1 if (k + 1) in done else k
        best = minimise(f, lo, k, hi, value(done[lo]), value(done[k]), value(done[hi]),
                        stop=0.1 * self.spec.rtol, xtol=REFINE_XTOL, max_eval=REFINE_EVALS)  # fmt: skip
        if best.t == k:
            return _Sample({}, None, {})
        return self._mark(trials[best.t], best.t)

    @staticmethod
    def _mark(s: _Sample, t: float) -> _Sample:
        s.row.update(refined=True, _t=t)
        return s


def _seed(sample: _Sample, fallback: Array) -> Array:
    """The sample's configuration, or ``fallback`` when it did not assemble."""
    return fallback if sample.q is None else sample.q


def _vertex_below(k: int, d: float, dl: float, dr: float, level: float) -> bool:
    """The V through the three samples (:func:`pinmob.refine.v_vertex`) predicts a minimum below ``level``."""
    vertex = v_vertex(k - 1, k, k + 1, dl, d, dr)
    return vertex is not None and vertex[1] < level


def _distinct(points: list[_Sample]) -> list[_Sample]:
    """Refined points, one per location (within 1e-6 sample): the one with the smallest distance."""
    out: list[_Sample] = []
    for p in sorted(points, key=lambda s: s.distance):
        if all(abs(p.row["_t"] - o.row["_t"]) > 1e-6 for o in out):
            out.append(p)
    return out


def run_chunk(mech: Mechanism, spec: ScanSpec, start: int, stop: int, seed: Array) -> list[dict[str, Any]]:
    """Rows of samples ``start .. stop - 1`` warm-started from ``seed``, with their refined points."""
    return _Chunk(mech, spec).run(start, stop, seed)


# --------------------------------------------------------------------------- building specs


def resolve_pose(mech: Mechanism, text: str) -> tuple[pin.SE3, Array]:
    """A named configuration, or ``x,y,z,roll,pitch,yaw`` [m, rad]: (platform pose, closed q)."""
    if text in mech.configurations:
        q = mech.configuration(text)
        return platform_pose(mech, q), q
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 6 or not np.all(np.isfinite(values)):
        raise ConfigurationError(
            f"{text!r} is neither a configuration of {mech.name!r} ({choices(mech.configurations)}) "
            "nor a pose 'x,y,z,roll,pitch,yaw' [m, rad]"
        )
    return pose_from_vector(np.array(values)), np.array([])


def path_spec(
    mech: Mechanism, start: str, end: str, samples: int, *, joints: bool = False, rtol: float = RTOL
) -> ScanSpec:
    """A path from ``start`` to ``end`` (configuration names or poses; joint paths need names).

    Raises:
        ConfigurationError: fewer than 2 samples, no platform frame, a joint path without actuated joints or names.
    """
    require_platform(mech, "pinmob scan")
    if samples < 2:
        raise ConfigurationError(f"a path needs at least 2 samples, got {samples}")
    pa, qa = resolve_pose(mech, start)
    pb, qb = resolve_pose(mech, end)
    if qa.size == 0:
        qa = assemble_pose(mech, pa, _nearest_seed(mech, pa))
    g = generic_constraint_rank(mech, rtol=rtol)
    if joints:
        if not mech.actuated:
            raise ConfigurationError(f"{mech.name!r} declares no actuated joint; a joint path needs some")
        if qb.size == 0:
            raise ConfigurationError("a joint path goes between two named configurations")
        idx = [mech.model.joints[mech.model.getJointId(n)].idx_q for n in mech.actuated]
        return ScanSpec("joints", qa, qa[idx], qb[idx], samples, mech.actuated, rtol=rtol, generic_rank=g)
    return ScanSpec("pose", qa, pa.homogeneous, pb.homogeneous, samples, rtol=rtol, generic_rank=g)


def grid_spec(mech: Mechanism, at: str, axes: list[tuple[str, float, float, int]], rtol: float = RTOL) -> ScanSpec:
    """A grid over two pose coordinates around the pose of ``at`` (a configuration name or a pose)."""
    require_platform(mech, "pinmob scan")
    if len(axes) != 2 or axes[0][0] == axes[1][0]:
        raise ConfigurationError(f"a grid needs two different coordinates, got {[a[0] for a in axes]}")
    out = []
    for name, lo, hi, n in axes:
        if name not in POSE_COORDS:
            raise ConfigurationError(f"unknown grid coordinate {name!r}; valid: {choices(POSE_COORDS)}")
        if n < 1 or not (np.isfinite(lo) and np.isfinite(hi)):
            raise ConfigurationError(f"grid axis {name}: need finite bounds and at least 1 sample, got {lo}, {hi}, {n}")
        out.append((POSE_COORDS.index(name), float(lo), float(hi), int(n)))
    pose, q = resolve_pose(mech, at)
    if q.size == 0:
        q = assemble_pose(mech, pose, _nearest_seed(mech, pose))
    g = generic_constraint_rank(mech, rtol=rtol)
    return ScanSpec("grid", q, base=pose_vector(pose), axes=tuple(out), rtol=rtol, generic_rank=g)


def _nearest_seed(mech: Mechanism, pose: pin.SE3) -> Array:
    """The named configuration whose platform pose is nearest to ``pose`` (else neutral)."""
    best, seed = np.inf, mech.neutral()
    for name in mech.configurations:
        try:
            q = mech.configuration(name)
        except PinmobError:
            continue
        d = float(np.linalg.norm(pin.log6(platform_pose(mech, q).actInv(pose)).vector))
        if d < best:
            best, seed = d, q
    return seed


# --------------------------------------------------------------------------- running

_WORKER: dict[str, Any] = {}


def _init_worker(mech: Mechanism | str, spec: ScanSpec) -> None:
    """Worker set-up: the mechanism (forked workers) or the file to load it from (spawned workers)."""
    if isinstance(mech, str):
        from .mechanism_file import load

        mech = load(mech)
    _WORKER.update(mech=mech, spec=spec)


def _work(job: tuple[int, int, Array]) -> list[dict[str, Any]]:
    return run_chunk(_WORKER["mech"], _WORKER["spec"], *job)


def scan(mech: Mechanism, spec: ScanSpec, workers: int = 1, progress: bool | None = None) -> Iterator[dict[str, Any]]:
    """Rows of the scan (samples and refined points), in order of the line parameter, one at a time.

    Args:
        workers: local processes (1 = in this process); the rows do not depend on it.
        progress: show a tqdm bar on stderr (None: only for scans of 50 samples or more on a terminal).
    """
    from tqdm import tqdm

    if workers < 1:
        raise ConfigurationError(f"--workers must be at least 1, got {workers}")
    jobs = chunk_seeds(mech, spec)
    disable = (None if spec.size >= 50 else True) if progress is None else not progress
    bar = tqdm(total=spec.size, disable=disable, unit="sample", desc=f"scan {mech.name}", leave=False)
    try:
        if workers == 1 or len(spec.chunks()) == 1:
            for job in jobs:
                rows = run_chunk(mech, spec, *job)
                bar.update(job[1] - job[0])
                yield from rows
            return
        init: tuple[Mechanism | str, ScanSpec]
        if "fork" in mp.get_all_start_methods():
            ctx: BaseContext = mp.get_context("fork")
            init = (mech, spec)
        else:
            if mech.source is None:
                raise ConfigurationError("--workers > 1 needs a mechanism loaded from a file on this platform")
            ctx, init = mp.get_context("spawn"), (str(mech.source), spec)
        with ctx.Pool(min(workers, len(spec.chunks())), initializer=_init_worker, initargs=init) as pool:
            for rows in pool.imap(_work, jobs):
                bar.update(sum(not r["refined"] for r in rows))
                yield from rows
    finally:
        bar.close()


def columns(spec: ScanSpec) -> list[str]:
    """CSV columns of a scan's rows, in order."""
    params = list(spec.params(0))
    return ["index", *params, "refined", *POSE_COORDS, "reachable", "dof", "motion_type", "constraint_rank",
            "locked_dof", "singularity", "near_singular", "closest", "singular_limbs", "dependent_limbs",
            "uncontrolled", "distance", *SV_COLUMNS]  # fmt: skip
