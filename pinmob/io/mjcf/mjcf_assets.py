"""Mesh, texture, height-field and skin files of an MJCF that MuJoCo's compiler must not or cannot read, taken out.

MuJoCo opens every ``<mesh file>``, ``<texture file>``, ``<hfield file>`` and ``<skin file>`` when it compiles, and refuses the model when one
is missing (``Error opening file ...stl``): meshes kept elsewhere, or Git LFS files not pulled (a small
text pointer where the mesh should be). Kinematics needs none of them: a geom only draws, collides and
weighs (the body frames, joints, sites and equalities do not depend on it; pinmob gives massless bodies
a tiny mass). So, as for a URDF whose meshes are missing, the model is compiled without them
(:func:`drop_unread_files`), with one warning: a geom of a missing mesh becomes a tiny transparent sphere
in a hidden group (anything naming the geom still finds it; it is not drawn), the mesh asset is deleted,
a missing texture is deleted with the materials' references to it, a height field like a mesh (its geoms
become stand-ins), a skin (drawn only) deleted.

A file resolving (symbolic links followed) outside the model's folders (:func:`pinmob.io.mesh_files.mesh_roots`)
is taken out the same way, so that it is never read (``file="/etc/shadow"``, ``../../key.stl``): its
content would otherwise reach the drawing, which the HTML export embeds.

MuJoCo finds a file as its ``compiler`` documentation says: the file name (its folders dropped with
``strippath``) if absolute, else in ``meshdir`` (``texturedir``) if absolute, else in the main model
file's folder joined with ``meshdir``; a file given in the spec's in-memory ``assets`` is not looked for.

One exception: with ``<compiler alignfree="true">`` MuJoCo aligns a free body's frame with its inertia,
which the geoms give; pinmob keeps MuJoCo's choice and the warning says that its free joints' frames may
differ from the model with meshes.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

from pinmob.io.mesh_files import inside, mesh_roots

#: The first bytes of a Git LFS pointer file (what a clone without ``git lfs pull`` holds).
LFS_POINTER = b"version https://git-lfs.github.com/spec/v1"
#: Radius [file units] of the sphere a geom of a missing mesh becomes (not drawn: its group is hidden).
STAND_IN_SIZE = 1e-6
#: The geom group of the stand-ins (MuJoCo shows groups 0 to 2 by default).
HIDDEN_GROUP = 5


def asset_path(spec: Any, file: str, folder: str) -> Path:
    """Where MuJoCo's compiler opens ``file`` (of a mesh, ``folder`` = meshdir; of a texture, texturedir)."""
    name = os.path.basename(file) if spec.strippath else file
    if os.path.isabs(name):
        return Path(name)
    if os.path.isabs(folder):
        return Path(folder) / name
    return Path(spec.modelfiledir or ".") / folder / name


def unread_reason(path: Path, roots: tuple[Path, ...]) -> str | None:
    """Why MuJoCo must not read ``path``: ``outside`` the model's folders, ``missing``, or an ``LFS`` pointer; None to read it."""
    if not inside(path, roots):
        return "outside"
    if not path.is_file():
        return "missing"
    with open(path, "rb") as f:
        return "LFS" if f.read(len(LFS_POINTER)) == LFS_POINTER else None


def _stand_in(geom: Any) -> None:
    """Turn a geom of a missing mesh into a tiny transparent sphere in a hidden group (its name and frame kept)."""
    import mujoco

    geom.meshname = ""
    geom.type = mujoco.mjtGeom.mjGEOM_SPHERE
    geom.size = [STAND_IN_SIZE] * 3
    geom.rgba = [0.0, 0.0, 0.0, 0.0]
    geom.group = HIDDEN_GROUP
    geom.contype, geom.conaffinity = 0, 0


def drop_unread_files(spec: Any, model_file: Path) -> str | None:
    """Take the mesh and texture files MuJoCo must not or cannot read out of ``spec`` (changed in place).

    Args:
        spec: the ``mujoco.MjSpec`` of the file, before it compiles.
        model_file: the MJCF file (its folder bounds the files that may be read).

    Returns:
        The warning to give (how many files of each reason and the first of each), or None when all are read.
    """
    roots = mesh_roots(model_file)
    assets = set(spec.assets)
    found: dict[str, list[str]] = {}
    # meshes, height fields (their images) and skins, all looked for in meshdir; a skin only draws
    dropped = {
        kind: _drop_files(spec, items, kind, roots, model_file, found)
        for kind, items in (("mesh", spec.meshes), ("height-field", spec.hfields), ("skin", spec.skins))
    }
    dropped_meshes, dropped_fields = dropped["mesh"], dropped["height-field"]
    for geom in spec.geoms:
        if geom.meshname in dropped_meshes or geom.hfieldname in dropped_fields:
            geom.hfieldname = ""
            _stand_in(geom)
    dropped_textures = set()
    for texture in list(spec.textures):
        files = [f for f in [texture.file, *texture.cubefiles] if f and f not in assets]
        paths = [asset_path(spec, f, spec.compiler.texturedir) for f in files]
        unread = [(r, path) for r, path in ((unread_reason(path, roots), path) for path in paths) if r]
        if unread:
            found.setdefault(f"texture {unread[0][0]}", []).append(_shown(unread[0][1], model_file))
            dropped_textures.add(texture.name)
            spec.delete(texture)
    for material in spec.materials:
        material.textures = ["" if t in dropped_textures else t for t in material.textures]
    return _warning(found, spec.compiler.alignfree and bool(dropped_meshes))


def _drop_files(
    spec: Any, items: Any, kind: str, roots: tuple[Path, ...], model_file: Path, found: dict[str, list[str]]
) -> set[str]:
    """The names of the ``items`` (meshes, height fields, skins: files in meshdir) deleted from ``spec``.

    Those whose file MuJoCo must not or cannot read, each noted in ``found`` under ``"<kind> <reason>"``.
    """
    assets, out = set(spec.assets), set()
    for item in list(items):
        if not item.file or item.file in assets:
            continue
        path = asset_path(spec, item.file, spec.compiler.meshdir)
        reason = unread_reason(path, roots)
        if reason:
            found.setdefault(f"{kind} {reason}", []).append(_shown(path, model_file))
            out.add(item.name)
            spec.delete(item)
    return out


def _shown(path: Path, model_file: Path) -> str:
    """``path`` as the user wrote it from the model's folder when it lies there, else as it is."""
    relative = os.path.relpath(os.path.abspath(path), os.path.abspath(model_file.parent))
    return os.path.normpath(path) if relative.startswith("..") else relative


def _warning(found: dict[str, list[str]], align: bool) -> str | None:
    if not found:
        return None
    said = {
        "missing": "missing",
        "LFS": "are Git LFS pointers (run git lfs pull)",
        "outside": "outside the model's folders (not read)",
    }
    parts = []
    for key, files in found.items():
        kind, reason = key.rsplit(" ", 1)
        parts.append(f"{len(files)} {kind} file(s) {said[reason]}, first {files[0]!r}")
    if align:
        return "; ".join(parts) + (
            ": compiled without them (not drawn); with alignfree the free bodies' frames follow their inertia, "
            "which the meshes gave: free joint values may differ from the complete model's"
        )
    return "; ".join(parts) + ": compiled without them, kinematics unaffected (their geoms are not drawn)"
