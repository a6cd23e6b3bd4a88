"""Reading pinmob's mechanism files: TOML with a URDF beside it.

See docs/mechanism-file.md for the format. Every error names the file and the key.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

import pinocchio as pin

from pinmob.exceptions import FrameError, MechanismFileError, PinmobError
from pinmob.io.gazebo_joints import unread_elements
from pinmob.io.mimic import mimic_couplings, unique
from pinmob.io.schema import (
    CLOSURE_KEYS,
    CONFIG_KEYS,
    EXPECTED_KEYS,
    LIMB_KEYS,
    POSE_KEYS,
    TOP_KEYS,
    check_table,
    errors_at,
    file_error,
    finite_number,
    joint_values,
    toml_text,
    vector3,
)
from pinmob.io.text_file import parsing, read_text
from pinmob.io.urdf import check_model, load_geometry, read_urdf
from pinmob.io.urdf import package_dirs as package_dirs
from pinmob.model import Closure, Expectation, Geometry, Mechanism, NamedConfiguration, frame_id, make_closure
from pinmob.name_matching import choices, did_you_mean


def _frame(path: Path, where: str, model: pin.Model, name: str) -> None:
    """A :class:`FrameError` naming the file, the key path, the bad frame and the valid ones, if ``name`` is none."""
    try:
        frame_id(model, name)
    except FrameError as exc:
        raise FrameError(f"{path}: {where}: {exc}") from None


def _joints(path: Path, where: str, joint_names: set[str], names: list[str]) -> list[str]:
    for name in names:
        if name not in joint_names:
            raise FrameError(
                f"{path}: {where} names unknown joint {name!r}{did_you_mean(name, joint_names)}; "
                f"valid joints: {choices(joint_names)}"
            )
    return names


def load_urdf(path: Path, urdf: Path, model: pin.Model | None = None) -> tuple[pin.Model, Geometry, list[Closure]]:
    """Kinematic model of the URDF a mechanism file names (:func:`pinmob.io.urdf.read_urdf`), its geometry, its mimic couplings.

    The geometry's meshes are checked now and loaded when first drawn (:func:`pinmob.io.urdf.load_geometry`);
    each ``<mimic>`` joint is a ``joint`` coupling (:func:`pinmob.io.mimic.mimic_couplings`). A ``.xacro`` file is
    expanded first (:func:`pinmob.io.xacro_file.expand_xacro`, no arguments; ``$(find)`` in ``ROS_PACKAGE_PATH``),
    and has no geometry. ``model``: the URDF's model parsed by the caller from the very text of the file (see
    :func:`load_toml`), checked as a parsed file is (:func:`pinmob.io.urdf.check_model`), not parsed again.
    """
    try:
        if model is not None:
            check_model(model, urdf)
            return model, load_geometry(model, urdf), mimic_couplings(urdf, model)
        if urdf.suffix.lower() == ".xacro":
            from pinmob.io.xacro_file import expand_xacro

            text = expand_xacro(urdf)
            model = read_urdf(urdf, text)
            return model, Geometry(None), mimic_couplings(urdf, model, text)
        model = read_urdf(urdf)
        couplings = mimic_couplings(urdf, model)
    except MechanismFileError as exc:
        raise file_error(path, str(exc)) from None
    return model, load_geometry(model, urdf), couplings


def read_toml(path: Path) -> dict[str, Any]:
    """Parse a TOML file; a missing, unreadable, oversized, non-UTF-8 or too deeply nested file or a syntax error is a :class:`MechanismFileError`."""
    text = read_text(path, "TOML")
    import tomllib  # imported when a file is read, not with pinmob

    with parsing(path, "TOML"):
        try:
            return tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise file_error(path, f"TOML syntax error: {exc}") from None


def load_toml(path: str | Path, urdf_model: pin.Model | None = None) -> Mechanism:
    """Load a pinmob mechanism file (TOML) and the URDF it names.

    ``urdf_model``: the model of that URDF when the caller has just parsed the text it wrote there (a sweep's
    design: :meth:`pinmob.builder.MechanismBuilder.model`); it is checked as the file's would be, not parsed again,
    and the mechanism takes it (one model per call, never shared). Default: the URDF file is read.

    Raises:
        MechanismFileError: the file is missing, unreadable or not TOML, or a key is
            unknown, of the wrong type or invalid (the message names the key path).
        FrameError: a limb tip, the platform or an actuated joint does not exist.
    """
    path = Path(path)
    doc = check_table(path, "", read_toml(path), TOP_KEYS)
    for key in ("name", "urdf"):
        if not doc.get(key):
            raise file_error(path, f"required key {key!r} must be a non-empty string")
    model, geometry, couplings = load_urdf(path, path.parent / doc["urdf"], urdf_model)
    joint_names = set(list(model.names)[1:])

    closures = unique(path, _closures(path, doc.get("closures", []), model) + couplings)
    limbs, actuated = _limbs(path, doc.get("limbs", []), model, joint_names)
    if not (limbs or closures):
        raise file_error(path, "needs at least one [[limbs]] table with 'name' and 'tip', or one [[closures]] table")
    actuated[""] = _joints(path, "actuated", joint_names, doc.get("actuated", []))
    configurations, expected = _configurations(path, doc.get("configurations", {}), joint_names)

    length = doc.get("length_scale")
    if length is not None and not (finite_number(length) and length > 0):
        raise file_error(path, f"length_scale must be a positive number [m], got {toml_text(length)}")
    generic_rank = doc.get("generic_rank")
    if generic_rank is not None and not 0 <= generic_rank <= 6:
        raise file_error(path, f"generic_rank must be an integer from 0 to 6, got {generic_rank!r}")
    platform = doc.get("platform")
    if platform is not None:
        _frame(path, "platform", model, platform)
    with errors_at(path):
        return Mechanism.from_model(
            model,
            limbs,
            name=doc["name"],
            platform=platform,
            actuated=actuated,
            length_scale=length,
            configurations=configurations,
            expected=expected,
            description=doc.get("description", ""),
            source=path,
            geometry=geometry,
            generic_rank=generic_rank,
            closures=closures,
        ).with_ignored(unread_elements(path.parent / doc["urdf"], "the TOML file"))


def _limbs(
    path: Path, table: list[Mapping[str, Any]], model: pin.Model, joint_names: set[str]
) -> tuple[list[tuple[str, str]], dict[str, list[str]]]:
    """``[[limbs]]``: (name, tip) pairs and actuated joints by limb name; names unique, tips existing."""
    limbs: list[tuple[str, str]] = []
    actuated: dict[str, list[str]] = {}
    for i, limb in enumerate(table):
        where = f"limbs[{i}]"
        check_table(path, where, limb, LIMB_KEYS)
        for key in ("name", "tip"):
            if not limb.get(key):
                raise file_error(path, f"{where} needs a non-empty string {key!r}")
        name, tip = limb["name"], limb["tip"]
        if name in actuated:
            raise file_error(path, f"{where}.name: duplicate limb name {name!r}; every limb needs its own name")
        _frame(path, f"{where}.tip", model, tip)
        limbs.append((name, tip))
        actuated[name] = _joints(path, f"{where}.actuated", joint_names, limb.get("actuated", []))
    return limbs, actuated


def _configurations(
    path: Path, table: Mapping[str, Any], joint_names: set[str]
) -> tuple[dict[str, NamedConfiguration], dict[str, Expectation]]:
    """``[configurations.<name>]``: joint values or a pose (with seed and approach), and expectations."""
    configurations, expected = {}, {}
    for cname, conf in table.items():
        where = f"configurations.{cname}"
        check_table(path, where, conf, CONFIG_KEYS)
        if ("joints" in conf) == ("pose" in conf):
            raise file_error(path, f"{where} needs exactly one of 'joints' or 'pose'")
        pose = None
        if "pose" in conf:
            check_table(path, f"{where}.pose", conf["pose"], POSE_KEYS)
            xyz = vector3(path, f"{where}.pose.xyz", conf["pose"].get("xyz", [0, 0, 0]))
            rpy = vector3(path, f"{where}.pose.rpy", conf["pose"].get("rpy", [0, 0, 0]))
            pose = pin.SE3(pin.rpy.rpyToMatrix(rpy), xyz)
        configurations[cname] = NamedConfiguration(
            cname,
            joint_values(path, f"{where}.joints", conf.get("joints", {}), joint_names),
            pose,
            joint_values(path, f"{where}.seed", conf.get("seed", {}), joint_names),
            joint_values(path, f"{where}.approach", conf.get("approach", {}), joint_names),
        )
        if "expected" in conf:
            exp = check_table(path, f"{where}.expected", conf["expected"], EXPECTED_KEYS)
            if "dof" not in exp or "motion_type" not in exp:
                raise file_error(path, f"{where}.expected needs an integer 'dof' and a string 'motion_type'")
            expected[cname] = Expectation(exp["dof"], exp["motion_type"], exp.get("source", ""))
    return configurations, expected


def _closures(path: Path, table: list[Mapping[str, Any]], model: pin.Model) -> list[Closure]:
    """``[[closures]]``: name, frames = [a, b], type (default 6d), axis (in frame a), axis_b (in frame b)."""
    out = []
    for i, c in enumerate(table):
        where = f"closures[{i}]"
        check_table(path, where, c, CLOSURE_KEYS)
        frames = c.get("frames")
        if frames is None or len(frames) != 2:
            raise file_error(path, f"{where}.frames must be a list of two frame names, got {frames!r}")
        axes = {k: vector3(path, f"{where}.{k}", c[k]) for k in ("axis", "axis_b") if k in c}
        try:
            out.append(
                make_closure(
                    model,
                    str(c.get("name", f"closure{i}")),
                    frames[0],
                    frames[1],
                    str(c.get("type", "6d")),
                    axes.get("axis"),
                    axes.get("axis_b"),
                )
            )
        except PinmobError as exc:
            raise file_error(path, f"{where}: {exc}") from None
    return out
