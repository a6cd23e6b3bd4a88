"""What a scan covers: a path or a grid of targets, their order, chunks and seeding walk.

* ``pose path``: platform poses ``M(s) = M_A exp(s log(M_A^-1 M_B))``, s in [0, 1];
* ``coordinate path`` (kind ``coords``): one to three coordinates (some of them pose
  coordinates, :mod:`pinmob.scan.coordinates`) interpolated linearly, ``c(s) = (1 - s) c_A + s c_B``,
  the others held or following (:func:`coordinate_path_spec`);
* ``joint path``: actuated joint values ``a(s) = (1 - s) a_A + s a_B``, assembled
  by forward kinematics (:func:`pinmob.assembly.assemble.assemble_joints`); its
  ends are configuration names or joint values ``name=value,...``. A mechanism
  without a platform is scanned this way only, each row the whole closed
  chain's answer (:mod:`pinmob.scan.chain_scan`);
* ``grid``: one to three coordinates on a grid, each a platform pose coordinate
  (x, y, z [m], roll, pitch, yaw [rad]) or a one-degree joint [rad or m]; of the
  other coordinates, those that can still move at the reference configuration
  (``--at``) are held there and the rest follow the mechanism
  (:mod:`pinmob.scan.coordinates`). Its *scan lines* vary the last coordinate,
  the others fixed (the first varying slowest).

Samples are numbered ``k = 0 .. size - 1`` along the scan lines; a fractional
``t`` lies between samples of a line (:meth:`ScanSpec.target`). A line is cut
into chunks of at most ``CHUNK`` samples (a path), or ``LINE_CHUNK`` (a grid's line: most grids' lines are one
chunk each); the coarse walk that seeds them (:meth:`ScanSpec.waypoints`) visits every ``STRIDE``-th sample (of a
grid's line, up to its last chunk's first sample). Running a
spec is :mod:`pinmob.scan`'s business.
"""

from __future__ import annotations

from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.analysis import ORDER, Configuration, check_joints, check_order, generic_constraint_rank, require_platform
from pinmob.assembly import (
    POSE_COORDS,
    Gaps,
    assemble_coordinates,
    assemble_pose,
    check_closure_tol,
    compiled_kernel,
    frame_gaps,
    gaps_closed,
    pose_from_vector,
    pose_vector,
)
from pinmob.bounds import check_bound
from pinmob.exceptions import ClosureError, ConfigurationError
from pinmob.model import CLOSURE_TOL, Mechanism, parse_joint_values
from pinmob.scan.chain_scan import end_values, joint_path_ends, value_joints
from pinmob.scan.coordinates import check_coordinates, coordinate_values, held_coordinates
from pinmob.scan.references import platform_pose as platform_pose  # re-exported: its home before references.py
from pinmob.scan.references import reference, resolve_pose
from pinmob.screw import RTOL, Array, check_rtol

KINDS = ("pose", "joints", "coords", "grid")

#: A scan's line parameters at many samples (:meth:`ScanSpec.param_columns`): their names and (B, A) values.
ParamColumns = tuple[list[str], Array]

#: Samples per chunk of a path, and coarse step (in samples) of the walk that seeds the chunks.
CHUNK, STRIDE = 32, 8
#: Samples per chunk of a grid's line: a line of up to this many samples is one chunk, seeded at its first sample
#: alone (a chunk of 32 cut a 41-sample line in two, and the walk visited five of its samples: a fifth of the time
#: of a 41 x 41 scan); a group of :data:`pinmob.scan.lockstep.GROUP` chunks then holds as many lines.
LINE_CHUNK = 128


@dataclass(frozen=True)
class ScanSpec:
    """What to scan (picklable; see the module docstring).

    Attributes:
        kind: ``pose``, ``joints``, ``coords`` or ``grid``.
        q_ref: (nq,) closed configuration the walk starts from.
        a, b: path ends: (4, 4) homogeneous poses for ``pose``, (m,) actuated
            values for ``joints``, (k,) values of ``coords`` for ``coords``; unused for ``grid``.
        samples: samples along a path.
        joints: actuated joint names (``joints`` kind).
        axes: one to three grid coordinates: (name, low, high, count) each (a pose coordinate or a joint).
        held: a grid's held coordinates and their values at ``--at``: (name, value) each (:mod:`pinmob.scan.coordinates`).
        start: a grid's gridded coordinates and their values at ``--at`` (where its seeding walk starts).
        coords: a coordinate path's coordinates (``a`` and ``b`` hold their values at its ends).
        rtol: relative tolerance of rank decisions.
        generic_rank: the mechanism's generic constraint rank.
        finite_order: with a value, each row adds the finite DoF at its configuration (the finite-mobility
            analysis with this order bound, :func:`pinmob.analysis.finite.finite_mobility.finite_mobility`); None: not.
        platform: rows about the platform (else about the whole closed chain, :mod:`pinmob.scan.chain_scan`; then
            ``generic_rank`` is the generic closure rank).
        closure_tol: largest closure residual of an assembled sample (position / L, rotation [rad]).
        values: the joints whose values the rows give (:func:`pinmob.scan.chain_scan.value_joints`).
        engine: ``batch`` (a chunk's samples analysed together, :mod:`pinmob.scan.batch_rows`) or ``single``
            (each sample on its own); the same rows, the figures to round-off, where the seeding walk's
            continuation is unique (:func:`pinmob.scan.seeding_walk.chunk_seeds`).
        gaps: with a ``closure_tol`` above the default (:attr:`cad`), the frame placements that hold the
            reference configuration's CAD gaps (:mod:`pinmob.assembly.cad_gaps`): the samples are assembled on
            the mechanism so corrected (:meth:`assembly_mechanism`), and analysed on the file's.
        ends: as given, a path's start and end, or a grid's ``at`` (what :func:`pinmob.scan.results.scan_report.describe`
            names).
    """

    kind: str
    q_ref: Array = field(repr=False)
    a: Array | None = field(default=None, repr=False)
    b: Array | None = field(default=None, repr=False)
    samples: int = 0
    joints: tuple[str, ...] = ()
    axes: tuple[tuple[str, float, float, int], ...] = ()
    held: tuple[tuple[str, float], ...] = ()
    start: tuple[tuple[str, float], ...] = ()
    coords: tuple[str, ...] = ()
    rtol: float = RTOL
    generic_rank: int = 0
    finite_order: int | None = None
    platform: bool = True
    closure_tol: float = CLOSURE_TOL
    values: tuple[str, ...] = ()
    engine: str = "batch"
    gaps: Gaps = ()
    ends: tuple[str, ...] = ()

    @property
    def cad(self) -> bool:
        """A closure tolerance above the default: loops closed to CAD accuracy, each row analysed as ``analyze`` does.

        Each sample is then checked against ``closure_tol`` on the file's mechanism and its rank decisions use
        that sample's tolerance (:meth:`pinmob.analysis.configuration.Configuration.rank_rtol`: at least 10 x its
        closure residual); the rows add its ``residual`` and ``rank_rtol``.
        """
        return self.closure_tol > CLOSURE_TOL

    def reference_rtol(self, mech: Mechanism) -> float:
        """``rtol``; with :attr:`cad`, the rank tolerance at ``q_ref`` (at least 10 x its residual, the gaps held).

        What the refinement and the near-singular band of the summary use (each row has its own, ``rank_rtol``).
        """
        if not self.cad:
            return self.rtol
        return Configuration(mech, self.q_ref, closure_tol=self.closure_tol).rank_rtol(self.rtol)

    def assembly_mechanism(self, mech: Mechanism) -> Mechanism:
        """The mechanism the samples are assembled on: ``mech`` with the reference's gaps held (:attr:`gaps`)."""
        return gaps_closed(mech, self.gaps)

    @property
    def size(self) -> int:
        """Number of samples (path samples, or the product of the grid's counts)."""
        if self.kind == "grid":
            return int(np.prod([a[3] for a in self.axes]))
        return self.samples

    @property
    def line_size(self) -> int:
        """Samples per scan line: the whole path, or one grid line (the last coordinate varying)."""
        return self.axes[-1][3] if self.kind == "grid" else self.samples

    @property
    def varied(self) -> tuple[str, ...]:
        """The coordinates a grid or a coordinate path varies."""
        return tuple(a[0] for a in self.axes) or self.coords

    @property
    def pose_grid(self) -> bool:
        """A grid or a coordinate path with a pose coordinate among its coordinates."""
        return any(c in POSE_COORDS for c in self.varied)

    @property
    def following(self) -> tuple[str, ...]:
        """The pose coordinates that follow the mechanism (neither varied nor held; :mod:`pinmob.scan.coordinates`)."""
        if not self.pose_grid:
            return ()
        given = set(self.varied) | {c for c, _ in self.held}
        return tuple(c for c in POSE_COORDS if c not in given)

    @property
    def target_kind(self) -> str:
        """The kind of every target of the scan (:meth:`target`): ``pose``, ``joints`` or ``coords``."""
        if self.kind in ("pose", "joints"):
            return self.kind
        return "pose" if {*self.varied, *(c for c, _ in self.held)} == set(POSE_COORDS) else "coords"

    def line(self, k: int) -> tuple[int, int]:
        """First and last sample of the scan line holding sample k."""
        first = k - k % self.line_size
        return first, first + self.line_size - 1

    def params(self, t: float) -> dict[str, float]:
        """Scan parameters at sample t (fractional between samples of a line): ``s``, or ``grid_<coordinate>`` each."""
        if self.kind == "grid":
            n_last = self.axes[-1][3]
            r = int(t // n_last)
            lines: list[int] = []  # the line's step along each other coordinate (np.unravel_index, C order)
            left = r
            for n in reversed([a[3] for a in self.axes[:-1]]):
                left, i = divmod(left, n)
                lines.insert(0, i)
            if left:
                raise ValueError(f"sample {t} is beyond the grid's {self.size} samples")
            steps = [*(float(i) for i in lines), t - r * n_last]  # each coordinate's step, the last fractional
            return {"grid_" + name: lo + (hi - lo) * i / (n - 1) if n > 1 else lo
                    for (name, lo, hi, n), i in zip(self.axes, steps)}  # fmt: skip
        return {"s": t / (self.samples - 1) if self.samples > 1 else 0.0}

    def params_of(self, ts: Sequence[float]) -> list[dict[str, float]]:
        """:meth:`params` at each of ``ts``, the same values (the same arithmetic), computed over them at once."""
        names, values = self.param_columns(ts)
        return [dict(zip(names, row)) for row in values.tolist()]

    def param_columns(self, ts: Sequence[float]) -> ParamColumns:
        """:meth:`params_of` as columns: the parameters' names and their (B, A) values, a row per t."""
        t = np.asarray(ts, float)
        if self.kind != "grid":
            return ["s"], (t / (self.samples - 1) if self.samples > 1 else 0.0 * t)[:, None]
        counts = np.array([a[3] for a in self.axes])
        r = t // counts[-1]
        steps = np.empty((len(t), len(counts)))
        steps[:, -1] = t - r * counts[-1]
        left = r.astype(np.int64)
        for j in range(len(counts) - 2, -1, -1):  # np.unravel_index, C order
            left, steps[:, j] = np.divmod(left, counts[j])
        if left.any():
            raise ValueError(f"sample {t[np.flatnonzero(left)[0]]} is beyond the grid's {self.size} samples")
        lo, hi = np.array([a[1] for a in self.axes]), np.array([a[2] for a in self.axes])
        values = np.where(counts > 1, lo + (hi - lo) * steps / np.maximum(counts - 1, 1), lo)
        return ["grid_" + a[0] for a in self.axes], values

    def target(self, t: float, params: dict[str, float] | None = None) -> tuple[str, Any]:
        """``("pose", SE3)``, ``("joints", {name: value})`` or ``("coords", (pose, joints))`` at sample t.

        A grid's target: the gridded and held coordinates (pose coordinates, joint values); a plain pose when
        all six pose coordinates are given and no joint (the others follow, :mod:`pinmob.scan.coordinates`).
        ``params``: :meth:`params` at t, already computed (None: computed here).
        """
        p = self.params(t) if params is None else params
        if self.kind == "grid":
            return self.coordinates_target({name[5:]: value for name, value in p.items()})
        s = p["s"]
        if self.kind == "coords":
            vals = (1 - s) * np.asarray(self.a) + s * np.asarray(self.b)
            return self.coordinates_target(dict(zip(self.coords, vals.tolist())))
        if self.kind == "joints":
            vals = (1 - s) * np.asarray(self.a) + s * np.asarray(self.b)
            return "joints", dict(zip(self.joints, vals.tolist()))
        ma, mb = pin.SE3(np.asarray(self.a)), pin.SE3(np.asarray(self.b))
        return "pose", ma * pin.exp6(s * pin.log6(ma.actInv(mb)))

    def pose_targets(self, ts: Sequence[float], params: ParamColumns | None = None) -> Array:
        """(B, 6) pose coordinates :data:`POSE_COORDS` the targets at samples ``ts`` give (NaN: not given).

        The vectors of :meth:`target` without its poses and dicts: a ``pose`` target's coordinates (a pose path's
        through :func:`~pinmob.assembly.reach.pose_vector`), a ``coords`` target's given pose coordinates (its
        joint values: :meth:`joint_targets`); a joint path's targets give none (every row NaN).
        ``params``: :meth:`param_columns` at ``ts``, already computed (None: computed here).
        """
        if self.kind == "joints":
            return np.full((len(ts), 6), np.nan)
        names, values = self.param_columns(ts) if params is None else params
        if self.kind == "pose":
            return np.array([pose_vector(self.target(t, {"s": s})[1]) for t, s in zip(ts, values[:, 0].tolist())])
        out = np.full((len(ts), 6), np.nan)
        for c, v in self.held:
            if c in POSE_COORDS:
                out[:, POSE_COORDS.index(c)] = v
        varied = [i for i, c in enumerate(self.varied) if c in POSE_COORDS]
        cols = [POSE_COORDS.index(self.varied[i]) for i in varied]
        if not cols:
            return out
        if self.kind == "grid":
            out[:, cols] = values[:, [names.index("grid_" + self.varied[i]) for i in varied]]
        else:  # a coordinate path: c(s) = (1 - s) c_A + s c_B, as target's
            s = values[:, 0]
            out[:, cols] = (1 - s)[:, None] * np.asarray(self.a)[varied] + s[:, None] * np.asarray(self.b)[varied]
        return out

    @property
    def target_joints(self) -> tuple[str, ...]:
        """The joints whose values a grid's or a path's targets give (a grid's varied, then held); a pose path none."""
        if self.kind == "joints":
            return tuple(self.joints)
        if self.kind not in ("grid", "coords"):
            return ()
        return tuple(c for c in (*self.varied, *(c for c, _ in self.held)) if c not in POSE_COORDS)

    def joint_targets(self, ts: Sequence[float], params: ParamColumns | None = None) -> Array:
        """(B, J) the values of :attr:`target_joints` the targets at samples ``ts`` give (as :meth:`target`'s).

        ``params``: :meth:`param_columns` at ``ts``, already computed (None: computed here).
        """
        names, values = self.param_columns(ts) if params is None else params
        held = dict(self.held)
        out = np.empty((len(ts), len(self.target_joints)))
        for i, c in enumerate(self.target_joints):
            if c in held:
                out[:, i] = held[c]
            elif self.kind == "grid":
                out[:, i] = values[:, names.index("grid_" + c)]
            else:  # a path, element by element as target's
                j, s = (i if self.kind == "joints" else self.varied.index(c)), values[:, 0]
                out[:, i] = (1 - s) * np.asarray(self.a)[j] + s * np.asarray(self.b)[j]
        return out

    def coordinates_target(self, gridded: dict[str, float]) -> tuple[str, Any]:
        """A grid's target with the gridded coordinates at ``gridded`` and the held ones at their values."""
        values = dict(self.held) | gridded
        pose = {c: values[c] for c in POSE_COORDS if c in values}
        joints = {c: v for c, v in values.items() if c not in POSE_COORDS}
        if len(pose) == 6 and not joints:
            return "pose", pose_from_vector(np.array([pose[c] for c in POSE_COORDS]))
        return "coords", (pose, joints)

    @property
    def chunk_size(self) -> int:
        """Samples per chunk of a line at most: ``LINE_CHUNK`` on a grid, ``CHUNK`` on a path."""
        return LINE_CHUNK if self.kind == "grid" else CHUNK

    def chunks(self) -> list[tuple[int, int]]:
        """(start, stop) sample ranges: runs of at most :attr:`chunk_size` samples of a line."""
        n, m = self.line_size, self.chunk_size
        return [(first + s, first + min(s + m, n)) for first in range(0, self.size, n) for s in range(0, n, m)]

    def waypoints(self) -> Iterator[tuple[tuple[str, Any], int | None]]:
        """The coarse walk seeding the chunks: ``(target, sample index or None)``.

        A path: every STRIDE-th sample. A grid: straight from the reference
        (``--at``) to the first sample (steps of at most two spacings), then, on
        each line, the chunks' first samples and every STRIDE-th sample between
        them (the first sample alone on a line of at most LINE_CHUNK samples), lines
        alternately forwards and backwards (each move is at most STRIDE
        spacings), a three-coordinate grid's lines in a serpentine (:meth:`line_order`).
        """
        if self.kind != "grid":
            for k in range(0, self.samples, STRIDE):
                yield self.target(k), k
            return
        yield from ((target, None) for target in self.approach())
        n, m = self.line_size, self.chunk_size
        cols = sorted({*range(0, (n - 1) // m * m + 1, STRIDE), *range(0, n, m)})
        for turn, r in enumerate(self.line_order()):
            for c in cols if turn % 2 == 0 else cols[::-1]:
                yield self.target(r * n + c), r * n + c

    def line_order(self) -> list[int]:
        """A grid's lines in the order the seeding walk visits them: a serpentine over the other coordinates."""
        counts = [a[3] for a in self.axes[:-1]]
        if len(counts) < 2:
            return list(range(counts[0] if counts else 1))
        return [
            i * counts[1] + (j if i % 2 == 0 else counts[1] - 1 - j) for i in range(counts[0]) for j in range(counts[1])
        ]

    def approach(self) -> list[tuple[str, Any]]:
        """Grid: the targets from the reference to the first sample, at most two spacings apart."""
        start = {name: value for name, value in self.start}
        first = {name: lo for name, lo, _, _ in self.axes}
        spacing = np.array([(hi - lo) / max(1, n - 1) for _, lo, hi, n in self.axes])
        delta = np.abs(np.array([first[name] - start[name] for name in first]))
        steps = int(np.ceil(np.max(delta / np.where(spacing > 0, 2 * spacing, np.inf), initial=0.0)))
        return [self.coordinates_target({c: start[c] + t * (first[c] - start[c]) for c in first})
                for t in np.arange(1, steps) / steps]  # fmt: skip


def parse_grid_axis(text: str, option: str = "grid axis") -> tuple[str, float, float, int]:
    """``COORD:LO:HI:N`` -> (coordinate, low, high, count); checked by :func:`grid_spec`."""
    parts = text.split(":") if isinstance(text, str) else []
    try:
        if len(parts) != 4:
            raise ValueError
        return parts[0], float(parts[1]), float(parts[2]), int(parts[3])
    except ValueError:
        raise ConfigurationError(
            f"{option} {text!r}: expected COORD:LO:HI:N (four fields separated by ':'), e.g. x:-0.1:0.1:21"
        ) from None


def path_spec(
    mech: Mechanism, start: str, end: str, samples: int, *, joints: bool = False, rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL
) -> ScanSpec:  # fmt: skip
    """A path from ``start`` to ``end``: configuration names, poses, or joint values ``name=value,...``.

    A coordinate path (:func:`coordinate_path_spec`) when an end's values name a pose coordinate; a joint path
    (the actuated joints interpolated) when ``joints`` is set, when an end is joint values, or when the mechanism
    has no platform (then each row is the whole closed chain's answer, :mod:`pinmob.scan.chain_scan`); else a path in
    platform poses.

    Raises:
        PinmobError: fewer than 2 samples, no actuated joint for a joint path, an unknown end or joint, an open end,
            ``closure_tol`` out of range (:func:`~pinmob.assembly.residual.check_closure_tol`).
    """
    return replace(_path_spec(mech, start, end, samples, joints, rtol, closure_tol), ends=(str(start), str(end)))


def _path_spec(
    mech: Mechanism, start: str, end: str, samples: int, joints: bool, rtol: float, closure_tol: float
) -> ScanSpec:
    rtol, closure_tol = check_rtol(rtol), check_closure_tol(closure_tol)
    if samples < 2:
        raise ConfigurationError(f"a path needs at least 2 samples, got {samples}")
    check_bound("samples", samples, "the path (samples)", "samples")
    compiled_kernel()  # numba loaded (when installed) before the generic configurations are closed: by it
    given = [parse_joint_values(t, "path end") if "=" in t else {} for t in (start, end)]
    if mech.has_platform and not joints and any(c in POSE_COORDS for g in given for c in g):
        return coordinate_path_spec(mech, start, end, samples, given, rtol, closure_tol)
    if joints or not mech.has_platform or "=" in start or "=" in end:
        acts, qa, qb, g = joint_path_ends(mech, start, end, rtol, closure_tol)
        va, vb = end_values(mech, acts, start, qa), end_values(mech, acts, end, qb)
        gaps = frame_gaps(mech, qa, closure_tol) if closure_tol > CLOSURE_TOL else ()
        return ScanSpec("joints", qa, va, vb, samples, acts, rtol=rtol, generic_rank=g,
                        platform=mech.has_platform, closure_tol=closure_tol, gaps=gaps,
                        values=value_joints(mech))  # fmt: skip
    pa, qa, gaps = reference(mech, start, closure_tol)
    pb, _ = resolve_pose(mech, end, closure_tol)
    g = generic_constraint_rank(mech, rtol=rtol)
    return ScanSpec("pose", qa, pa.homogeneous, pb.homogeneous, samples, rtol=rtol, generic_rank=g,
                    closure_tol=closure_tol, gaps=gaps, values=value_joints(mech))  # fmt: skip


def coordinate_path_spec(
    mech: Mechanism, start: str, end: str, samples: int, given: list[dict[str, float]], rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL
) -> ScanSpec:  # fmt: skip
    """A path in one to three coordinates (some of them pose coordinates), the others held or following.

    Its ends give the values of the coordinates (``roll=0.2,pitch=0.1``; a configuration end gives all of
    them); they are interpolated linearly. The *reference* is the end that is a configuration (or a pose),
    else the first named configuration: the rule of :mod:`pinmob.scan.coordinates` is taken there, the held
    coordinates keep their values there, and an end's coordinates it does not name too.

    Raises:
        PinmobError: an unknown or too many coordinates, no reference, coordinates that cannot vary
            independently at the reference, a start that does not assemble.
    """
    names = check_coordinates(mech, list(dict.fromkeys([*given[0], *given[1]])), "a coordinate path")
    refs = [t for t in (start, end) if "=" not in t] or list(mech.configurations)[:1]
    if not refs:
        raise ConfigurationError(f"{mech.name!r} declares no configuration: give one end of the path as a pose")
    _, q_ref, gaps = reference(mech, refs[0], closure_tol)
    solver = gaps_closed(mech, gaps)  # the reference closes it exactly: its motions are the file's less the gaps
    held = held_coordinates(solver, q_ref, names, refs[0], rtol)
    at_ref = coordinate_values(mech, q_ref, names + held)
    ends = []
    for text, values in zip((start, end), given):
        if "=" in text:
            ends.append([values.get(n, at_ref[n]) for n in names])
        else:
            end_pose, q_end = resolve_pose(mech, text, closure_tol)
            if q_end.size == 0:
                q_end = assemble_pose(solver, end_pose, q_ref, closure_tol)
            ends.append(list(coordinate_values(mech, q_end, names).values()))
    spec = ScanSpec("coords", q_ref, np.array(ends[0]), np.array(ends[1]), samples, rtol=rtol, closure_tol=closure_tol,
                    generic_rank=generic_constraint_rank(mech, rtol=rtol), held=tuple((c, at_ref[c]) for c in held),
                    coords=names, values=value_joints(mech), gaps=gaps)  # fmt: skip
    kind, target = spec.target(0)
    try:
        if kind == "pose":
            q0 = assemble_pose(solver, target, q_ref, closure_tol)
        else:
            q0 = assemble_coordinates(solver, target[0], target[1], q_ref, closure_tol)
    except ClosureError as exc:
        raise ClosureError(f"path start {start!r} does not assemble from {refs[0]!r}: {exc}", exc.residuals) from None
    return replace(spec, q_ref=q0)


def grid_spec(
    mech: Mechanism, at: str, axes: list[tuple[str, float, float, int]], rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL
) -> ScanSpec:  # fmt: skip
    """A grid over one to three coordinates (pose coordinates or joints) around ``at`` (a configuration or a pose).

    The coordinates not on the grid are held at their values at ``at`` or follow the mechanism
    (:func:`pinmob.scan.coordinates.held_coordinates`). With ``closure_tol`` above the default, ``at`` may close
    only within it (CAD geometry): its gaps are held (:attr:`ScanSpec.cad`, :mod:`pinmob.assembly.cad_gaps`).

    Raises:
        ArgumentError: ``rtol`` or ``closure_tol`` out of range.
        ConfigurationError: no platform, an unknown or repeated coordinate (the message lists the valid ones), an
            empty range, too many samples, or gridded coordinates that cannot vary independently at ``at``.
    """
    rtol, closure_tol = check_rtol(rtol), check_closure_tol(closure_tol)
    require_platform(mech, "grid_spec")
    compiled_kernel()  # numba loaded (when installed) before the generic configurations are closed: by it
    names = check_coordinates(mech, [a[0] for a in axes])
    out = []
    for name, lo, hi, n in axes:
        if n < 1 or not (np.isfinite(lo) and np.isfinite(hi)):
            raise ConfigurationError(f"grid axis {name}: need finite bounds and at least 1 sample, got {lo}, {hi}, {n}")
        out.append((name, float(lo), float(hi), int(n)))
    check_bound("samples", int(np.prod([a[3] for a in out])), f"the grid ({' x '.join(str(a[3]) for a in out)})")
    _, q, gaps = reference(mech, at, closure_tol)
    held = held_coordinates(gaps_closed(mech, gaps), q, names, at, rtol)
    values = coordinate_values(mech, q, names + held)
    g = generic_constraint_rank(mech, rtol=rtol)
    return ScanSpec("grid", q, axes=tuple(out), rtol=rtol, generic_rank=g, closure_tol=closure_tol,
                    held=tuple((c, values[c]) for c in held), start=tuple((c, values[c]) for c in names),
                    values=value_joints(mech), gaps=gaps, ends=(str(at),))  # fmt: skip


def with_finite(mech: Mechanism, spec: ScanSpec, order: int | None = None) -> ScanSpec:
    """``spec`` whose rows add each sample's finite DoF (``pinmob scan --finite``), checked before any sample.

    Args:
        mech: the mechanism scanned.
        spec: the scan.
        order: the order bound of the finite analysis (2..8; None: the default, 4).

    Raises:
        ConfigurationError: a bad order bound, or a joint type the higher-order conditions cannot treat.
    """
    order = check_order(ORDER if order is None else order)
    check_joints(Configuration(mech, spec.q_ref, closure_tol=spec.closure_tol))
    return replace(spec, finite_order=order)
