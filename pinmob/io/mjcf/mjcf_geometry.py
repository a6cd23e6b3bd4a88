"""The visual geometry of a compiled MuJoCo model, as a Pinocchio geometry model on pinmob's MJCF tree.

Each geom of a visible group (MuJoCo shows groups 0, 1 and 2 by default; every geom when none is in
those groups) becomes a geometry object on
the joint carrying its body: spheres, capsules, cylinders, boxes and ellipsoids as coal shapes (MuJoCo
sizes are half-lengths and radii), meshes from their files. MuJoCo moves a mesh's vertices into the
mesh's own frame when it compiles it, ``c = R^T (s v - p)`` (``mesh_quat`` R, ``mesh_pos`` p,
``mesh_scale`` s, v a vertex of the file), so the file's mesh is placed at ``geom * (R, p)^-1`` with
scale s. Planes, height fields and SDF geoms are left out.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Any

import coal
import numpy as np
import pinocchio as pin

from pinmob.io.mjcf.mjcf_tree import Tree, name_of, se3, unique

#: MuJoCo's geom types (``mjtGeom``) pinmob draws.
SPHERE, CAPSULE, ELLIPSOID, CYLINDER, BOX, MESH = 2, 3, 4, 5, 6, 7
#: Geom groups MuJoCo's viewer shows by default.
VISIBLE_GROUPS = (0, 1, 2)


def _shape(m: Any, g: int) -> coal.ShapeBase | None:
    size, kind = m.geom_size[g], int(m.geom_type[g])
    if kind == SPHERE:
        return coal.Sphere(size[0])
    if kind == CAPSULE:
        return coal.Capsule(size[0], 2 * size[1])
    if kind == ELLIPSOID:
        return coal.Ellipsoid(*size)
    if kind == CYLINDER:
        return coal.Cylinder(size[0], 2 * size[1])
    if kind == BOX:
        return coal.Box(*(2 * size))
    return None


def visual_geometry(m: Any, tree: Tree, source: Path) -> pin.GeometryModel:
    """The visible geoms of ``m`` attached to ``tree.model`` (a mesh file that does not load is warned about)."""
    geom = pin.GeometryModel()
    taken: set[str] = set()
    paths = bytes(m.paths)
    groups = VISIBLE_GROUPS if set(np.asarray(m.geom_group).tolist()) & set(VISIBLE_GROUPS) else range(32)
    for g in range(m.ngeom):
        if int(m.geom_group[g]) not in groups:
            continue
        body = int(m.geom_bodyid[g])
        joint, at = tree.body_joint[body], tree.body_placement[body] * se3(m.geom_pos[g], m.geom_quat[g])
        name = unique(name_of(m, "geom", g) or f"geom{g}", taken)
        color = np.array(m.geom_rgba[g], float)
        if int(m.geom_type[g]) == MESH:
            k = int(m.geom_dataid[g])
            path = paths[int(m.mesh_pathadr[k]) :].split(b"\0", 1)[0].decode() if m.mesh_pathadr[k] >= 0 else ""
            try:
                scale = np.array(m.mesh_scale[k], float)
                shape = coal.MeshLoader().load(path, scale)
            except Exception as exc:
                warnings.warn(f"{source.name}: mesh {path or k!r} not drawn ({exc})", stacklevel=3)
                continue
            at = at * se3(m.mesh_pos[k], m.mesh_quat[k]).inverse()
            obj = pin.GeometryObject(name, joint, at, shape, path, scale, True, color)
        else:
            shape = _shape(m, g)
            if shape is None:
                continue
            obj = pin.GeometryObject(name, joint, at, shape, "", np.ones(3), True, color)
        geom.addGeometryObject(obj)
    return geom
