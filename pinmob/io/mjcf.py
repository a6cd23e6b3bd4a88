"""MJCF models with loops: ``<equality><connect/weld>`` through Pinocchio's MJCF parser.

Pinocchio (``pin.buildModelAndLegacyConstraintsFromMJCF``) builds the tree and
one rigid constraint model per equality: ``connect`` is a ``3d`` closure (the
anchor point, in body1's frame, meets the point of body2 where it is at the
reference configuration: :func:`connect_placements`), ``weld`` a ``6d``
closure (the relative pose of the reference configuration is kept). pinmob adds a frame
for each side of each constraint (``<name>_a`` on body1, ``<name>_b`` on body2)
and turns it into a :class:`~pinmob.model.closure.Closure`. Each constraint is
paired with its ``<equality>`` element by name when Pinocchio gives one, else by
kind and by the joints that carry body1 and body2 (and, between the same two
bodies, by the anchor); a constraint that matches no element, or an element of
another kind (``joint``, ``tendon``, ``distance``, ...), is an error. Actuated
joints are those named by ``<actuator>`` elements (``joint="..."``).

The file is parsed where it is. Pinocchio 4.1's parser reads only the first
body under ``<worldbody>`` and ignores ``<include>``: a file with several
top-level bodies or with includes is read through a temporary copy (includes
expanded, top-level bodies wrapped into one fixed body, ``meshdir`` and
``texturedir`` made absolute so that meshes still load), deleted once parsed.
"""

from __future__ import annotations

import tempfile
import warnings
import xml.etree.ElementTree as ET
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from pinmob.io.mesh_files import confine, mesh_roots
from pinmob.io.schema import errors_at, file_error
from pinmob.model.closure import make_closure
from pinmob.model.mechanism import Mechanism

KINDS = {"connect": "3d", "weld": "6d"}
#: Nested ``<include>`` levels followed before the file is refused.
MAX_INCLUDE_DEPTH = 8


def _read(path: Path, what: str) -> ET.Element:
    try:
        return ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise file_error(path, f"XML syntax error{what}: {exc}") from None
    except OSError as exc:
        raise file_error(path, f"cannot read{what}: {exc}") from None


def _expand_includes(path: Path, root: ET.Element, folder: Path, depth: int = 0) -> bool:
    """Replace every ``<include file=...>`` under ``root`` by the children of the included ``<mujoco>``.

    Files are relative to the main file's ``folder`` (MuJoCo's rule). Returns
    True when anything was included.
    """
    changed = False
    for parent in list(root.iter()):
        for i, child in enumerate(list(parent)):
            if child.tag != "include":
                continue
            if depth >= MAX_INCLUDE_DEPTH:
                raise file_error(path, f"<include> nested deeper than {MAX_INCLUDE_DEPTH} levels (a cycle?)")
            name = child.get("file", "")
            target = folder / name
            if not name or not target.is_file():
                raise file_error(path, f"<include file={name!r}>: no such file {str(target)!r}")
            included = _read(target, f" in included file {str(target)!r}")
            _expand_includes(path, included, folder, depth + 1)
            parent.remove(child)
            for k, item in enumerate(list(included)):
                parent.insert(i + k, item)
            changed = True
    return changed


def _wrap_bodies(root: ET.Element) -> bool:
    """Put the top-level bodies of ``<worldbody>`` under one fixed body; True when there were several."""
    world = root.find("worldbody")
    bodies = [] if world is None else world.findall("body")
    if world is None or len(bodies) <= 1:
        return False
    wrapper = ET.SubElement(world, "body", {"name": "pinmob_world"})
    for b in bodies:
        world.remove(b)
        wrapper.append(b)
    return True


def _absolute_dirs(root: ET.Element, folder: Path) -> None:
    """Make ``<compiler meshdir/texturedir>`` absolute (relative to ``folder``), so that a copy elsewhere loads them."""
    compiler = root.find("compiler")
    if compiler is None:
        compiler = ET.Element("compiler")
        root.insert(0, compiler)
    for key in ("meshdir", "texturedir"):  # MuJoCo: each falls back to assetdir, then to the file's folder
        compiler.set(key, str((folder / (compiler.get(key) or compiler.get("assetdir") or "")).resolve()))


@contextmanager
def parseable(path: Path, root: ET.Element, expanded: bool) -> Iterator[Path]:
    """The file for Pinocchio's parser: ``path`` itself, or a temporary rewritten copy deleted on exit.

    Args:
        path: the MJCF file.
        root: the file's tree with its includes expanded (it is modified: top-level bodies wrapped).
        expanded: the tree had includes.
    """
    if not (_wrap_bodies(root) | expanded):
        yield path
        return
    _absolute_dirs(root, path.parent)
    with tempfile.TemporaryDirectory(prefix="pinmob_mjcf_") as tmp:
        out = Path(tmp) / path.name
        ET.ElementTree(root).write(out)
        yield out


def _joint_of_body(model: pin.Model, body: str | None) -> int:
    """Joint carrying an MJCF body (0 for the world); -1 when the model has no such body."""
    if body in (None, "", "world"):
        return 0
    if not model.existFrame(body, pin.FrameType.BODY):
        return -1
    return int(model.frames[model.getFrameId(body, pin.FrameType.BODY)].parentJoint)


def _anchor(eq: ET.Element) -> pin.SE3:
    return pin.SE3(np.eye(3), np.array([float(x) for x in eq.get("anchor", "0 0 0").split()]))


def _anchor_gap(model: pin.Model, eq: ET.Element, c: Any) -> float:
    """Distance [m] between a connect's anchor and the constraint's point on joint 1 (0 for a weld).

    The anchor is taken in body1's frame and in its joint's frame (Pinocchio's reading), the nearer counts.
    """
    if eq.tag != "connect":
        return 0.0
    body = model.frames[model.getFrameId(eq.get("body1", ""), pin.FrameType.BODY)].placement
    t = c.joint1_placement.translation
    anchor = _anchor(eq)
    return float(min(np.linalg.norm((body * anchor).translation - t), np.linalg.norm(anchor.translation - t)))


def connect_placements(model: pin.Model, eq: ET.Element) -> tuple[int, pin.SE3, int, pin.SE3]:
    """(joint 1, anchor in joint 1's frame, joint 2, the same point in joint 2's frame) of a ``<connect>``.

    MuJoCo's rule: the anchor is in body1's frame, and body2's point is where
    the anchor is at the reference configuration (all joints zero: Pinocchio's
    neutral). Pinocchio 4.1 puts the anchor in the frame of the joint carrying
    body1, which differs when body1 is a body without a joint (merged into its
    parent) or its joint is not at the body's origin; pinmob follows MuJoCo.
    """
    frame = model.frames[model.getFrameId(eq.get("body1", ""), pin.FrameType.BODY)]
    j1, j2 = int(frame.parentJoint), _joint_of_body(model, eq.get("body2"))
    on_1 = frame.placement * _anchor(eq)
    data = model.createData()
    pin.forwardKinematics(model, data, pin.neutral(model))
    on_2 = data.oMi[j2].actInv(data.oMi[j1] * on_1)
    return j1, on_1, j2, pin.SE3(np.eye(3), on_2.translation)


def match_equalities(path: Path, model: pin.Model, equalities: list[ET.Element], constraints: list[Any]) -> list[int]:
    """For each Pinocchio constraint, the index of its ``<equality>`` element.

    By name when the constraint has one; else by kind (connect = 3d, weld =
    6d) and the joints carrying body1 and body2; among equal candidates, the
    connect whose anchor is the constraint's point.

    Raises:
        MechanismFileError: a constraint matches no unused element.
    """
    out: list[int] = []
    for k, c in enumerate(constraints):
        kind = "3d" if c.type == pin.ContactType.CONTACT_3D else "6d"
        free = [i for i in range(len(equalities)) if i not in out and KINDS[equalities[i].tag] == kind]
        if c.name:
            cands = [i for i in free if equalities[i].get("name") == c.name]
        else:
            cands = [
                i
                for i in free
                if (
                    _joint_of_body(model, equalities[i].get("body1")),
                    _joint_of_body(model, equalities[i].get("body2")),
                )
                == (c.joint1_id, c.joint2_id)
            ]
        if not cands:
            raise file_error(
                path,
                f"Pinocchio's constraint {k} ({kind} between joints {model.names[c.joint1_id]!r} and "
                f"{model.names[c.joint2_id]!r}{', name ' + repr(c.name) if c.name else ''}) matches no <connect>/<weld> "
                "equality of the file (same kind and bodies); pinmob cannot tell which closure it is",
            )
        out.append(min(cands, key=lambda i: _anchor_gap(model, equalities[i], c)))
    return out


def load_mjcf(path: str | Path) -> Mechanism:
    """Load an MJCF file: the tree, its connect/weld equalities as closures, its actuated joints."""
    path = Path(path)
    root = _read(path, "")
    if root.tag != "mujoco":
        raise file_error(path, f"root element is <{root.tag}>, not <mujoco>: not an MJCF file")
    expanded = _expand_includes(path, root, path.parent)
    elements = [e for eq in root.findall("equality") for e in eq]
    unsupported = sorted({e.tag for e in elements if e.tag not in KINDS})
    if unsupported:
        raise file_error(
            path,
            f"<equality> kind(s) {', '.join(f'<{t}>' for t in unsupported)} are not loop closures pinmob reads; "
            f"valid: {', '.join(f'<{t}>' for t in KINDS)}",
        )
    equalities = elements
    actuated = [a.get("joint", "") for act in root.findall("actuator") for a in act if a.get("joint")]
    with parseable(path, root, expanded) as source:
        try:
            model, constraints = pin.buildModelAndLegacyConstraintsFromMJCF(str(source))
        except Exception as exc:
            raise file_error(path, f"Pinocchio's MJCF parser failed: {' '.join(str(exc).split())[:300]}") from None
        visual = None
        try:
            visual = confine(
                pin.buildGeomFromMJCF(model, str(source), pin.GeometryType.VISUAL), mesh_roots(path), path.name
            )
        except Exception as exc:
            warnings.warn(
                f"{path.name}: visual geometry not loaded ({' '.join(str(exc).split())[:200]}); kinematics only",
                stacklevel=2,
            )
    if len(constraints) != len(equalities):
        raise file_error(
            path, f"Pinocchio built {len(constraints)} constraints for {len(equalities)} connect/weld equalities"
        )
    closures = []
    with errors_at(path):
        pairs = sorted(
            zip(match_equalities(path, model, equalities, list(constraints)), constraints), key=lambda p: p[0]
        )
        for i, c in pairs:  # in the file's order
            eq = equalities[i]
            name = eq.get("name") or f"{eq.tag}{i}"
            j1, m1, j2, m2 = (
                connect_placements(model, eq)
                if eq.tag == "connect"
                else (c.joint1_id, c.joint1_placement, c.joint2_id, c.joint2_placement)
            )
            fa = model.addFrame(pin.Frame(f"{name}_a", j1, m1, pin.FrameType.OP_FRAME), False)
            fb = model.addFrame(pin.Frame(f"{name}_b", j2, m2, pin.FrameType.OP_FRAME), False)
            closures.append(make_closure(model, name, model.frames[fa].name, model.frames[fb].name, KINDS[eq.tag]))
        return Mechanism.from_model(
            model,
            [],
            name=root.get("model") or path.stem,
            actuated={"": actuated},
            description=f"MJCF {path.name}",
            source=path,
            visual_model=visual,
            closures=closures,
        )
