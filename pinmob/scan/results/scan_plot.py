"""PNG plots of scans (matplotlib, Agg backend), read back from the scan's CSV file.

* :func:`plot_path`: along a path, against the coordinate the path varies most
  (:func:`path_abscissa`: a platform pose coordinate [m or rad], or an actuated
  joint [m or rad]; the path parameter s on the top axis): the singular values
  relative to the largest (``sigma_k / sigma_1``, log scale) of the stacked
  locked-limb wrenches (actuation) and of the stacked limb wrenches
  (constraint), each panel only when that matrix is not empty, with the rank
  threshold ``rtol``; the distance to singularity with ``rtol`` and the
  near-singular band; the DoF. Singular samples, near-singular samples and
  refined singular points are marked, the latter labelled by class; samples
  that could not be assembled are shaded grey.
* :func:`pinmob.scan.results.workspace_map.plot_map`: a workspace slice as two maps.

Every colour and mark has a legend entry. Only the columns drawn are read
(:func:`pinmob.scan.results.output.read_columns`). Absent singular values (a stack with
fewer than six columns) are NaN and not drawn; singular values that are exactly
zero are drawn at ``FLOOR``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from pinmob.analysis import NEAR_FACTOR
from pinmob.figures import pyplot, save_figure
from pinmob.model import Mechanism, linear_velocity_mask
from pinmob.scan.results.output import read_columns
from pinmob.scan.results.table import ScanTable
from pinmob.scan.scan_spec import POSE_COORDS, ScanSpec
from pinmob.screw import RTOL

#: Log-scale floor for singular values and distances that are exactly zero.
FLOOR = 1e-17
#: units of the platform pose coordinates
POSE_UNITS = {"x": "m", "y": "m", "z": "m", "roll": "rad", "pitch": "rad", "yaw": "rad"}
#: shading of samples that could not be assembled
UNREACHABLE = "0.85"

MARKS = {
    "singular": {"marker": "x", "color": "red", "ms": 8, "ls": "none", "mew": 1.5},
    "near": {"marker": "o", "mfc": "none", "color": "darkorange", "ms": 8, "ls": "none", "mew": 1.2},
    "refined": {"marker": "*", "color": "magenta", "ms": 12, "ls": "none", "mec": "black", "mew": 0.5},
}


def sample_classes(c: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
    """Boolean masks: ``sample`` (not refined), ``reach``, ``singular``, ``near``, ``refined``."""
    refined = c["refined"] == 1
    reach = c["reachable"] == 1
    singular = reach & (c["singularity"] != "none") & ~refined
    return {
        "sample": ~refined,
        "reach": reach & ~refined,
        "singular": singular,
        "near": (c["near_singular"] == 1) & ~refined,
        "refined": refined & reach,
    }


def _relative(c: dict[str, np.ndarray], prefix: str) -> np.ndarray:
    """(n, 6) ``sigma_k / sigma_1``: NaN where absent, ``FLOOR`` where exactly zero."""
    s = np.column_stack([c[f"{prefix}{i}"] for i in range(1, 7)])
    top = s[:, :1]
    with np.errstate(invalid="ignore", divide="ignore"):
        rel = s / np.where(top > 0, top, np.nan)
    return np.where(np.isnan(rel), np.nan, np.maximum(rel, FLOOR))


PATH_COLUMNS = ["s", "refined", "reachable", "singularity", "singular_limbs", "near_singular", "distance", "dof",
                *POSE_COORDS] + [f"{p}{i}" for p in ("sv", "av") for i in range(1, 7)]  # fmt: skip
#: The columns of a joint path of a mechanism without a platform (:mod:`pinmob.scan.chain_scan`).
CHAIN_PATH_COLUMNS = [c for c in PATH_COLUMNS if c != "singular_limbs" and c not in POSE_COORDS]
#: Panel titles (actuation, constraint) and the DoF axis of a platform's path plot, and of a closed chain's.
PANELS = {
    True: ("actuation: stacked locked-limb wrenches (actuators locked)", "constraint: stacked limb wrenches",
           "platform DoF"),
    False: ("actuation: actuated joints' rates on the closed chain's motions", "closure: closure Jacobian K",
            "mechanism DoF"),
}  # fmt: skip


@dataclass(frozen=True)
class Abscissa:
    """What a path plot is drawn against: a name with its unit, and its value at every row (s where none varies)."""

    label: str
    values: np.ndarray


def path_abscissa(
    c: dict[str, np.ndarray], length: float = 1.0, joint: tuple[str, str, float, float] | None = None
) -> Abscissa:
    """The coordinate a path varies most, at every row of a path scan.

    Args:
        c: the path scan's columns (``s`` and the pose coordinates).
        length: the mechanism's length scale L [m]: positions are compared with angles as ``x / L``.
        joint: for a path in actuated joints, the joint varying most: ``(name, unit, value at s = 0,
            value at s = 1)``; its value is linear in s.

    Returns:
        that coordinate, or the path parameter s itself when no pose coordinate changes monotonically.
    """
    s = c["s"]
    if joint is not None:
        name, unit, a, b = joint
        return Abscissa(f"actuated joint {name} [{unit}]", a + s * (b - a))
    order = np.argsort(s, kind="stable")
    spans = {}
    for name in POSE_COORDS:
        v = np.asarray(c.get(name, np.full(s.shape, np.nan)), float)
        if not np.all(np.isfinite(v)):
            continue
        if POSE_UNITS[name] == "rad":  # angles in (-pi, pi]: unwrap along the path
            v = v.copy()
            v[order] = np.unwrap(v[order])
        steps = np.diff(v[order])
        span = float(np.ptp(v)) / (length if POSE_UNITS[name] == "m" else 1.0)
        if span > 1e-9 and (np.all(steps >= -1e-9 * span) or np.all(steps <= 1e-9 * span)):
            spans[name] = (span, v)
    if not spans:
        return Abscissa("path parameter s (0: start, 1: end)", s)
    name = max(spans, key=lambda k: spans[k][0])
    return Abscissa(f"platform {name} [{POSE_UNITS[name]}]", spans[name][1])


def _continued(x: Any, xp: np.ndarray, fp: np.ndarray) -> np.ndarray:
    """``np.interp(x, xp, fp)`` continued past both ends along the line through the end points.

    The top s axis maps the whole bottom axis, margins included: clamped there (``np.interp``), s = 0 and 1
    sat at the plot's edges instead of over the first and last samples.
    """
    x = np.asarray(x, float)
    slope = (fp[-1] - fp[0]) / (xp[-1] - xp[0]) if xp[-1] != xp[0] else 0.0
    inside = np.interp(x, xp, fp)
    return np.where(x < xp[0], fp[0] + slope * (x - xp[0]), np.where(x > xp[-1], fp[-1] + slope * (x - xp[-1]), inside))


def varied_joint(mech: Mechanism, spec: ScanSpec) -> tuple[str, str, float, float] | None:
    """For a path in actuated joints, the one varying most (prismatic joints as ``value / L``).

    Returns:
        ``(name, unit, value at s = 0, value at s = 1)``, or None for any other scan.
    """
    if spec.kind != "joints" or spec.a is None or spec.b is None:
        return None
    model = mech.model
    linear = [bool(linear_velocity_mask(model)[model.joints[model.getJointId(n)].idx_v]) for n in spec.joints]
    a, b = np.asarray(spec.a, float), np.asarray(spec.b, float)
    span = np.abs(b - a) / np.where(linear, mech.length_scale, 1.0)
    k = int(np.argmax(span))
    return spec.joints[k], "m" if linear[k] else "rad", float(a[k]), float(b[k])


def plot_path(
    csv_path: str | Path | ScanTable,
    png_path: str | Path,
    title: str = "",
    rtol: float = RTOL,
    length: float = 1.0,
    joint: tuple[str, str, float, float] | None = None,
    platform: bool = True,
) -> Path:
    """Singular values, distance and DoF along a path scan; returns the PNG path (see :func:`path_abscissa`).

    ``platform`` False: a closed chain's joint path (:mod:`pinmob.scan.chain_scan`): its panels and mechanism DoF.
    """
    plt = pyplot()
    c = read_columns(csv_path, PATH_COLUMNS if platform else CHAIN_PATH_COLUMNS)
    fig = path_figure(c, rtol, path_abscissa(c, length, joint), platform)
    return save_figure(plt, fig, title or "scan along a path", png_path)


def path_figure(
    c: dict[str, np.ndarray], rtol: float = RTOL, abscissa: Abscissa | None = None, platform: bool = True
) -> Any:
    """The figure of :func:`plot_path` from the columns ``PATH_COLUMNS`` (else ``CHAIN_PATH_COLUMNS``) of a path."""
    plt = pyplot()
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    m = sample_classes(c)
    s, sample = c["s"], m["sample"]
    axis = abscissa or Abscissa("path parameter s (0: start, 1: end)", s)
    u = axis.values
    band = NEAR_FACTOR * rtol
    panels = [
        (prefix, name, _relative(c, prefix)[sample])
        for prefix, name in (("av", PANELS[platform][0]), ("sv", PANELS[platform][1]))
    ]
    panels = [p for p in panels if not np.all(np.isnan(p[2]))]  # no panel for an empty matrix
    fig, axes = plt.subplots(len(panels) + 1, 1, figsize=(9, 3.4 * (len(panels) + 1)), sharex=True, squeeze=False)
    axes = list(axes[:, 0])
    marked = m["singular"] | m["refined"]
    for ax, (_, name, rel) in zip(axes, panels):
        for k in range(6):
            if np.any(np.isfinite(rel[:, k])):
                ax.semilogy(u[sample], rel[:, k], ".-", lw=1, ms=3, label=f"$\\sigma_{k + 1}/\\sigma_1$")
        ax.axhline(rtol, color="red", ls="--", lw=0.8, label=f"rank threshold rtol = {rtol:.0e}")
        ax.set_ylabel("relative singular value")
        ax.set_title(name, fontsize=9)
        for x in u[marked]:
            ax.axvline(x, color="red", lw=0.8, alpha=0.4)
    ax = axes[-1]
    dist = np.maximum(c["distance"], FLOOR)
    ax.semilogy(u[sample], dist[sample], "k.-", lw=1, ms=3, label="distance to singularity")
    ax.axhline(rtol, color="red", ls="--", lw=0.8, label=f"singular below rtol = {rtol:.0e}")
    ax.axhline(band, color="darkorange", ls=":", lw=0.8, label=f"near-singular below {band:.0e}")
    for key, mask, label in (
        ("singular", m["singular"], "singular sample"),
        ("near", m["near"], "near-singular sample"),
        ("refined", m["refined"], "refined singular point"),
    ):
        if mask.any():
            ax.plot(u[mask], dist[mask], label=label, **MARKS[key])
    span = (float(np.nanmin(u)), float(np.nanmax(u))) if u.size else (0.0, 1.0)
    limbs_of = c["singular_limbs"] if "singular_limbs" in c else np.full(s.shape, "", dtype=object)
    for x, sx, y, label, limbs in zip(u[m["refined"]], s[m["refined"]], dist[m["refined"]],
                                      c["singularity"][m["refined"]], limbs_of[m["refined"]]):  # fmt: skip
        text = f"{label} {limbs.replace(';', ',')}".strip() + (
            f"\nat {x:.6g} (s = {sx:.6g})" if u is not s else f"\ns = {x:.6g}"
        )
        right = x < span[0] + 0.75 * (span[1] - span[0])
        ax.annotate(text, (x, y), textcoords="offset points", xytext=(8 if right else -8, 6), fontsize=7,
                    ha="left" if right else "right")  # fmt: skip
    ax.set_ylabel("distance ($\\sigma_r / \\sigma_1$)")
    ax.set_xlabel(axis.label)
    twin = ax.twinx()
    reach = m["reach"]
    twin.step(u[reach], c["dof"][reach], "b-", where="mid", lw=1, alpha=0.5)
    dof_label = PANELS[platform][2]
    twin.set_ylabel(f"{dof_label} (blue)", color="b")
    twin.set_ylim(-0.5, max(6, float(np.max(c["dof"][reach], initial=0))) + 0.5)
    extra: list[Any] = [Line2D([], [], color="b", alpha=0.5, label=f"{dof_label} (right axis)")]
    if marked.any():
        extra.append(Line2D([], [], color="red", lw=0.8, alpha=0.4, label="singular sample or refined point"))
    unreachable = sample & ~m["reach"]
    if unreachable.any():
        values = np.unique(u[sample])
        half = 0.5 * float(np.min(np.abs(np.diff(values)))) if values.size > 1 else 0.5
        for a in axes:
            for x in u[unreachable]:
                a.axvspan(x - half, x + half, color=UNREACHABLE, lw=0, zorder=0)
        extra.append(Patch(color=UNREACHABLE, label="not assembled"))
    for a in axes[:-1]:
        a.legend(fontsize=7, ncol=4, loc="lower left")
    handles, _ = ax.get_legend_handles_labels()
    ax.legend(handles=handles + extra, fontsize=7, loc="best", ncol=2, framealpha=0.8)
    axes[-1].set_xlim(span[0] - 0.02 * (span[1] - span[0]), span[1] + 0.02 * (span[1] - span[0]))
    order = np.argsort(s[sample], kind="stable")
    if np.sum(np.diff(u[sample][order])) < 0:  # read from the start of the path to its end, left to right
        axes[-1].invert_xaxis()
    if u is not s and np.ptp(u) > 0:
        by_u, by_s = np.argsort(u, kind="stable"), np.argsort(s, kind="stable")
        top = axes[0].secondary_xaxis(
            "top", functions=(lambda x: _continued(x, u[by_u], s[by_u]), lambda t: _continued(t, s[by_s], u[by_s]))
        )
        top.set_xlabel("path parameter s", fontsize=8)
        axes[0].set_title(axes[0].get_title(), fontsize=9, pad=28)
    return fig
