"""Figures written as PNG files: matplotlib on the Agg backend (files only, no display), saved safely.

:func:`pyplot` gives matplotlib's pyplot (imported when first called: ``import pinmob`` loads no
matplotlib); :func:`save_figure` titles, lays out and writes a figure through a temporary file
(:class:`~pinmob.output_files.Replacing`), for the scans' plots (:mod:`pinmob.scan.results.scan_plot`) and the
sweeps' (:mod:`pinmob.sweeps.sweep_plot`) alike.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pinmob.output_files import Replacing


def pyplot() -> Any:
    """The pyplot module of matplotlib, on the Agg backend (files only, no display)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(
    plt: Any, fig: Any, title: str | None, png_path: str | Path, metadata: dict[str, str] | None = None
) -> Path:
    """Title (if any), lay out, write the PNG and close the figure (the scans' and the sweeps' plots alike).

    110 dpi, ``metadata`` in the PNG's text chunks, written through a temporary file renamed at the end.
    """
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
