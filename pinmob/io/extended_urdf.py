"""Extended URDF: a URDF plus a YAML sidecar describing its loops (LAAS-CNRS convention).

The convention of example-parallel-robots / toolbox-parallel-robots: beside
``robot.urdf``, a ``robot.yaml`` with

- ``closed_loop``: pairs of frame names ``[frame_a, frame_b]`` joined when the loop is closed;
- ``type``: per pair, ``6d`` (same pose) or ``3d`` (same origin); default ``6d``; pinmob also reads its own
  closure types here (``revolute``, ``planar_weld``, ... as ``pinmob fix`` writes them), with ``axis`` and
  ``axis_b`` (per pair, a 3-vector in the pair's first / second frame or ``null``) and ``urdf`` (the URDF's
  path, relative to the sidecar), keys the LAAS tools do not read;
- ``name_mot``: the actuated joints;
- ``joint_name`` / ``joint_type`` (optional): joints rebuilt as another joint
  model: ``SPHERICAL`` (a ball joint, :class:`pin.JointModelSpherical`),
  ``UJOINT_AB`` with A, B in X, Y, Z (a universal joint: revolute about the
  joint frame's axis A, then about its axis B, one composite joint),
  ``CARDAN`` (= ``UJOINT_XY``), ``FIXED`` (locked at 0).

The URDF's ``<mimic>`` joints are ``joint`` couplings (:mod:`pinmob.io.mimic`), on the rebuilt joints.

The files are read as they are; missing meshes only cost the visuals (a
warning). The mechanism is named after the YAML file, or its folder for
``robot.yaml`` (the repository's layout, ``<robot>/robot.yaml``, whose URDFs
say ``<robot name="onshape">``). There is no platform: the whole mechanism is
analysed, and any frame can be named as end frame.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pinocchio as pin

from pinmob.exceptions import ConfigurationError, MechanismFileError
from pinmob.io.gazebo_joints import unread_elements
from pinmob.io.mimic import mimic_couplings, unique
from pinmob.io.schema import errors_at, file_error, unicode_text
from pinmob.io.text_file import parsing, read_text, shown
from pinmob.io.urdf import load_geometry, read_urdf
from pinmob.model import CLOSURE_TYPES, Mechanism, has_joint, make_closure, with_joints
from pinmob.name_matching import choices

JOINT_TYPES = ("SPHERICAL", "CARDAN", "FIXED") + tuple(f"UJOINT_{a}{b}" for a in "XYZ" for b in "XYZ" if a != b)
YAML_KEYS = ("closed_loop", "type", "name_mot", "joint_name", "joint_type", "axis", "axis_b", "urdf")
_AXIS = {"X": pin.JointModelRX, "Y": pin.JointModelRY, "Z": pin.JointModelRZ}


def _joint_model(kind: str) -> pin.JointModel:
    if kind == "SPHERICAL":
        return pin.JointModelSpherical()
    pair = "XY" if kind == "CARDAN" else kind.split("_")[1]
    composite = pin.JointModelComposite(2)
    composite.addJoint(_AXIS[pair[0]]())
    composite.addJoint(_AXIS[pair[1]]())
    return composite


def replace_joints(model: pin.Model, replacements: Mapping[str, str]) -> pin.Model:
    """A copy of ``model`` with the named joints rebuilt as :data:`JOINT_TYPES` (same names, frames and inertias).

    Joint placements, frames and inertias are kept (:func:`~pinmob.model.joints.with_joints`); position limits
    of the unchanged joints are copied. ``FIXED`` joints are removed with ``pin.buildReducedModel`` at 0.
    """
    kinds = {j: replacements[model.names[j]] for j in range(1, model.njoints) if model.names[j] in replacements}
    rebuilt = {j: _joint_model(kind) for j, kind in kinds.items() if kind != "FIXED"}
    new = with_joints(model, rebuilt, ("lowerPositionLimit", "upperPositionLimit"))
    locked = [j for j, kind in kinds.items() if kind == "FIXED"]
    if locked:
        new = pin.buildReducedModel(new, locked, pin.neutral(new))
    return new


def read_sidecar(path: Path) -> dict[str, Any]:
    """The document of a YAML sidecar (a mapping; the text pinmob reads checked), read once for its readers.

    Raises:
        MechanismFileError: a missing or unreadable file, a YAML syntax error, not a mapping, or a lone surrogate
            in the keys pinmob reads.
    """
    return _read_yaml(path)


def _read_yaml(path: Path) -> dict[str, Any]:
    import yaml

    text = read_text(path, "YAML")
    with parsing(path, "YAML"):
        try:
            doc = yaml.safe_load(text)
        except yaml.YAMLError as exc:
            raise file_error(path, f"YAML syntax error: {' '.join(str(exc).split())[:300]}") from None
    if not isinstance(doc, Mapping):
        raise file_error(path, f"must be a mapping with keys {choices(YAML_KEYS)}")
    try:  # PyYAML reads "\ud800" (and each half of a pair) as a lone surrogate, which Pinocchio's names cannot hold
        _texts([doc[k] for k in YAML_KEYS if k in doc])  # the keys pinmob reads (others are another tool's)
    except ConfigurationError as exc:
        raise file_error(path, str(exc)) from None
    return dict(doc)


def _texts(value: object) -> None:
    """Every string of a YAML value, keys too, is text that UTF-8 holds (:func:`unicode_text`).

    Each list or mapping is visited once: YAML aliases share them (an alias bomb's 9^10 strings are 100 objects),
    and may make cycles.
    """
    seen: set[int] = set()
    stack = [value]
    while stack:
        item = stack.pop()
        if isinstance(item, str):
            unicode_text(
                "YAML text", item, "write the character itself, not \\uD800-\\uDFFF escapes (PyYAML joins no pair)"
            )
        elif isinstance(item, (Mapping, list)) and id(item) not in seen:
            seen.add(id(item))
            stack.extend([*item.keys(), *item.values()] if isinstance(item, Mapping) else item)


def _names(path: Path, doc: Mapping[str, Any], key: str) -> list[str]:
    value = doc.get(key) or []
    if not isinstance(value, list) or not all(isinstance(v, str) for v in value):
        raise file_error(path, f"{key!r} must be a list of names, got {shown(value)}")
    return value


def sidecar(urdf: Path) -> tuple[Path, dict[str, Any]] | None:
    """The Extended URDF sidecar of ``urdf`` (a same-named ``.yaml`` or ``.yml`` with ``closed_loop``) and its document.

    The file is read once: its document goes to :func:`load_extended_urdf` with it.

    A same-named YAML file without that key (another tool's configuration) is no sidecar: None, as for none.
    One that does not parse is no sidecar either, unless its text names ``closed_loop``: then it was meant as
    one, and its error is raised.

    Raises:
        MechanismFileError: a same-named YAML file naming ``closed_loop`` does not parse.
    """
    for suffix in (".yaml", ".yml"):
        candidate = urdf.with_suffix(suffix)
        if candidate.is_file():
            try:
                doc = _read_yaml(candidate)
            except MechanismFileError:
                with candidate.open("rb") as fh:  # its start: the file may be over the size bound
                    if b"closed_loop" in fh.read(1_000_000):
                        raise
                continue
            if "closed_loop" in doc:
                return candidate, doc
    return None


def find_urdf(path: Path) -> Path:
    """The URDF beside a YAML sidecar: same stem, else the only ``*.urdf`` in the folder."""
    same = path.with_suffix(".urdf")
    if same.exists():
        return same
    found = sorted(path.parent.glob("*.urdf"))
    if len(found) == 1:
        return found[0]
    raise file_error(
        path,
        f"no URDF named {same.name!r} beside it, and {len(found)} other .urdf files: {choices(p.name for p in found)}",
    )


def sidecar_urdf(path: Path, doc: Mapping[str, Any] | None = None) -> Path:
    """The URDF of a sidecar: its ``urdf`` key (relative to it), else the one beside it (:func:`find_urdf`)."""
    doc = _read_yaml(path) if doc is None else doc
    return path.parent / str(doc["urdf"]) if "urdf" in doc else find_urdf(path)


def load_extended_urdf(path: str | Path, doc: Mapping[str, Any] | None = None) -> Mechanism:
    """Load an Extended URDF robot from its YAML sidecar (the URDF beside it), or from the URDF beside its sidecar.

    Given a ``.urdf`` file, its sidecar is the same-named YAML file (:func:`sidecar`); the mechanism's
    description names both files either way. ``doc``: the sidecar's document when the caller has read it
    (:func:`sidecar`'s), so that the file is read once.
    """
    path = Path(path)
    if path.suffix.lower() == ".urdf":
        found = sidecar(path)
        if found is None:
            raise file_error(path, "no Extended URDF sidecar beside it (a same-named .yaml file with 'closed_loop')")
        path, doc = found
    doc = _read_yaml(path) if doc is None else doc
    if "closed_loop" not in doc:
        raise file_error(path, f"no 'closed_loop' key: not an Extended URDF sidecar (keys {choices(YAML_KEYS)})")
    loops = doc.get("closed_loop") or []
    if not isinstance(loops, list) or not all(
        isinstance(p, list) and len(p) == 2 and all(isinstance(x, str) for x in p) for p in loops
    ):
        raise file_error(path, f"'closed_loop' must be a list of [frame_a, frame_b] pairs, got {shown(loops)}")
    types = doc.get("type") or ["6d"] * len(loops)
    if not isinstance(types, list) or len(types) != len(loops):
        raise file_error(path, f"'type' must list one of '6d', '3d' per closed loop ({len(loops)}), got {shown(types)}")
    joint_names, joint_types = _names(path, doc, "joint_name"), _names(path, doc, "joint_type")
    if len(joint_names) != len(joint_types):
        raise file_error(
            path, f"'joint_name' ({len(joint_names)}) and 'joint_type' ({len(joint_types)}) must have the same length"
        )
    urdf = sidecar_urdf(path, doc)
    axes = {k: doc.get(k) or [None] * len(loops) for k in ("axis", "axis_b")}
    for k, v in axes.items():
        if not isinstance(v, list) or len(v) != len(loops):
            raise file_error(path, f"{k!r} must list a 3-vector or null per closed loop ({len(loops)}), got {shown(v)}")
    try:
        model = read_urdf(urdf)  # urdfdom's own messages go into the error or one warning, never raw to stderr
    except MechanismFileError as exc:
        raise file_error(path, str(exc)) from None
    for jname, jtype in zip(joint_names, joint_types):
        if not has_joint(model, jname):
            raise file_error(
                path, f"joint_name {jname!r} is not a joint of {urdf.name}; valid: {choices(list(model.names)[1:])}"
            )
        if str(jtype).upper() not in JOINT_TYPES:
            raise file_error(path, f"joint_type {jtype!r} of {jname!r} is not supported; valid: {choices(JOINT_TYPES)}")
    if joint_names:
        model = replace_joints(model, {n: str(t).upper() for n, t in zip(joint_names, joint_types)})
    try:
        couplings = mimic_couplings(urdf, model)
    except MechanismFileError as exc:
        raise file_error(path, str(exc)) from None
    geometry = load_geometry(model, urdf)
    with errors_at(path):
        closures = []
        for (a, b), t, u, ub in zip(loops, types, axes["axis"], axes["axis_b"]):
            if str(t).lower() not in CLOSURE_TYPES:
                raise file_error(
                    path,
                    f"closed loop [{a!r}, {b!r}] has type {t!r}; valid: '3d', '6d' (pinmob's own: "
                    f"{choices(CLOSURE_TYPES[2:])})",
                )
            closures.append(make_closure(model, f"{a}={b}", a, b, str(t).lower(), u, ub))
        return Mechanism.from_model(
            model,
            [],
            name=path.absolute().parent.name if path.stem == "robot" else path.stem,  # robot.yaml: its folder's
            actuated={"": _names(path, doc, "name_mot")},
            description=f"Extended URDF {urdf.name} + {path.name}"
            + (f" ({len(couplings)} mimic joint{'s' * (len(couplings) != 1)})" if couplings else ""),
            source=path,
            geometry=geometry,
            closures=unique(path, closures + couplings),
        ).with_ignored(unread_elements(urdf, "the YAML sidecar"))
