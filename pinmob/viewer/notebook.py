"""The animated scene inside a notebook cell: :func:`notebook` returns a :class:`NotebookScene` Jupyter shows.

The cell shows the page :func:`pinmob.viewer.html.scene_html` builds (what ``pinmob show --html`` writes:
meshcat's viewer script, pinmob's panel and the scene's recorded commands in one self-contained page),
embedded in an ``<iframe srcdoc="...">``. Chosen because it needs nothing after the cell ran: no meshcat
server, no websocket, no network, no file beside the notebook; the scene keeps playing when the kernel
stops, and a saved notebook shows it again when opened in a trusted session. meshcat's own embedding
(``Visualizer.jupyter_cell()``) is an iframe of a running server's URL: blank once that server stops, and
without pinmob's panel. The price is size: the cell's output holds the page (meshcat's script, about
0.9 MB, and the meshes), so save notebooks without outputs or clear this cell before committing one.

The iframe is sandboxed (``allow-scripts`` only): the page runs its own scripts and cannot reach the
notebook's page. How to use it, with the Report's own display: docs/notebooks.md.
"""

from __future__ import annotations

import html
from dataclasses import dataclass, field
from typing import Any

from pinmob.analysis import Configuration, Mobility, Report
from pinmob.exceptions import ConfigurationError
from pinmob.model import Mechanism
from pinmob.viewer.html import scene_html
from pinmob.viewer.scene import Array, Scene


def _attribute(text: str) -> str:
    """``text`` as an HTML attribute's value, ASCII only (character references): right in a page of any encoding."""
    return html.escape(text, quote=True).encode("ascii", "xmlcharrefreplace").decode("ascii")


@dataclass(frozen=True)
class NotebookScene:
    """A scene as a notebook cell shows it (``_repr_html_``: the page in a sandboxed iframe).

    Attributes:
        page: the self-contained HTML page (:func:`pinmob.viewer.html.scene_html`).
        scene: what was put in the viewer (clips, notes, the analysis shown).
        height: the iframe's height [CSS pixels].
    """

    page: str = field(repr=False)
    scene: Scene
    height: int = 480

    def _repr_html_(self) -> str:
        title = _attribute(f"pinmob: {self.scene.mobility.mechanism}")
        return (
            f'<iframe title="{title}" srcdoc="{_attribute(self.page)}" sandbox="allow-scripts" '
            f'style="width: 100%; height: {self.height}px; border: 1px solid #ddd"></iframe>'
        )


def notebook(
    shown: Report | Mechanism,
    q: Array | str | Configuration | None = None,
    *,
    height: int = 480,
    **options: Any,
) -> NotebookScene:
    """The mechanism and its animated free motions, for a notebook cell (the last expression of a cell shows it).

    >>> report = pinmob.analyze(pinmob.load("3-PUU-flat"), "flat")      # doctest: +SKIP
    >>> pinmob.viewer.notebook(report)                                  # doctest: +SKIP

    Args:
        shown: a :class:`~pinmob.analysis.report.Report` (its mechanism at its configuration, its mobility), or a
            mechanism (then ``q`` is required).
        q: with a mechanism: (nq,) closed configuration, the name of one of ``mech.configurations``, or a
            :class:`Configuration`; with a Report: leave it out.
        height: the cell's height [CSS pixels].
        **options: the scene's options (:class:`~pinmob.viewer.options.ViewOptions`: ``motion``, ``wrenches``,
            ``amplitude``, ``steps``, ``animate``, ``finite``).

    Raises:
        ConfigurationError: a mechanism without ``q``, a Report with ``q``, or a height that is not a positive
            whole number of pixels.
        ViewerError: meshcat missing, or the mechanism has no platform.
        ClosureError: q does not close.
    """
    if isinstance(height, bool) or not isinstance(height, int) or height <= 0:
        raise ConfigurationError(f"height must be a positive whole number of pixels, not {height!r}")
    state: Array | str | Configuration
    mobility: Mobility | Report | None
    if isinstance(shown, Report):
        if q is not None:
            raise ConfigurationError("a Report carries its configuration: give the Report alone, or a mechanism and q")
        mech, state, mobility = shown.state.mechanism, shown.state, shown
    elif isinstance(shown, Mechanism):
        if q is None:
            names = ", ".join(repr(n) for n in shown.configurations) or "none in its file"
            raise ConfigurationError(
                f"give the configuration to show {shown.name!r} at: joint values or a configuration's name ({names})"
            )
        mech, state, mobility = shown, q, None
    else:
        raise ConfigurationError(f"notebook shows a Report or a Mechanism, not a {type(shown).__name__}")
    page, scene = scene_html(mech, state, mobility, **options)
    return NotebookScene(page, scene, height)
