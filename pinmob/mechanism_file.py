"""Reading mechanism files: pinmob's TOML (URDF beside it) and built-in model names.

See the README for the format. Every error names the file and the key.
"""

from __future__ import annotations

import os
import tomllib
import warnings
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import pinocchio as pin

from .exceptions import MechanismFileError, PinmobError, choices
from .mechanism import Closure, Expectation, Mechanism, NamedConfiguration, make_closure

TOP_KEYS = {
    "name",
    "description",
    "urdf",
    "platform",
    "length_scale",
    "limbs",
    "configurations",
    "closures",
    "actuated",
    "generic_rank",
}
CLOSURE_KEYS = {"name", "frames", "type", "axis", "axis_b"}
LIMB_KEYS = {"name", "tip", "actuated"}
CONFIG_KEYS = {"joints", "pose", "seed", "approach", "expected"}
POSE_KEYS = {"xyz", "rpy"}
EXPECTED_KEYS = {"dof", "motion_type", "source"}

#: Loaders by file suffix; other modules register theirs here.
LOADERS: dict[str, Callable[[Path], Mechanism]] = {}


def builtin_dir() -> Path:
    """Folder of the built-in models (``pinmob/models`` installed, ``models/`` in a source checkout)."""
    try:
        return Path(str(resources.files("pinmob.models")))
    except ModuleNotFoundError:  # running from a source tree that is not installed
        return Path(__file__).resolve().parent.parent / "models"


def builtin_models() -> dict[str, Path]:
    """Built-in mechanism names and their files."""
    out = {}
    for path in sorted(builtin_dir().glob("*.toml")):
        with path.open("rb") as fh:
            out[str(tomllib.load(fh).get("name", path.stem))] = path
    return out


def load(name_or_path: str | Path) -> Mechanism:
    """Load a mechanism: a built-in model name, or a path to a mechanism file.

    Raises:
        MechanismFileError: the file is missing, does not parse, or is invalid;
            the message lists the built-in names when neither matches.
    """
    text = str(name_or_path)
    path = Path(text).expanduser()
    builtins = builtin_models()
    if text in builtins and not path.exists():
        return load_toml(builtins[text])
    suffix = path.suffix.lower()
    if not path.exists():
        raise MechanismFileError(
            f"{text!r} is neither a built-in model nor an existing file; built-in models: {choices(builtins)}"
        )
    if suffix == ".toml":
        return load_toml(path)
    if suffix in LOADERS:
        return LOADERS[suffix](path)
    raise MechanismFileError(f"{text!r}: unknown mechanism file type {suffix!r}; valid: {choices(['.toml', *LOADERS])}")


def file_error(path: Path, msg: str) -> MechanismFileError:
    """``MechanismFileError("<path>: <msg>")``: an error in a mechanism file, naming the file."""
    return MechanismFileError(f"{path}: {msg}")


@contextmanager
def errors_at(path: Path) -> Iterator[None]:
    """Name ``path`` in any :class:`PinmobError` raised inside (a :class:`MechanismFileError` names it already)."""
    try:
        yield
    except MechanismFileError:
        raise
    except PinmobError as exc:
        raise type(exc)(f"{path}: {exc}") from None


def _check_keys(path: Path, where: str, table: Mapping[str, Any], valid: set[str]) -> None:
    unknown = set(table) - valid
    if unknown:
        raise file_error(path, f"unknown key(s) {choices(unknown)} in {where}; valid keys: {choices(valid)}")


def _number_table(path: Path, where: str, table: Any, joint_names: set[str]) -> dict[str, float]:
    if not isinstance(table, Mapping):
        raise file_error(path, f"{where} must be a table of joint values, got {type(table).__name__}")
    out = {}
    for k, v in table.items():
        if k not in joint_names:
            raise file_error(path, f"{where} names unknown joint {k!r}; valid joints: {choices(joint_names)}")
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not np.isfinite(v):
            raise file_error(path, f"{where}.{k} must be a finite number [m or rad], got {v!r}")
        out[k] = float(v)
    return out


def _vector3(path: Path, where: str, value: Any) -> np.ndarray:
    if (
        not isinstance(value, list)
        or len(value) != 3
        or not all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in value)
    ):
        raise file_error(path, f"{where} must be a list of 3 numbers, got {value!r}")
    arr = np.array(value, float)
    if not np.isfinite(arr).all():
        raise file_error(path, f"{where} must be finite, got {value!r}")
    return arr


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


def load_urdf(path: Path, urdf: Path) -> tuple[pin.Model, pin.GeometryModel | None, pin.GeometryModel | None]:
    """Kinematic model from a URDF; visual/collision geometry when its meshes load (else a warning)."""
    if not urdf.exists():
        raise file_error(path, f"urdf file {str(urdf)!r} does not exist")
    try:
        model = pin.buildModelFromUrdf(str(urdf))
    except Exception as exc:  # pinocchio raises RuntimeError/ValueError with parser text
        raise file_error(
            path, f"urdf {str(urdf)!r} does not parse: {str(exc).strip().splitlines()[0] if str(exc).strip() else exc}"
        ) from None
    visual, collision = load_geometry(model, urdf)
    return model, visual, collision


def load_geometry(model: pin.Model, urdf: Path) -> tuple[pin.GeometryModel | None, pin.GeometryModel | None]:
    """Visual and collision geometry of a URDF for ``model``; ``None`` with a warning when meshes are missing."""
    geoms: list[pin.GeometryModel | None] = []
    for kind in (pin.GeometryType.VISUAL, pin.GeometryType.COLLISION):
        try:
            geoms.append(pin.buildGeomFromUrdf(model, str(urdf), kind, package_dirs=package_dirs(urdf)))
        except Exception as exc:
            warnings.warn(
                f"{urdf.name}: {kind.name.lower()} geometry not loaded ({str(exc).strip()[:200]}); kinematics only",
                stacklevel=4,
            )
            geoms.append(None)
    return geoms[0], geoms[1]


def load_toml(path: str | Path) -> Mechanism:
    """Load a pinmob mechanism file (TOML) and the URDF it names."""
    path = Path(path)
    if not path.exists():
        raise MechanismFileError(f"mechanism file {str(path)!r} does not exist")
    try:
        with path.open("rb") as fh:
            doc = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise file_error(path, f"TOML syntax error: {exc}") from None
    _check_keys(path, "the top level", doc, TOP_KEYS)
    for key in ("name", "urdf"):
        if not isinstance(doc.get(key), str) or not doc[key]:
            raise file_error(path, f"required key {key!r} must be a non-empty string")
    model, visual, collision = load_urdf(path, path.parent / doc["urdf"])
    joint_names = set(list(model.names)[1:])

    closures = _closures(path, doc.get("closures", []), model)
    limbs_doc = doc.get("limbs", [])
    if not isinstance(limbs_doc, list) or not (limbs_doc or closures):
        raise file_error(path, "needs at least one [[limbs]] table with 'name' and 'tip', or one [[closures]] table")
    limbs, actuated = [], {}
    for i, limb in enumerate(limbs_doc):
        _check_keys(path, f"limbs[{i}]", limb, LIMB_KEYS)
        if not isinstance(limb.get("name"), str) or not isinstance(limb.get("tip"), str):
            raise file_error(path, f"limbs[{i}] needs string keys 'name' and 'tip'")
        limbs.append((limb["name"], limb["tip"]))
        acts = limb.get("actuated", [])
        if not isinstance(acts, list) or not all(isinstance(a, str) for a in acts):
            raise file_error(path, f"limbs[{i}].actuated must be a list of joint names")
        actuated[limb["name"]] = acts
    extra = doc.get("actuated", [])
    if not isinstance(extra, list) or not all(isinstance(a, str) for a in extra):
        raise file_error(path, "top-level 'actuated' must be a list of joint names (actuated joints outside limbs)")
    actuated[""] = extra

    configurations, expected = {}, {}
    confs = doc.get("configurations", {})
    if not isinstance(confs, Mapping):
        raise file_error(path, "'configurations' must be a table of named configurations")
    for cname, conf in confs.items():
        where = f"configurations.{cname}"
        if not isinstance(conf, Mapping):
            raise file_error(path, f"{where} must be a table")
        _check_keys(path, where, conf, CONFIG_KEYS)
        if ("joints" in conf) == ("pose" in conf):
            raise file_error(path, f"{where} needs exactly one of 'joints' or 'pose'")
        pose = None
        if "pose" in conf:
            if not isinstance(conf["pose"], Mapping):
                raise file_error(path, f"{where}.pose must be a table with xyz and rpy")
            _check_keys(path, f"{where}.pose", conf["pose"], POSE_KEYS)
            xyz = _vector3(path, f"{where}.pose.xyz", conf["pose"].get("xyz", [0, 0, 0]))
            rpy = _vector3(path, f"{where}.pose.rpy", conf["pose"].get("rpy", [0, 0, 0]))
            pose = pin.SE3(pin.rpy.rpyToMatrix(rpy), xyz)
        configurations[cname] = NamedConfiguration(
            cname,
            _number_table(path, f"{where}.joints", conf.get("joints", {}), joint_names),
            pose,
            _number_table(path, f"{where}.seed", conf.get("seed", {}), joint_names),
            _number_table(path, f"{where}.approach", conf.get("approach", {}), joint_names),
        )
        if "expected" in conf:
            exp = conf["expected"]
            if not isinstance(exp, Mapping):
                raise file_error(path, f"{where}.expected must be a table with dof and motion_type")
            _check_keys(path, f"{where}.expected", exp, EXPECTED_KEYS)
            if not isinstance(exp.get("dof"), int) or not isinstance(exp.get("motion_type"), str):
                raise file_error(path, f"{where}.expected needs an integer 'dof' and a string 'motion_type'")
            expected[cname] = Expectation(exp["dof"], exp["motion_type"], str(exp.get("source", "")))

    length = doc.get("length_scale")
    if length is not None and (isinstance(length, bool) or not isinstance(length, (int, float)) or not length > 0):
        raise file_error(path, f"length_scale must be a positive number [m], got {length!r}")
    platform = doc.get("platform")
    if platform is not None and not isinstance(platform, str):
        raise file_error(path, f"platform must be a frame name, got {platform!r}")
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
            description=str(doc.get("description", "")),
            source=path,
            visual_model=visual,
            collision_model=collision,
            generic_rank=doc.get("generic_rank"),
            closures=closures,
        )


def _closures(path: Path, table: Any, model: pin.Model) -> list[Closure]:
    """``[[closures]]``: name, frames = [a, b], type (default 6d), axis (in frame a), axis_b (in frame b)."""
    if not isinstance(table, list):
        raise file_error(path, "'closures' must be an array of tables [[closures]]")
    out = []
    for i, c in enumerate(table):
        where = f"closures[{i}]"
        if not isinstance(c, Mapping):
            raise file_error(path, f"{where} must be a table")
        _check_keys(path, where, c, CLOSURE_KEYS)
        frames = c.get("frames")
        if not isinstance(frames, list) or len(frames) != 2 or not all(isinstance(f, str) for f in frames):
            raise file_error(path, f"{where}.frames must be a list of two frame names, got {frames!r}")
        axes = {k: _vector3(path, f"{where}.{k}", c[k]) for k in ("axis", "axis_b") if k in c}
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
