"""Scans: mobility and singularities along a path or over a workspace slice.

Three kinds of scan, each a sequence of targets that are assembled one after
the other with warm starts (the previous sample's configuration seeds the
closure solver of the next):

* ``pose path``: platform poses ``M(s) = M_A exp(s log(M_A^-1 M_B))``, s in [0, 1];
* ``joint path``: actuated joint values ``a(s) = (1 - s) a_A + s a_B``, assembled
  by forward kinematics (:func:`pinmob.closure.assemble_joints`);
* ``grid``: two platform pose coordinates (x, y, z [m], roll, pitch, yaw [rad])
  on a grid, the other four fixed at a reference pose.

Samples are split into chunks (fixed-size runs of a path, rows of a grid).
Each chunk starts from the reference configuration, walks coarsely to its
first target (every ``stride`` samples of a path; grid steps of at most two
spacings), then runs warm-started. The serial run does exactly the same, so
``workers=N`` gives results identical to ``workers=1``. Results are yielded
one row at a time (memory flat in the number of samples); targets that cannot
be assembled give a row with ``reachable = False``.
"""

from __future__ import annotations

import json
import multiprocessing as mp
from collections.abc import Iterator
from dataclasses import dataclass, field
from multiprocessing.context import BaseContext
from typing import Any

import numpy as np
import pinocchio as pin

from .closure import assemble_joints, assemble_pose
from .exceptions import ConfigurationError, PinmobError, choices
from .mechanism import Mechanism
from .mobility import analyze
from .screw import RTOL, Array
from .singularity import analyze_singularity, generic_constraint_rank

POSE_COORDS = ("x", "y", "z", "roll", "pitch", "yaw")
KINDS = ("pose", "joints", "grid")
SV_COLUMNS = [f"sv{i}" for i in range(1, 7)] + [f"av{i}" for i in range(1, 7)]

#: Samples per chunk of a path, and coarse step (in samples) of the walk to a chunk's start.
CHUNK, STRIDE = 32, 8


def platform_pose(mech: Mechanism, q: Array) -> pin.SE3:
    """World pose of the platform frame at q."""
    data = mech.model.createData()
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

    def params(self, k: int) -> dict[str, float]:
        """Scan parameters of sample k: ``s`` on a path, ``grid_<coordinate>`` (two) on a grid."""
        if self.kind == "grid":
            (i, lo_i, hi_i, n_i), (j, lo_j, hi_j, n_j) = self.axes
            r, c = divmod(k, n_j)
            return {
                "grid_" + POSE_COORDS[i]: float(np.linspace(lo_i, hi_i, n_i)[r]),
                "grid_" + POSE_COORDS[j]: float(np.linspace(lo_j, hi_j, n_j)[c]),
            }
        return {"s": k / (self.samples - 1) if self.samples > 1 else 0.0}

    def target(self, k: int) -> tuple[str, Any]:
        """``("pose", SE3)`` or ``("joints", {name: value})`` for sample k."""
        p = self.params(k)
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
        """(start, stop) sample ranges: rows of a grid, runs of CHUNK samples of a path."""
        if self.kind == "grid":
            n_j = self.axes[1][3]
            return [(r * n_j, (r + 1) * n_j) for r in range(self.axes[0][3])]
        return [(s, min(s + CHUNK, self.samples)) for s in range(0, self.samples, CHUNK)]

    def approach(self, start: int) -> list[tuple[str, Any]]:
        """Targets walked from ``q_ref`` before the first sample of the chunk starting at ``start``."""
        if self.kind != "grid":
            return [self.target(k) for k in range(0, start, STRIDE)]
        (i, lo_i, hi_i, n_i), (j, lo_j, hi_j, n_j) = self.axes
        first = np.array(self.base, float)
        for name, value in self.params(start).items():
            first[POSE_COORDS.index(name[5:])] = value
        base = np.array(self.base, float)
        spacing = np.array([(hi_i - lo_i) / max(1, n_i - 1), (hi_j - lo_j) / max(1, n_j - 1)])
        delta = np.abs(np.array([first[i] - base[i], first[j] - base[j]]))
        steps = int(np.ceil(np.max(delta / np.where(spacing > 0, 2 * spacing, np.inf), initial=0.0)))
        return [("pose", pose_from_vector(base + t * (first - base))) for t in np.arange(1, steps) / steps]


#: Iterations of the closure solver per sample (warm starts converge in a few; unreachable targets fail fast).
MAX_ITER = 40


def _assemble(mech: Mechanism, target: tuple[str, Any], seed: Array) -> Array:
    kind, value = target
    if kind == "pose":
        return assemble_pose(mech, value, seed, max_iter=MAX_ITER)
    return assemble_joints(mech, value, seed, max_iter=MAX_ITER)


def evaluate(mech: Mechanism, q: Array, rtol: float = RTOL, generic_rank: int | None = None) -> dict[str, Any]:
    """One scan row at a closed configuration: pose, DoF, motion type, singularity, singular values."""
    mob = analyze(mech, q, rtol=rtol)
    sing = analyze_singularity(mech, q, rtol=rtol, generic_rank=generic_rank)
    row: dict[str, Any] = dict(zip(POSE_COORDS, pose_vector(platform_pose(mech, q)).tolist()))
    row.update(
        reachable=True,
        dof=mob.dof,
        motion_type=mob.motion_type,
        constraint_rank=mob.constraint_rank,
        locked_dof=sing.locked_dof,
        singularity=sing.label,
        singular_limbs=";".join(sing.limbs),
        uncontrolled=";".join(m.label for m in sing.uncontrolled),
        distance=sing.distance,
    )
    row.update(zip(SV_COLUMNS, [*sing.constraint_singular_values.tolist(), *sing.actuation_singular_values.tolist()]))
    return row


def _unreachable(pose: Array | None) -> dict[str, Any]:
    row: dict[str, Any] = dict(zip(POSE_COORDS, [float("nan")] * 6 if pose is None else pose.tolist()))
    row.update(
        reachable=False,
        dof=-1,
        motion_type="unreachable",
        constraint_rank=-1,
        locked_dof=-1,
        singularity="",
        singular_limbs="",
        uncontrolled="",
        distance=float("nan"),
    )
    row.update(dict.fromkeys(SV_COLUMNS, float("nan")))
    return row


def run_chunk(mech: Mechanism, spec: ScanSpec, start: int, stop: int) -> list[dict[str, Any]]:
    """Rows of samples ``start .. stop - 1`` (walk from ``q_ref`` to the chunk, then warm starts)."""
    q = np.array(spec.q_ref, float)
    for target in spec.approach(start):
        try:
            q = _assemble(mech, target, q)
        except PinmobError:
            continue
    rows = []
    for k in range(start, stop):
        target = spec.target(k)
        head = {"index": k, **spec.params(k)}
        try:
            q = _assemble(mech, target, q)
        except PinmobError:
            rows.append(head | _unreachable(pose_vector(target[1]) if target[0] == "pose" else None))
            continue
        rows.append(head | evaluate(mech, q, spec.rtol, spec.generic_rank))
    return rows


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
    """A path from ``start`` to ``end`` (configuration names or poses; joint paths need names)."""
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
    """A grid over two pose coordinates around the pose of ``at`` (a configuration name)."""
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


def _work(bounds: tuple[int, int]) -> list[dict[str, Any]]:
    return run_chunk(_WORKER["mech"], _WORKER["spec"], *bounds)


def scan(mech: Mechanism, spec: ScanSpec, workers: int = 1, progress: bool | None = None) -> Iterator[dict[str, Any]]:
    """Rows of the scan, in sample order, one at a time.

    Args:
        workers: local processes (1 = in this process); the rows do not depend on it.
        progress: show a tqdm bar on stderr (None: only for scans of 50 samples or more on a terminal).
    """
    from tqdm import tqdm

    if workers < 1:
        raise ConfigurationError(f"--workers must be at least 1, got {workers}")
    chunks = spec.chunks()
    disable = (None if spec.size >= 50 else True) if progress is None else not progress
    bar = tqdm(total=spec.size, disable=disable, unit="sample", desc=f"scan {mech.name}", leave=False)
    try:
        if workers == 1 or len(chunks) == 1:
            for bounds in chunks:
                rows = run_chunk(mech, spec, *bounds)
                bar.update(len(rows))
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
        with ctx.Pool(min(workers, len(chunks)), initializer=_init_worker, initargs=init) as pool:
            for rows in pool.imap(_work, chunks):
                bar.update(len(rows))
                yield from rows
    finally:
        bar.close()


def columns(spec: ScanSpec) -> list[str]:
    """CSV columns of a scan's rows, in order."""
    params = list(spec.params(0))
    return ["index", *params, *POSE_COORDS, "reachable", "dof", "motion_type", "constraint_rank", "locked_dof",
            "singularity", "singular_limbs", "uncontrolled", "distance", *SV_COLUMNS]  # fmt: skip


# --------------------------------------------------------------------------- output


class RowWriter:
    """Stream rows to a CSV file and/or a JSON file (``{"scan": {...}, "samples": [...]}``) as they come.

    Use as a context manager; nothing is kept in memory but the current row.
    """

    def __init__(self, spec: ScanSpec, meta: dict[str, Any], csv_path: str | None = None, json_path: str | None = None):
        self.cols = columns(spec)
        self.meta = meta
        self.csv_path, self.json_path = csv_path, json_path
        self.count = 0

    def __enter__(self) -> RowWriter:
        import csv

        self._csv_fh = open(self.csv_path, "w", newline="") if self.csv_path else None  # noqa: SIM115
        self._csv = csv.DictWriter(self._csv_fh, self.cols) if self._csv_fh else None
        if self._csv:
            self._csv.writeheader()
        self._json = open(self.json_path, "w") if self.json_path else None  # noqa: SIM115
        if self._json:
            self._json.write('{"scan": ' + json.dumps(self.meta) + ', "samples": [')
        return self

    def write(self, row: dict[str, Any]) -> None:
        if self._csv:
            self._csv.writerow({k: (f"{v:.10g}" if isinstance(v, float) else v) for k, v in row.items()})
        if self._json:
            clean = {k: (None if isinstance(v, float) and not np.isfinite(v) else v) for k, v in row.items()}
            self._json.write((",\n" if self.count else "\n") + json.dumps(clean, allow_nan=False))
        self.count += 1

    def __exit__(self, *exc: object) -> None:
        if self._json:
            self._json.write("\n]}\n")
            self._json.close()
        if self._csv_fh:
            self._csv_fh.close()
