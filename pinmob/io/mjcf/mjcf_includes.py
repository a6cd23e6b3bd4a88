"""The files an MJCF makes MuJoCo read as XML (itself and its ``<include>`` files): checked before MuJoCo opens them.

MuJoCo's parser opens whatever path an ``<include file>`` names, and opening a named pipe blocks
until someone writes to it: ``<include file="fifo"/>`` (or ``pinmob analyze fifo.xml``) hung the
program. Before compiling, :func:`check_xml_files` walks the model file and its includes (nested
ones too) as MuJoCo resolves them (relative to the main file's folder, else the including file's)
and refuses, in one line naming the file, one that is not a regular file (a pipe, a device, a
folder), one larger than the file bound (``PINMOB_MAX_FILE_BYTES``: :mod:`pinmob.bounds`), or one
outside the model's folders (:func:`pinmob.io.mesh_files.mesh_roots`: what it includes becomes the
model, drawn and exported, as the mesh files it names may not). A file that does not parse is left
to MuJoCo, whose message names the error.
"""

from __future__ import annotations

import os
import xml.etree.ElementTree as ET
from pathlib import Path

from pinmob.io.mesh_files import inside, mesh_roots
from pinmob.io.schema import file_error
from pinmob.io.text_file import check_regular


def check_xml_files(model_file: Path) -> None:
    """Refuse an MJCF whose own file or an included one MuJoCo must not open (see the module docstring).

    Raises:
        MechanismFileError: the file named is not a regular file, is over the size bound, or (an include)
            lies outside the model's folders.
    """
    roots = mesh_roots(model_file)
    main_folder = model_file.parent
    todo, seen = [model_file], set()
    while todo:
        path = todo.pop()
        real = os.path.realpath(path)
        if real in seen:
            continue  # MuJoCo refuses a file included twice: its message says which
        seen.add(real)
        if path is not model_file and not inside(path, roots):
            raise file_error(
                model_file,
                f"<include file={_shown(path, main_folder)!r}> lies outside the model's folder "
                f"{str(main_folder)!r}; copy it into that folder",
            )
        what = "the model file" if path == model_file else f"<include file={_shown(path, main_folder)!r}>"
        check_regular(path, f"{model_file}: {what}", missing_ok=True)  # MuJoCo names a missing include
        todo += [_resolved(name, main_folder, path.parent) for name in _includes(path)]


def _includes(path: Path) -> list[str]:
    """The ``file`` of each ``<include>`` in ``path`` (none when it does not parse: MuJoCo says why)."""
    try:
        root = ET.parse(path).getroot()
    except (ET.ParseError, OSError, ValueError, RecursionError):
        return []
    return [e.get("file", "") for e in root.iter("include") if e.get("file")]


def _resolved(name: str, main_folder: Path, folder: Path) -> Path:
    """Where MuJoCo opens include ``name``: from the main file's folder, else (nested) the including file's."""
    if os.path.isabs(name):
        return Path(name)
    first = main_folder / name
    return first if os.path.lexists(first) or folder == main_folder else folder / name


def _shown(path: Path, folder: Path) -> str:
    """``path`` relative to the model's folder when inside it, else as given."""
    path = Path(os.path.normpath(path))
    return str(path.relative_to(folder)) if path.is_relative_to(folder) else str(path)
