"""PNG plots of a sweep (matplotlib, Agg backend), read back from its Parquet file.

* :func:`plot_atlas`: the designs over two parameters, each coloured by a record field (a colour bar with
  the field's unit, or a legend of its values for a text or true/false field); failed designs crossed.
* :func:`plot_pareto`: two numeric fields, every design that succeeded as a dot and the Pareto front (the
  designs no other design beats in both, for the goals ``max`` or ``min`` of each) as a line.

Each PNG carries ``pinmob sweep IDENTITY`` in its ``Description`` text chunk: a later run of the same
sweep may replace it without ``--force`` (:func:`written_by`).
"""

from __future__ import annotations

import struct
import zlib
from pathlib import Path
from typing import Any

import numpy as np

from pinmob.figures import pyplot, save_figure
from pinmob.sweeps.fields import TYPES
from pinmob.sweeps.sweep_spec import SweepSpec


def _label(spec: SweepSpec, name: str) -> str:
    unit = spec.unit(name)
    return f"{name} [{unit}]" if unit else name


def _columns(path: Path, names: list[str]) -> dict[str, np.ndarray]:
    import pyarrow.parquet as pq

    table = pq.read_table(path, columns=list(dict.fromkeys(names)))
    return {n: np.array(table.column(n).to_pylist(), dtype=object) for n in table.column_names}


def _save(fig: Any, png: Path, spec: SweepSpec) -> Path:
    return save_figure(pyplot(), fig, None, png, metadata={"Description": f"pinmob sweep {spec.identity()}"})


def _figure() -> Any:
    return pyplot().subplots(figsize=(7.5, 5.8))


def plot_atlas(parquet: str | Path, png: str | Path, spec: SweepSpec) -> Path:
    """The atlas of ``spec.plots['atlas']`` (x, y: parameters; color: a record field); returns the PNG path."""
    x, y, color = (spec.plots["atlas"][k] for k in ("x", "y", "color"))
    c = _columns(Path(parquet), [x, y, color, "status"])
    fig, ax = _figure()
    ok = c["status"] == "ok"
    xs, ys, values = c[x].astype(float), c[y].astype(float), c[color]
    has = ok & np.array([v is not None for v in values])
    size = 260 if ok.sum() <= 150 else 60
    if TYPES.get(color) in ("int", "float") or color in spec.parameters:
        if has.any():
            dots = ax.scatter(xs[has], ys[has], c=values[has].astype(float), s=size, marker="s", cmap="viridis")
            fig.colorbar(dots, ax=ax, label=_label(spec, color))
    else:
        import matplotlib.pyplot as plt

        kinds = sorted({str(v) for v in values[has]})
        palette = plt.get_cmap("tab10")
        for k, kind in enumerate(kinds):
            mask = has & np.array([str(v) == kind for v in values])
            ax.scatter(xs[mask], ys[mask], s=size, marker="s", color=palette(k % 10), label=f"{color} = {kind}")
    empty = ok & ~has
    if empty.any():
        ax.scatter(xs[empty], ys[empty], s=size, marker="s", facecolors="none", edgecolors="0.5",
                   label=f"no value of {color} (no sample assembled)")  # fmt: skip
    if (~ok).any():
        ax.scatter(xs[~ok], ys[~ok], s=size / 3, marker="x", color="red", label="failed design (reason in the records)")
    ax.set_xlabel(_label(spec, x))
    ax.set_ylabel(_label(spec, y))
    ax.set_title(f"{spec.name}: {color} per design ({int(ok.sum())} of {len(ok)} designs ok)", fontsize=10)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="best", framealpha=0.85)
    return _save(fig, Path(png), spec)


def pareto_front(xs: np.ndarray, ys: np.ndarray, x_goal: str = "max", y_goal: str = "max") -> np.ndarray:
    """Indices of the non-dominated points (no other point at least as good in both and better in one), by x."""
    sx = xs if x_goal == "max" else -xs
    sy = ys if y_goal == "max" else -ys
    order = np.lexsort((-sy, -sx))  # best x first, ties by best y
    front, best = [], -np.inf
    for i in order:
        if sy[i] > best:
            front.append(i)
            best = sy[i]
    return np.array(sorted(front, key=lambda i: xs[i]), dtype=int)


def plot_pareto(parquet: str | Path, png: str | Path, spec: SweepSpec) -> Path:
    """The Pareto front of ``spec.plots['pareto']`` (two numeric fields and their goals); returns the PNG path."""
    p = spec.plots["pareto"]
    c = _columns(Path(parquet), [p["x"], p["y"], "status", "design"])
    fig, ax = _figure()
    has = (c["status"] == "ok") & np.array([a is not None and b is not None for a, b in zip(c[p["x"]], c[p["y"]])])
    xs, ys = c[p["x"]][has].astype(float), c[p["y"]][has].astype(float)
    ax.scatter(xs, ys, s=18, color="0.6", label=f"designs ({has.sum()} with both values)")
    if has.any():
        front = pareto_front(xs, ys, p["x_goal"], p["y_goal"])
        ax.plot(xs[front], ys[front], "o-", color="crimson", ms=6, lw=1.5,
                label=f"Pareto front ({p['x_goal']} {p['x']}, {p['y_goal']} {p['y']}): {len(front)} designs")  # fmt: skip
        for i in front[:12]:
            ax.annotate(
                f"#{c['design'][has][i]}", (xs[i], ys[i]), textcoords="offset points", xytext=(4, 4), fontsize=7
            )
    ax.set_xlabel(_label(spec, p["x"]))
    ax.set_ylabel(_label(spec, p["y"]))
    ax.set_title(f"{spec.name}: Pareto front (labels: design index)", fontsize=10)
    ax.legend(fontsize=7, loc="best", framealpha=0.85)
    return _save(fig, Path(png), spec)


def written_by(png: str | Path) -> str | None:
    """The ``Description`` text chunk of a PNG file (None: none, or not a PNG)."""
    try:
        data = Path(png).read_bytes()
    except OSError:
        return None
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        return None
    pos = 8
    while pos + 8 <= len(data):
        length, kind = struct.unpack(">I4s", data[pos : pos + 8])
        body = data[pos + 8 : pos + 8 + length]
        if kind == b"tEXt" and body.startswith(b"Description\0"):
            return body[12:].decode("latin-1")
        if kind == b"zTXt" and body.startswith(b"Description\0"):
            return zlib.decompress(body[13:]).decode("latin-1")
        if kind == b"IEND":
            break
        pos += 12 + length
    return None
