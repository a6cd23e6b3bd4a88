"""PNG maps of grid scans: a workspace slice as two maps (matplotlib, Agg backend), read back from the CSV file.

:func:`plot_map` draws each sample as a cell centred on it, axes in [m] or
[rad]: the motion type, and the distance to singularity (log scale). Singular
samples are crossed, near-singular ones circled, refined points starred; cells
that were not assembled are left blank, and the legend says so. The shared
helpers are in :mod:`pinmob.scan.results.scan_plot`.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from pinmob.analysis import NEAR_FACTOR
from pinmob.figures import pyplot, save_figure
from pinmob.scan.results.output import header, read_columns
from pinmob.scan.results.scan_plot import FLOOR, MARKS, POSE_UNITS, sample_classes
from pinmob.scan.results.table import ScanTable
from pinmob.screw import RTOL


def _edges(centres: np.ndarray, fallback: float) -> np.ndarray:
    """Cell edges around sorted cell centres: midpoints, and half a spacing beyond the ends."""
    if centres.size == 1:
        return np.array([centres[0] - fallback / 2, centres[0] + fallback / 2])
    mid = (centres[1:] + centres[:-1]) / 2
    return np.concatenate([[2 * centres[0] - mid[0]], mid, [2 * centres[-1] - mid[-1]]])


MAP_COLUMNS = ["refined", "reachable", "singularity", "near_singular", "distance", "motion_type"]


def plot_map(
    csv_path: str | Path | ScanTable,
    png_path: str | Path,
    title: str = "",
    rtol: float = RTOL,
    units: dict[str, str] | None = None,
) -> Path:
    """A grid scan as two maps: motion type, and distance to singularity; returns the PNG path.

    ``units``: a gridded joint's unit (``rad`` or ``m``) by name (pose coordinates know theirs).
    """
    plt = pyplot()
    keys = [k for k in header(csv_path) if k.startswith("grid_")]
    fig = map_figure(read_columns(csv_path, keys + MAP_COLUMNS), keys, rtol, units)
    return save_figure(plt, fig, title or "scan over a workspace slice", png_path)


def axis_label(name: str, units: dict[str, str] | None = None) -> str:
    """A map axis: ``platform x [m]``, or a joint's ``joint A_motor [rad]`` (its unit from ``units``)."""
    if name in POSE_UNITS:
        return f"platform {name} [{POSE_UNITS[name]}]"
    unit = (units or {}).get(name)
    return f"joint {name} [{unit}]" if unit else f"joint {name} [rad or m]"


def map_figure(
    c: dict[str, np.ndarray], keys: list[str], rtol: float = RTOL, units: dict[str, str] | None = None
) -> Any:
    """The figure of :func:`plot_map` from the columns ``keys`` (the two ``grid_`` ones) and ``MAP_COLUMNS``."""
    plt = pyplot()
    from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm
    from matplotlib.patches import Patch
    from matplotlib.ticker import MaxNLocator

    m = sample_classes(c)
    u, v = c[keys[0]], c[keys[1]]
    us, vs = np.unique(u[m["sample"]]), np.unique(v[m["sample"]])
    spacing = [float(np.min(np.diff(a))) for a in (us, vs) if a.size > 1]
    fallback = min(spacing) if spacing else 1.0
    eu, ev = _edges(us, fallback), _edges(vs, fallback)
    iu, iv = np.searchsorted(us, u), np.searchsorted(vs, v)
    reach = m["reach"]
    types = sorted(set(c["motion_type"][reach]))
    code = np.full((us.size, vs.size), np.nan)
    dist = np.full((us.size, vs.size), np.nan)
    for a, b, t, d in zip(iu[reach], iv[reach], c["motion_type"][reach], c["distance"][reach]):
        code[a, b] = types.index(t)
        dist[a, b] = max(d, FLOOR)
    fig, axes = plt.subplots(1, 2, figsize=(13, 5.5))
    palette = plt.get_cmap("tab10")
    if types:
        cmap = ListedColormap([palette(k % 10) for k in range(len(types))]).with_extremes(bad="white")
        norm = BoundaryNorm(np.arange(-0.5, len(types)), cmap.N)
        mesh = axes[0].pcolormesh(eu, ev, np.ma.masked_invalid(code.T), cmap=cmap, norm=norm)
        bar = fig.colorbar(mesh, ax=axes[0], ticks=range(len(types)))
        bar.ax.set_yticklabels(types)
        finite = dist[np.isfinite(dist)]
        lo = min(float(finite.min()), rtol / 10)
        cm2 = plt.get_cmap("viridis").with_extremes(bad="white")
        mesh2 = axes[1].pcolormesh(eu, ev, np.ma.masked_invalid(dist.T), cmap=cm2, norm=LogNorm(vmin=lo, vmax=1.0))
        bar2 = fig.colorbar(mesh2, ax=axes[1], label="distance to singularity ($\\sigma_r / \\sigma_1$)")
        bar2.ax.axhline(rtol, color="red", lw=1.5)
        bar2.ax.axhline(NEAR_FACTOR * rtol, color="darkorange", lw=1.5)
    for ax, name in zip(axes, ("motion type", f"distance (red: rtol = {rtol:.0e}; orange: {NEAR_FACTOR * rtol:.0e})")):
        ax.xaxis.set_major_locator(MaxNLocator(6))
        ax.set_xlim(eu[0], eu[-1])
        ax.set_ylim(ev[0], ev[-1])
        ax.set_title(name, fontsize=10)
        ax.set_xlabel(axis_label(keys[0][5:], units))
        ax.set_ylabel(axis_label(keys[1][5:], units))
        if not types:
            ax.text(0.5, 0.5, "no sample could be assembled", ha="center", va="center", transform=ax.transAxes)
        for key, label in (("singular", "singular"), ("near", "near-singular"), ("refined", "refined singular point")):
            if m[key].any():
                ax.plot(u[m[key]], v[m[key]], label=label, **MARKS[key])
        handles, _ = ax.get_legend_handles_labels()
        if (m["sample"] & ~m["reach"]).any():
            handles.append(Patch(facecolor="white", edgecolor="0.4", label="not assembled (blank)"))
        if handles:
            ax.legend(handles=handles, fontsize=7, loc="upper right", framealpha=0.8)
    return fig
