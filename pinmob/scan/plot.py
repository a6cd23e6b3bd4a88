"""PNG plots of scans (matplotlib, Agg backend), read back from the scan's CSV file.

* :func:`plot_path`: along a path, the singular values relative to the
  largest (``sigma_k / sigma_1``, log scale) of the stacked limb wrenches
  (constraint) and of the stacked locked-limb wrenches (actuation), with the
  rank threshold ``rtol``; the distance to singularity with ``rtol`` and the
  near-singular band; the DoF. Singular samples, near-singular samples and
  refined singular points are marked, the latter labelled by class.
* :func:`plot_map`: a workspace slice as two maps, each sample a cell centred
  on it: the motion type, and the distance to singularity (log scale).
  Singular samples are crossed, near-singular ones circled, refined points
  starred; cells that were not assembled are left blank.

Only the columns drawn are read (:func:`pinmob.scan.output.read_columns`).
Absent singular values (a stack with fewer than six columns) are NaN and not
drawn; singular values that are exactly zero are drawn at ``FLOOR``.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from pinmob.analysis.singularity import NEAR_FACTOR
from pinmob.scan.files import Replacing
from pinmob.scan.output import header, read_columns
from pinmob.screw.rank import RTOL

#: Log-scale floor for singular values and distances that are exactly zero.
FLOOR = 1e-17

_MARKS = {
    "singular": {"marker": "x", "color": "red", "ms": 8, "ls": "none", "mew": 1.5},
    "near": {"marker": "o", "mfc": "none", "color": "darkorange", "ms": 8, "ls": "none", "mew": 1.2},
    "refined": {"marker": "*", "color": "magenta", "ms": 12, "ls": "none", "mec": "black", "mew": 0.5},
}


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_png(fig: Any, png_path: str | Path, title: str | None = None, metadata: dict[str, str] | None = None) -> Path:
    """Title (if any), lay out, write the PNG and close the figure (the scans' and the sweeps' plots alike).

    110 dpi, ``metadata`` in the PNG's text chunks, written through a temporary file renamed at the end.
    """
    import matplotlib.pyplot as plt

    if title is not None:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    replacing = Replacing(png_path)
    try:
        with replacing as tmp:
            fig.savefig(tmp, dpi=110, format="png", metadata=metadata)
            replacing.commit()
    finally:
        plt.close(fig)
    return Path(png_path)


def _classes(c: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
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


PATH_COLUMNS = ["s", "refined", "reachable", "singularity", "singular_limbs", "near_singular", "distance", "dof"] + [
    f"{p}{i}" for p in ("sv", "av") for i in range(1, 7)
]


def plot_path(csv_path: str | Path, png_path: str | Path, title: str = "", rtol: float = RTOL) -> Path:
    """Singular values, distance and DoF along a path scan; returns the PNG path."""
    fig = path_figure(read_columns(csv_path, PATH_COLUMNS), rtol)
    return save_png(fig, png_path, title or "scan along a path")


def path_figure(c: dict[str, np.ndarray], rtol: float = RTOL) -> Any:
    """The figure of :func:`plot_path` from the columns ``PATH_COLUMNS`` of a path scan."""
    plt = _pyplot()
    m = _classes(c)
    s, sample = c["s"], m["sample"]
    band = NEAR_FACTOR * rtol
    fig, axes = plt.subplots(3, 1, figsize=(9, 10), sharex=True)
    for ax, prefix, name in (
        (axes[0], "av", "actuation: stacked locked-limb wrenches (actuators locked)"),
        (axes[1], "sv", "constraint: stacked limb wrenches"),
    ):
        rel = _relative(c, prefix)[sample]
        if np.all(np.isnan(rel)):
            ax.text(
                0.5, 0.5, "no wrench (empty matrix) at any sample", ha="center", va="center", transform=ax.transAxes
            )
            ax.set_yscale("log")
        else:
            for k in range(6):
                if np.any(np.isfinite(rel[:, k])):
                    ax.semilogy(s[sample], rel[:, k], ".-", lw=1, ms=3, label=f"$\\sigma_{k + 1}/\\sigma_1$")
            ax.axhline(rtol, color="red", ls="--", lw=0.8, label=f"rank threshold rtol = {rtol:.0e}")
            ax.legend(fontsize=7, ncol=4, loc="lower left")
        ax.set_ylabel("relative singular value")
        ax.set_title(name, fontsize=9)
        for x in s[m["singular"] | m["refined"]]:
            ax.axvline(x, color="red", lw=0.8, alpha=0.4)
    ax = axes[2]
    dist = np.maximum(c["distance"], FLOOR)
    ax.semilogy(s[sample], dist[sample], "k.-", lw=1, ms=3, label="distance to singularity")
    ax.axhline(rtol, color="red", ls="--", lw=0.8, label=f"singular below rtol = {rtol:.0e}")
    ax.axhline(band, color="darkorange", ls=":", lw=0.8, label=f"near-singular below {band:.0e}")
    for key, mask, label in (
        ("singular", m["singular"], "singular sample"),
        ("near", m["near"], "near-singular sample"),
        ("refined", m["refined"], "refined singular point"),
    ):
        if mask.any():
            ax.plot(s[mask], dist[mask], label=label, **_MARKS[key])
    span = (float(np.nanmin(s)), float(np.nanmax(s))) if s.size else (0.0, 1.0)
    for x, y, label, limbs in zip(s[m["refined"]], dist[m["refined"]], c["singularity"][m["refined"]],
                                  c["singular_limbs"][m["refined"]]):  # fmt: skip
        text = f"{label} {limbs.replace(';', ',')}".strip() + f"\ns = {x:.6g}"
        right = x < span[0] + 0.75 * (span[1] - span[0])
        ax.annotate(text, (x, y), textcoords="offset points", xytext=(8 if right else -8, 6), fontsize=7,
                    ha="left" if right else "right")  # fmt: skip
    ax.set_ylabel("distance ($\\sigma_r / \\sigma_1$)")
    ax.set_xlabel("path parameter s")
    twin = ax.twinx()
    reach = m["reach"]
    twin.step(s[reach], c["dof"][reach], "b-", where="mid", lw=1, alpha=0.5)
    twin.set_ylabel("DoF (blue)", color="b")
    twin.set_ylim(-0.5, 6.5)
    ax.legend(fontsize=7, loc="lower left")
    unreachable = sample & ~m["reach"]
    if unreachable.any():
        half = 0.5 * float(np.min(np.diff(np.unique(s[sample])))) if np.unique(s[sample]).size > 1 else 0.5
        for a in axes:
            for x in s[unreachable]:
                a.axvspan(x - half, x + half, color="0.85", lw=0, zorder=0)
        axes[0].text(0.99, 0.97, "grey: not assembled", ha="right", va="top", fontsize=7, transform=axes[0].transAxes)
    axes[2].set_xlim(span[0] - 0.02 * (span[1] - span[0]), span[1] + 0.02 * (span[1] - span[0]))
    return fig


def _edges(centres: np.ndarray, fallback: float) -> np.ndarray:
    """Cell edges around sorted cell centres: midpoints, and half a spacing beyond the ends."""
    if centres.size == 1:
        return np.array([centres[0] - fallback / 2, centres[0] + fallback / 2])
    mid = (centres[1:] + centres[:-1]) / 2
    return np.concatenate([[2 * centres[0] - mid[0]], mid, [2 * centres[-1] - mid[-1]]])


MAP_COLUMNS = ["refined", "reachable", "singularity", "near_singular", "distance", "motion_type"]


def plot_map(csv_path: str | Path, png_path: str | Path, title: str = "", rtol: float = RTOL) -> Path:
    """A grid scan as two maps: motion type, and distance to singularity; returns the PNG path."""
    keys = [k for k in header(csv_path) if k.startswith("grid_")]
    fig = map_figure(read_columns(csv_path, keys + MAP_COLUMNS), keys, rtol)
    return save_png(fig, png_path, title or "scan over a workspace slice (blank: not assembled)")


def map_figure(c: dict[str, np.ndarray], keys: list[str], rtol: float = RTOL) -> Any:
    """The figure of :func:`plot_map` from the columns ``keys`` (the two ``grid_`` ones) and ``MAP_COLUMNS``."""
    plt = _pyplot()
    from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm
    from matplotlib.ticker import MaxNLocator

    m = _classes(c)
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
        ax.set_xlabel(keys[0][5:])
        ax.set_ylabel(keys[1][5:])
        if not types:
            ax.text(0.5, 0.5, "no sample could be assembled", ha="center", va="center", transform=ax.transAxes)
        for key, label in (("singular", "singular"), ("near", "near-singular"), ("refined", "refined singular point")):
            if m[key].any():
                ax.plot(u[m[key]], v[m[key]], label=label, **_MARKS[key])
        if m["singular"].any() or m["near"].any() or m["refined"].any():
            ax.legend(fontsize=7, loc="upper right", framealpha=0.8)
    return fig
