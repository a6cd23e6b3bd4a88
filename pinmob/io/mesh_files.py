"""Mesh and texture files a drawing may read: only those in the model's own folders.

A URDF or MJCF names its mesh files by path, and a Collada (``.dae``) mesh names
its texture images by path: any path, absolute or climbing out with ``..``
(``package://../../..``). The viewer embeds every file it draws into the HTML
export (meshes as they are, Collada textures base64-encoded), and the docs
invite attaching that file to a bug report: a path outside the model would put
that file's content (``/etc/passwd``, a key) into the page.

So a geometry model is confined once, when it is built (:func:`confine`): a
mesh is drawn only when its file and each of its Collada textures resolve
(symbolic links followed) inside the model's folders (:func:`mesh_roots`);
every other mesh is left out of the geometry, with a warning naming the file
and how to allow its folder (``ROS_PACKAGE_PATH``, the declared package
directories).
"""

from __future__ import annotations

import os
import warnings
from collections.abc import Iterable
from pathlib import Path

import pinocchio as pin


def mesh_roots(model_file: Path, package_dirs: Iterable[str] = ()) -> tuple[Path, ...]:
    """The folders a model's mesh and texture files may come from, resolved.

    The model file's folder tree, and the package that holds it when that folder is
    ``urdf/`` (the ROS layout: ``<package>/urdf/robot.urdf`` beside ``<package>/meshes``),
    then the declared package directories (``package_dirs``: ``ROS_PACKAGE_PATH``, an
    installed example-robot-data).
    """
    folder = Path(os.path.realpath(model_file)).parent
    roots = [folder] + ([folder.parent] if folder.name == "urdf" else [])
    roots += [Path(os.path.realpath(d)) for d in package_dirs]
    return tuple(dict.fromkeys(roots))


def inside(path: str | Path, roots: Iterable[Path]) -> bool:
    """``path`` resolves (symbolic links followed) inside one of the ``roots``."""
    real = Path(os.path.realpath(path))
    return any(real.is_relative_to(root) for root in roots)


def dae_textures(dae: Path) -> list[Path]:
    """The texture images a Collada file names (``<library_images>``' ``init_from``), as the viewer reads them.

    Relative paths count from the Collada file's folder, as Pinocchio's meshcat
    visualizer opens them. A file that does not parse names none (the viewer
    cannot draw it either).
    """
    import xml.etree.ElementTree as ET  # only for models with Collada meshes

    try:
        root = ET.parse(dae).getroot()
    except (ET.ParseError, OSError, ValueError):
        return []
    names = [
        (element.text or "").strip()
        for images in root.iter()
        if images.tag.endswith("library_images")
        for element in images.iter()
        if element.tag.endswith("init_from")
    ]
    return [Path(n) if Path(n).is_absolute() else dae.parent / n for n in names if n]


def confine(geometry: pin.GeometryModel, roots: tuple[Path, ...], label: str) -> pin.GeometryModel:
    """``geometry`` without the meshes whose file or textures lie outside ``roots`` (each named in a warning).

    Args:
        geometry: a geometry model just built from the model file (changed in place).
        roots: the allowed folders (:func:`mesh_roots`).
        label: the model file's name, for the warnings.

    Returns:
        The same geometry model.
    """
    names = []
    for obj in geometry.geometryObjects:
        path = obj.meshPath
        if not path:
            continue
        files = [Path(path)] + (
            dae_textures(Path(path)) if path.lower().endswith(".dae") and inside(path, roots) else []
        )
        outside = [str(f) for f in files if not inside(f, roots)]
        if outside:
            what = f"its mesh {path!r}" if outside[0] == path else f"the texture {outside[0]!r} of its mesh {path!r}"
            warnings.warn(
                f"{label}: {obj.name!r} left out of the drawing: {what} is outside the model's "
                f"folders ({', '.join(str(r) for r in roots)}); add its folder to ROS_PACKAGE_PATH to draw it",
                stacklevel=5,
            )
            names.append(obj.name)
    for name in names:
        geometry.removeGeometryObject(name)
    return geometry
