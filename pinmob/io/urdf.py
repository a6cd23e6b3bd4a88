"""Reading URDF files with Pinocchio: the kinematic model, optional geometry, and the parser's own messages.

urdfdom (the URDF parser inside Pinocchio) prints its diagnostics on the
process's stderr (file descriptor 2) and then raises a bare "does not contain a
valid URDF model". :func:`read_urdf` captures those lines and puts them into
the one error message (or a warning when the file still parses), so the user
sees one line instead of the C++ parser's output.
"""

from __future__ import annotations

import functools
import os
import sys
import warnings
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pinocchio as pin

from pinmob.bounds import check_bound
from pinmob.exceptions import MechanismFileError
from pinmob.io.mesh_files import confine, mesh_roots
from pinmob.io.text_file import check_regular
from pinmob.model import Geometry, motion_subspaces


def package_dirs(urdf: Path) -> list[str]:
    """Folders searched for ``package://`` mesh paths of ``urdf``.

    The URDF's own folder, then the folders of ``ROS_PACKAGE_PATH``, then the
    ``share`` folder of the installed example-robot-data (whose URDFs name
    their meshes ``package://example-robot-data/robots/...``), when importable.
    """
    dirs = [str(urdf.parent)]
    dirs += [d for d in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep) if d]
    try:
        import example_robot_data

        robots = Path(example_robot_data.getModelPath("ur_description/urdf/ur5_robot.urdf"))
        dirs.append(str((robots / ".." / "..").resolve()))
    except Exception:  # not installed, or a layout without robots: meshes are optional
        pass
    return dirs


@contextmanager
def native_stderr() -> Iterator[list[str]]:
    """Capture what native code (urdfdom, Pinocchio's C++) writes on file descriptor 2 inside the block.

    Yields a list that receives the captured lines when the block ends (also when it raises).
    Python's own ``sys.stderr`` is flushed first, so nothing of it is swallowed.
    """
    lines: list[str] = []
    sys.stderr.flush()
    try:
        saved = os.dup(2)
    except OSError:  # no file descriptor 2: nothing to capture
        saved = -1
    if saved < 0:
        yield lines
        return
    import tempfile  # imported when a file is read, not with pinmob

    with tempfile.TemporaryFile() as tmp:
        os.dup2(tmp.fileno(), 2)
        try:
            yield lines
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            tmp.seek(0)
            lines.extend(tmp.read().decode("utf-8", errors="replace").splitlines())


def native_messages(lines: list[str]) -> str:
    """Captured native stderr as one line: messages joined by ``; ``, source locations (``at line N in ...``) dropped."""
    texts = [" ".join(line.split()) for line in lines]
    return "; ".join(t for t in texts if t and not t.startswith("at line "))


def read_urdf(urdf: Path, text: str | None = None) -> pin.Model:
    """Kinematic model of a URDF (``pin.buildModelFromUrdf``), or of URDF ``text`` (a xacro file ``urdf`` expanded).

    What the parser prints on stderr goes into the error message, or into a
    warning when the file parses, never straight to the terminal.

    Raises:
        MechanismFileError: the file is missing, a folder, not a regular file, over the file bound, its path is
            not UTF-8, or it does not parse (with the parser's messages).
    """
    if text is None:
        check_regular(urdf, f"urdf file {str(urdf)!r}", "URDF")  # a pipe would block Pinocchio's reader
        try:
            str(urdf).encode()
        except UnicodeEncodeError:  # bytes of another encoding in a name (os.fsdecode's surrogates)
            raise MechanismFileError(
                f"urdf {str(urdf)!r}: its path holds bytes that are not UTF-8, and Pinocchio opens UTF-8 paths "
                "only; rename the file or the folders that hold it"
            ) from None
    try:
        with native_stderr() as printed:
            model = pin.buildModelFromUrdf(str(urdf)) if text is None else pin.buildModelFromXML(text)
    except Exception as exc:  # pinocchio raises RuntimeError/ValueError with a generic text
        said = native_messages(printed)
        raise MechanismFileError(
            f"urdf {str(urdf)!r} does not parse: {' '.join(str(exc).split()) or type(exc).__name__}"
            + (f" (parser: {said})" if said else "")
        ) from None
    said = native_messages(printed)
    if said:
        warnings.warn(f"{urdf.name}: {said}", stacklevel=4)
    check_model(model, urdf)
    return model


def check_model(model: pin.Model, urdf: Path) -> None:
    """The checks of a URDF's model once parsed (:func:`read_urdf`'s): the joint bound, then :func:`check_axes`.

    Raises:
        MechanismFileError: too many joints, or a joint with a zero or non-finite axis (naming ``urdf``).
    """
    check_bound("joints", model.njoints - 1, f"urdf {str(urdf)!r}")  # before anything builds its Data
    check_axes(model, str(urdf))


def check_axes(model: pin.Model, label: str) -> None:
    """Refuse a joint whose axis is zero or not finite (a prismatic ``<axis xyz="0 0 0"/>`` moves nothing).

    Each joint's motion subspace S at the neutral configuration (Pinocchio's, :func:`pinmob.model.motion_subspaces`,
    which the masks of lengths and angles read afterwards) must have finite columns of non-zero length.

    Raises:
        MechanismFileError: naming the file and the joint (the first in the model's order).
    """
    import numpy as np

    subspaces = motion_subspaces(model)
    if not subspaces:
        return
    stacked = np.hstack([s for _, s in subspaces])
    if np.isfinite(stacked).all() and (np.linalg.norm(stacked, axis=0) >= 1e-9).all():
        return
    for j, s in subspaces:
        if not np.isfinite(s).all() or (np.linalg.norm(s, axis=0) < 1e-9).any():
            raise MechanismFileError(
                f"{label}: joint {model.names[j]!r} has a zero or non-finite axis; give its <axis xyz=...> a "
                "finite, non-zero direction"
            )


def load_geometry(model: pin.Model, urdf: Path) -> Geometry:
    """Visual and collision geometry of a URDF for ``model``, its meshes loaded when first drawn.

    The mesh files are looked for now, where Pinocchio will look for them
    (:func:`missing_meshes`): a kind of geometry with a missing file gets a
    warning and no geometry (kinematics only), as when Pinocchio fails to load
    it (the message names the first missing file, as Pinocchio's would); the
    others are built by :func:`build_geometry` when first asked for.
    """
    kinds = []
    absent = missing_meshes(urdf)
    for kind in (pin.GeometryType.VISUAL, pin.GeometryType.COLLISION):
        missing = absent[kind.name.lower()]
        if missing:
            warnings.warn(
                f"{urdf.name}: {kind.name.lower()} geometry not loaded (Mesh {missing[0][:200]} could not be found.); "
                "kinematics only",
                stacklevel=4,
            )
        else:
            kinds.append(kind.name)
    return Geometry(loader=functools.partial(build_geometry, urdf=urdf, kinds=tuple(kinds)))


def build_geometry(
    model: pin.Model, urdf: Path, kinds: tuple[str, ...] = ("VISUAL", "COLLISION")
) -> tuple[pin.GeometryModel | None, pin.GeometryModel | None]:
    """Visual and collision geometry of a URDF for ``model`` (the ``kinds`` asked for); None with a warning on failure.

    Meshes whose file or textures lie outside the model's folders are left out, with a warning
    (:func:`pinmob.io.mesh_files.confine`).
    """
    geoms: list[pin.GeometryModel | None] = []
    for kind in (pin.GeometryType.VISUAL, pin.GeometryType.COLLISION):
        if kind.name not in kinds:
            geoms.append(None)
            continue
        try:
            with native_stderr() as printed:
                built = pin.buildGeomFromUrdf(model, str(urdf), kind, package_dirs=package_dirs(urdf))
            geoms.append(confine(built, mesh_roots(urdf, package_dirs(urdf)), urdf.name))
        except Exception as exc:
            said = native_messages(printed)
            warnings.warn(
                f"{urdf.name}: {kind.name.lower()} geometry not loaded ({' '.join(str(exc).split())[:200]}"
                + (f"; {said[:200]}" if said else "")
                + "); kinematics only",
                stacklevel=4,
            )
            geoms.append(None)
    return geoms[0], geoms[1]


def missing_meshes(urdf: Path) -> dict[str, list[str]]:
    """Per kind of element (``visual``, ``collision``), the mesh file names of the URDF's that cannot be found.

    The file is read and parsed once for both kinds.

    Each is looked for as Pinocchio resolves it: ``package://`` (and ``model://``) paths
    in :func:`package_dirs` (``package:///x``, without a package name, as ``x`` there), ``file://`` paths as they are, relative paths in the same
    folders, absolute paths as they are; other schemes are not handled.
    """
    kinds = ("visual", "collision")
    text = urdf.read_bytes()
    if b"<mesh" not in text:
        return {kind: [] for kind in kinds}
    import xml.etree.ElementTree as ET  # only for URDFs with meshes

    links = list(ET.fromstring(text).iter("link"))
    names = {
        kind: [
            mesh.get("filename", "")
            for link in links
            for element in link.findall(kind)
            for mesh in element.iter("mesh")
        ]
        for kind in kinds
    }
    dirs = package_dirs(urdf) if any(names.values()) else []
    return {kind: [name for name in dict.fromkeys(found) if not _found(name, dirs)] for kind, found in names.items()}


def _found(name: str, dirs: list[str]) -> bool:
    scheme, sep, rest = name.partition("://")
    if sep:
        if scheme in ("package", "model"):  # package:///x: no package name (onshape-to-robot), in the folders too
            return any((Path(d) / rest.lstrip("/")).exists() for d in dirs)
        return scheme == "file" and Path(rest).exists()
    if not Path(name).is_absolute():
        return any(Path(d + "/" + name).exists() for d in dirs)
    return Path(name).exists()
