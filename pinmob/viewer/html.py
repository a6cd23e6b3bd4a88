"""Static HTML export: a scene replayed from recorded meshcat commands in one self-contained file.

meshcat's ``Visualizer`` is given a window (:class:`_Recorder`) that records
every command (msgpack bytes) instead of sending it to a server; the page
(:func:`pinmob.viewer.page.static_page`) holds meshcat's viewer script, pinmob's
panel and those commands, compressed, replayed in order when it opens. No
server is needed to build or to open it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from pinmob.analysis import Configuration, Mobility, Report
from pinmob.exceptions import ConfigurationError, ViewerError
from pinmob.model import Mechanism
from pinmob.output_files import Replacing, check_target
from pinmob.viewer.options import view_options
from pinmob.viewer.page import static_page
from pinmob.viewer.prepared import prepare
from pinmob.viewer.scene import Array, Scene, build, require_meshcat
from pinmob.viewer.workspace import Workspace


class _Recorder:
    """A meshcat window that records commands (msgpack bytes) instead of sending them."""

    web_url = None

    def __init__(self) -> None:
        self.commands: list[bytes] = []

    def send(self, command: Any) -> None:
        import umsgpack

        self.commands.append(umsgpack.packb(command.lower()))


def scene_html(
    mech: Mechanism,
    q: Array | str | Configuration,
    mobility: Mobility | Report | None = None,
    *,
    workspace: Workspace | None = None,
    **options: Any,
) -> tuple[str, Scene]:
    """The scene as a self-contained HTML page (no server, no file); see :func:`export_html`."""
    prep = prepare(mech, q, mobility, view_options(**options))
    require_meshcat()
    from meshcat.visualizer import Visualizer

    recorder = _Recorder()
    scene = build(Visualizer(window=recorder), prep, workspace=workspace)
    mob = prep.mobility
    title = (
        f"pinmob: {prep.mechanism.name}"
        + (f" at {mob.configuration}" if mob.configuration else "")
        + f" ({mob.motion_type})"
    )
    if workspace is not None:
        title += f", workspace of {len(workspace.positions)} samples"
    return static_page(recorder.commands, title), scene


def export_html(
    mech: Mechanism,
    q: Array | str | Configuration,
    path: str | Path,
    mobility: Mobility | Report | None = None,
    *,
    overwrite: bool = False,
    workspace: Workspace | None = None,
    **options: Any,
) -> Scene:
    """Write the scene and its animations to a self-contained HTML file that opens without a server.

    The file holds meshcat's viewer script and the scene's commands (meshcat's
    static export, built without a server). It is written to a temporary file
    first and moved into place, so a failure leaves nothing half-written.

    Args:
        mech: the mechanism.
        q: (nq,) closed configuration, the name of one of ``mech.configurations``, or a :class:`Configuration`.
        path: the ``.html`` file to write.
        mobility: the platform mobility (or the Report) to show (default: ``analyze(mech, q)``).
        overwrite: replace an existing file; otherwise an existing file is an error.
        workspace: a scan's reachable set drawn beside the mechanism, with its legend in the panel
            (:func:`pinmob.viewer.workspace.workspace_cloud`).
        **options: the scene's options (:class:`~pinmob.viewer.options.ViewOptions`: ``motion``, ``wrenches``,
            ``amplitude``, ``steps``, ``animate``, ``finite``).

    Raises:
        ArgumentError: an unknown option (the message lists them).
        ViewerError: the file exists and ``overwrite`` is False, or cannot be written.
        ClosureError: q does not close.
    """
    try:
        target = check_target(
            "html file", path, overwrite, "overwrite"
        )  # only a regular file or a new path, never a link
    except ConfigurationError as exc:
        raise ViewerError(str(exc)).naming(*exc.parameters) from None
    page, scene = scene_html(mech, q, mobility, workspace=workspace, **options)
    try:
        with (replacing := Replacing(target)) as tmp:  # the old file stays until the page is complete
            tmp.write_text(page, encoding="utf-8")
            if not overwrite and target.exists():
                raise ViewerError(f"{str(target)!r} appeared while writing; not overwritten")
            replacing.commit()
    except ConfigurationError as exc:
        raise ViewerError(str(exc)).naming(*exc.parameters) from None
    except OSError as exc:
        raise ViewerError(f"cannot write {str(target)!r}: {exc.strerror or exc}") from None
    scene.html = target
    return scene
