"""MJCF models with loops: ``<equality><connect/weld>`` through Pinocchio's MJCF parser.

Pinocchio (``pin.buildModelAndLegacyConstraintsFromMJCF``) builds the tree and
one rigid constraint model per equality: ``connect`` is a ``3d`` closure (the
anchor point of body1 meets the same point of body2), ``weld`` a ``6d`` closure
(the relative pose of the reference configuration is kept). pinmob adds a frame
for each side of each constraint (``<name>_a`` on body1, ``<name>_b`` on body2)
and turns it into a :class:`~pinmob.mechanism.Closure`. Actuated joints are
those named by ``<actuator>`` elements (``joint="..."``).

Pinocchio 4.1's parser reads only the first body under ``<worldbody>``: a file
with several top-level bodies is read through a copy whose top-level bodies
are wrapped into one fixed body (meshes may then be missing: a warning).
"""

from __future__ import annotations

import tempfile
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import pinocchio as pin

from .mechanism import Mechanism, make_closure
from .mechanism_file import LOADERS, errors_at, file_error

KINDS = {"connect": "3d", "weld": "6d"}


def _wrapped(path: Path, root: ET.Element) -> Path:
    """The path to parse: ``path``, or a temporary copy with the top-level bodies under one fixed body."""
    world = root.find("worldbody")
    if world is None:
        return path
    bodies = world.findall("body")
    if len(bodies) <= 1:
        return path
    wrapper = ET.SubElement(world, "body", {"name": "pinmob_world"})
    for b in bodies:
        world.remove(b)
        wrapper.append(b)
    out = Path(tempfile.mkdtemp(prefix="pinmob_mjcf_")) / path.name
    ET.ElementTree(root).write(out)
    return out


def load_mjcf(path: str | Path) -> Mechanism:
    """Load an MJCF file: the tree, its connect/weld equalities as closures, its actuated joints."""
    path = Path(path)
    try:
        root = ET.parse(path).getroot()
    except ET.ParseError as exc:
        raise file_error(path, f"XML syntax error: {exc}") from None
    if root.tag != "mujoco":
        raise file_error(path, f"root element is <{root.tag}>, not <mujoco>: not an MJCF file")
    equalities = [e for eq in root.findall("equality") for e in eq if e.tag in KINDS]
    unsupported = sorted({e.tag for eq in root.findall("equality") for e in eq if e.tag not in KINDS})
    if unsupported:
        warnings.warn(
            f"{path.name}: equality constraints {unsupported} are not loop closures pinmob reads; ignored", stacklevel=3
        )
    actuated = [a.get("joint", "") for act in root.findall("actuator") for a in act if a.get("joint")]
    source = _wrapped(path, root)
    try:
        model, constraints = pin.buildModelAndLegacyConstraintsFromMJCF(str(source))
    except Exception as exc:
        raise file_error(path, f"Pinocchio's MJCF parser failed: {' '.join(str(exc).split())[:300]}") from None
    if len(constraints) != len(equalities):
        raise file_error(
            path, f"Pinocchio built {len(constraints)} constraints for {len(equalities)} connect/weld equalities"
        )
    closures = []
    with errors_at(path):
        for i, (eq, c) in enumerate(zip(equalities, constraints)):
            kind = "3d" if c.type == pin.ContactType.CONTACT_3D else "6d"
            if kind != KINDS[eq.tag]:
                raise file_error(
                    path, f"equality {i} <{eq.tag}> became a {kind} constraint in Pinocchio; order mismatch"
                )
            name = eq.get("name") or f"{eq.tag}{i}"
            fa = model.addFrame(pin.Frame(f"{name}_a", c.joint1_id, c.joint1_placement, pin.FrameType.OP_FRAME), False)
            fb = model.addFrame(pin.Frame(f"{name}_b", c.joint2_id, c.joint2_placement, pin.FrameType.OP_FRAME), False)
            closures.append(make_closure(model, name, model.frames[fa].name, model.frames[fb].name, kind))
        visual = None
        try:
            visual = pin.buildGeomFromMJCF(model, str(source), pin.GeometryType.VISUAL)
        except Exception as exc:
            warnings.warn(
                f"{path.name}: visual geometry not loaded ({' '.join(str(exc).split())[:200]}); kinematics only",
                stacklevel=3,
            )
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


LOADERS[".xml"] = load_mjcf
LOADERS[".mjcf"] = load_mjcf
