"""What a scan covers: a path or a grid of targets, their order, chunks and seeding walk.

* ``pose path``: platform poses ``M(s) = M_A exp(s log(M_A^-1 M_B))``, s in [0, 1];
* ``joint path``: actuated joint values ``a(s) = (1 - s) a_A + s a_B``, assembled
  by forward kinematics (:func:`pinmob.assembly.assemble.assemble_joints`); its
  ends are configuration names or joint values ``name=value,...``. A mechanism
  without a platform is scanned this way only, each row the whole closed
  chain's answer (:mod:`pinmob.scan.chain`);
* ``grid``: two platform pose coordinates (x, y, z [m], roll, pitch, yaw [rad])
  on a grid, the other four fixed at a reference pose. Its *scan lines* are
  the rows (the first coordinate fixed, the second varying).

Samples are numbered ``k = 0 .. size - 1`` along the scan lines; a fractional
``t`` lies between samples of a line (:meth:`ScanSpec.target`). A line is cut
into chunks of at most ``CHUNK`` samples; the coarse walk that seeds them
(:meth:`ScanSpec.waypoints`) visits every ``STRIDE``-th sample. Running a
spec is :mod:`pinmob.scan`'s business.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.analysis.configuration import Configuration
from pinmob.analysis.generic import generic_constraint_rank
from pinmob.analysis.higher_order import ORDER, check_order
from pinmob.analysis.loop_screws import check_joints
from pinmob.analysis.singularity_analysis import require_platform
from pinmob.assembly.assemble import assemble_pose
from pinmob.assembly.named import closed_configuration
from pinmob.bounds import check_bound
from pinmob.exceptions import ConfigurationError, PinmobError, choices
from pinmob.model.closure import CLOSURE_TOL
from pinmob.model.mechanism import Mechanism
from pinmob.scan.chain import end_values, joint_path_ends, value_joints
from pinmob.screw.algebra import Array
from pinmob.screw.rank import RTOL

POSE_COORDS = ("x", "y", "z", "roll", "pitch", "yaw")
KINDS = ("pose", "joints", "grid")

#: Samples per chunk of a line, and coarse step (in samples) of the walk that seeds the chunks.
CHUNK, STRIDE = 32, 8


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
        finite_order: with a value, each row adds the finite DoF at its configuration (the finite-mobility
            analysis with this order bound, :func:`pinmob.analysis.finite.finite_mobility`); None: not.
        platform: rows about the platform (else about the whole closed chain, :mod:`pinmob.scan.chain`; then
            ``generic_rank`` is the generic closure rank).
        closure_tol: largest closure residual of an assembled sample (position / L, rotation [rad]).
        values: the joints whose values the rows give (a closed chain's, :func:`pinmob.scan.chain.value_joints`).
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
    finite_order: int | None = None
    platform: bool = True
    closure_tol: float = CLOSURE_TOL
    values: tuple[str, ...] = ()

    @property
    def size(self) -> int:
        """Number of samples (path samples, or grid rows times columns)."""
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


def parse_grid_axis(text: str, option: str = "--grid") -> tuple[str, float, float, int]:
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


def resolve_pose(mech: Mechanism, text: str) -> tuple[pin.SE3, Array]:
    """A named configuration, or ``x,y,z,roll,pitch,yaw`` [m, rad]: (platform pose, closed q)."""
    if any(text.casefold() == name.casefold() for name in mech.configurations):
        q = closed_configuration(mech, text)
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
    mech: Mechanism, start: str, end: str, samples: int, *, joints: bool = False, rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL
) -> ScanSpec:  # fmt: skip
    """A path from ``start`` to ``end``: configuration names, poses, or joint values ``name=value,...``.

    A joint path (the actuated joints interpolated) when ``joints`` is set, when an end is joint values, or when
    the mechanism has no platform (then each row is the whole closed chain's answer, :mod:`pinmob.scan.chain`);
    else a path in platform poses.

    Raises:
        PinmobError: fewer than 2 samples, no actuated joint for a joint path, an unknown end or joint, an open end.
    """
    if samples < 2:
        raise ConfigurationError(f"a path needs at least 2 samples, got {samples}")
    check_bound("samples", samples, "the path (--samples)")
    if joints or not mech.has_platform or "=" in start or "=" in end:
        acts, qa, qb, g = joint_path_ends(mech, start, end, rtol, closure_tol)
        va, vb = end_values(mech, acts, start, qa), end_values(mech, acts, end, qb)
        return ScanSpec("joints", qa, va, vb, samples, acts, rtol=rtol, generic_rank=g,
                        platform=mech.has_platform, closure_tol=closure_tol,
                        values=() if mech.has_platform else value_joints(mech))  # fmt: skip
    pa, qa = resolve_pose(mech, start)
    pb, qb = resolve_pose(mech, end)
    if qa.size == 0:
        qa = assemble_pose(mech, pa, _nearest_seed(mech, pa))
    g = generic_constraint_rank(mech, rtol=rtol)
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
    check_bound("samples", out[0][3] * out[1][3], f"the grid ({out[0][3]} x {out[1][3]})")
    pose, q = resolve_pose(mech, at)
    if q.size == 0:
        q = assemble_pose(mech, pose, _nearest_seed(mech, pose))
    g = generic_constraint_rank(mech, rtol=rtol)
    return ScanSpec("grid", q, base=pose_vector(pose), axes=tuple(out), rtol=rtol, generic_rank=g)


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
    check_joints(Configuration(mech, spec.q_ref))
    return replace(spec, finite_order=order)


def _nearest_seed(mech: Mechanism, pose: pin.SE3) -> Array:
    """The named configuration whose platform pose is nearest to ``pose`` (else neutral)."""
    best, seed = np.inf, mech.neutral()
    for name in mech.configurations:
        try:
            q = closed_configuration(mech, name)
        except PinmobError:
            continue
        d = float(np.linalg.norm(pin.log6(platform_pose(mech, q).actInv(pose)).vector))
        if d < best:
            best, seed = d, q
    return seed
