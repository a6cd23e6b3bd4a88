"""PNG plots of scans (matplotlib, Agg backend), read back from the scan's CSV file.

* :func:`plot_path`: singular values along a path, relative to the largest
  (``sigma_k / sigma_1``, log scale): the stacked limb wrenches (constraint)
  and the stacked locked-limb wrenches (actuation); the distance to
  singularity; the DoF. Singular samples are marked and labelled by class.
* :func:`plot_map`: a workspace slice coloured by motion type, and by the
  distance to singularity; singular samples are crossed, unreachable ones left
  blank.
"""

from __future__ import annotations

import csv
from pathlib import Path
from typing import Any

import numpy as np

FLOOR = 1e-17  # log-scale floor for exactly zero singular values


def _pyplot() -> Any:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def _save(plt: Any, fig: Any, title: str, png_path: str | Path) -> Path:
    """Title, lay out, write the PNG (110 dpi) and close the figure."""
    fig.suptitle(title)
    fig.tight_layout()
    fig.savefig(png_path, dpi=110)
    plt.close(fig)
    return Path(png_path)


def read_rows(csv_path: str | Path) -> dict[str, np.ndarray]:
    """Columns of a scan CSV: numbers as float arrays, text as object arrays."""
    with open(csv_path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    if not rows:
        return {}
    out = {}
    for key in rows[0]:
        values = [r[key] for r in rows]
        try:
            out[key] = np.array([float(v) if v != "" else np.nan for v in values])
        except ValueError:
            out[key] = np.array(values, dtype=object)
    return out


def _relative(cols: dict[str, np.ndarray], prefix: str) -> np.ndarray:
    s = np.column_stack([cols[f"{prefix}{i}"] for i in range(1, 7)])
    top = s[:, :1]
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(top > 0, np.maximum(s / np.where(top > 0, top, 1.0), FLOOR), np.nan)


def plot_path(csv_path: str | Path, png_path: str | Path, title: str = "") -> Path:
    """Singular values, distance and DoF along a path scan; returns the PNG path."""
    plt = _pyplot()
    c = read_rows(csv_path)
    s = c["s"]
    reach = c["reachable"].astype(str) == "True"
    sing = reach & (c["singularity"].astype(str) != "none")
    fig, axes = plt.subplots(3, 1, figsize=(8, 9), sharex=True)
    for ax, prefix, name in (
        (axes[0], "av", "actuation: locked-limb wrenches"),
        (axes[1], "sv", "constraint: limb wrenches"),
    ):
        rel = _relative(c, prefix)
        if np.all(np.isnan(rel)):
            ax.text(0.5, 0.5, "no wrench (empty matrix)", ha="center", va="center", transform=ax.transAxes)
        else:
            for k in range(6):
                if np.nanmax(rel[:, k], initial=0.0) > FLOOR:
                    ax.semilogy(s, rel[:, k], ".-", lw=1, ms=3, label=f"$\\sigma_{k + 1}/\\sigma_1$")
            ax.legend(fontsize=7, ncol=3, loc="lower left")
        ax.set_ylabel("relative singular value")
        ax.set_title(name, fontsize=9)
        for x in s[sing]:
            ax.axvline(x, color="red", lw=0.8, alpha=0.5)
    ax = axes[2]
    dist = np.maximum(c["distance"], FLOOR)
    ax.semilogy(s, dist, "k.-", lw=1, ms=3, label="distance to singularity")
    ax.semilogy(s[sing], dist[sing], "rx", ms=8, label="singular")
    for x, y, label in zip(s[sing], dist[sing], c["singularity"][sing]):
        ax.annotate(str(label), (x, y), textcoords="offset points", xytext=(3, 6), fontsize=7, color="red")
    ax.set_ylabel("distance (sigma_r / sigma_1)")
    ax.set_xlabel("path parameter s")
    twin = ax.twinx()
    twin.step(s[reach], c["dof"][reach], "b-", where="mid", lw=1, alpha=0.6, label="DoF")
    twin.set_ylabel("DoF", color="b")
    twin.set_ylim(-0.5, 6.5)
    ax.legend(fontsize=7, loc="lower left")
    return _save(plt, fig, title or "scan along a path", png_path)


def plot_map(csv_path: str | Path, png_path: str | Path, title: str = "") -> Path:
    """A grid scan as two maps: motion type, and distance to singularity; returns the PNG path."""
    plt = _pyplot()
    from matplotlib.colors import BoundaryNorm, ListedColormap, LogNorm

    c = read_rows(csv_path)
    keys = [k for k in c if k.startswith("grid_")]
    u, v = c[keys[0]], c[keys[1]]
    us, vs = np.unique(u), np.unique(v)
    iu, iv = np.searchsorted(us, u), np.searchsorted(vs, v)
    reach = c["reachable"].astype(str) == "True"
    types = sorted(set(c["motion_type"][reach].astype(str)))
    code = np.full((us.size, vs.size), np.nan)
    dist = np.full((us.size, vs.size), np.nan)
    for a, b, r, t, d in zip(iu, iv, reach, c["motion_type"].astype(str), c["distance"]):
        if r:
            code[a, b] = types.index(t)
            dist[a, b] = max(d, 1e-12)
    sing = reach & (c["singularity"].astype(str) != "none")
    extent = (us[0], us[-1], vs[0], vs[-1]) if us.size > 1 and vs.size > 1 else None
    fig, axes = plt.subplots(1, 2, figsize=(12, 5))
    palette = plt.get_cmap("tab10")
    cmap = ListedColormap([palette(k % 10) for k in range(max(1, len(types)))]).with_extremes(bad="white")
    im = axes[0].imshow(code.T, origin="lower", extent=extent, aspect="auto", cmap=cmap,
                        norm=BoundaryNorm(np.arange(-0.5, len(types) + 0.5), cmap.N), interpolation="nearest")  # fmt: skip
    bar = fig.colorbar(im, ax=axes[0], ticks=range(len(types)))
    bar.ax.set_yticklabels(types)
    axes[0].set_title("motion type")
    cm2 = plt.get_cmap("viridis").with_extremes(bad="white")
    finite = dist[np.isfinite(dist)]
    lo = max(1e-12, float(finite.min())) if finite.size else 1e-12
    im2 = axes[1].imshow(dist.T, origin="lower", extent=extent, aspect="auto", cmap=cm2,
                         norm=LogNorm(vmin=min(lo, 0.99), vmax=1.0), interpolation="nearest")  # fmt: skip
    fig.colorbar(im2, ax=axes[1], label="distance to singularity (sigma_r / sigma_1)")
    axes[1].set_title("distance to singularity")
    for ax in axes:
        ax.plot(u[sing], v[sing], "rx", ms=7, label="singular")
        ax.set_xlabel(keys[0][5:])
        ax.set_ylabel(keys[1][5:])
        if sing.any():
            ax.legend(fontsize=7, loc="upper right")
    return _save(plt, fig, title or "scan over a workspace slice (blank: not assembled)", png_path)
