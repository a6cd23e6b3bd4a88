"""Closed configurations for the builder's files: joint values by name, and checked writing."""

from __future__ import annotations

import tempfile
from collections.abc import Mapping
from numbers import Real
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from pinmob.exceptions import ConfigurationError, PinmobError

from .layout import check_rotation, point
from .text import is_generated

if TYPE_CHECKING:
    import pinocchio as pin

    from pinmob.model import Mechanism
    from pinmob.screw import Array


def canonical_angle(x: float) -> float:
    """The angle ``x`` [rad] moved by a multiple of 2 pi into the canonical range (-pi, pi]."""
    return float(np.pi - np.mod(np.pi - float(x), 2 * np.pi))


def joint_values(mech: Mechanism, q: Array) -> dict[str, float]:
    """Non-zero values [rad or m] of the one-degree joints of ``mech`` at q, by name (for a ``joints`` table).

    Revolute angles are written in (-pi, pi] (:func:`pinmob.closure.wrap_angles`: where a joint's limits
    exclude that value, the representative inside them closest to 0). A continuous joint's value is
    ``atan2(sin, cos)`` of its two coordinates, in (-pi, pi].
    """
    from pinmob.model import wrap_angles

    model = mech.model
    q = wrap_angles(model, np.asarray(q, float))
    out = {}
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.nv != 1:
            continue
        if joint.nq == 2:
            x = canonical_angle(np.arctan2(q[joint.idx_q + 1], q[joint.idx_q]))
        else:
            x = float(q[joint.idx_q])
        if abs(x) > 1e-12:
            out[model.names[j]] = x
    return out


def canonical_joints(model: pin.Model, values: Mapping[str, Any]) -> dict[str, Any]:
    """``values`` (joint values by name, as in a ``joints`` or ``seed`` table) with revolute angles canonical.

    Every revolute angle is moved by a multiple of 2 pi into (-pi, pi] (for a joint with position limits
    that exclude that value, the representative inside them closest to 0, as the closure solver's
    :func:`pinmob.closure.wrap_angles`); a continuous joint's angle into (-pi, pi]. Prismatic values,
    unknown names and values that are not numbers are left as they are (loading the file reports those).
    So a configuration is written the same way whatever branch of ``atan2`` round-off picked.
    """
    from pinmob.model import angle_mask, has_joint, wrap_angles

    mask = angle_mask(model)
    out = dict(values)
    for name, value in values.items():
        if not has_joint(model, name) or isinstance(value, bool) or not isinstance(value, Real):
            continue
        joint, x = model.joints[model.getJointId(name)], float(value)
        if joint.nv != 1 or not np.isfinite(x):
            continue
        if joint.nq == 2:
            out[name] = canonical_angle(x)
        elif mask[joint.idx_q]:
            q = np.zeros(model.nq)  # only this coordinate is read back
            q[joint.idx_q] = x
            out[name] = float(wrap_angles(model, q)[joint.idx_q])
    return out


def closed_joints(
    mech: Mechanism,
    fixed: Mapping[str, float] | None = None,
    pose: tuple[ArrayLike, ArrayLike] | None = None,
    seed: Mapping[str, float] | None = None,
) -> dict[str, float]:
    """Joint values [rad or m] of a closed configuration of ``mech`` (its non-zero ones, by name).

    Either the ``fixed`` one-degree joints are held at their values and the
    others follow (:func:`pinmob.assembly.assemble.solve_actuated`), or the platform is
    put at ``pose = (xyz [m], rotation (3, 3))`` (:func:`pinmob.assembly.assemble.assemble_pose`).
    Both solve every loop closure by damped least squares from ``seed`` (joint
    values by name; the neutral configuration elsewhere), which selects the
    assembly mode.

    Raises:
        ClosureError: the solver did not close the loops.
    """
    import pinocchio as pin

    from pinmob.assembly import assemble_pose, solve_actuated

    start = mech.q_from_joints(seed or {})
    if pose is not None:
        target = pin.SE3(check_rotation("pose", pose[1]), np.array(point("pose", pose[0])))
        q = assemble_pose(mech, target, start)
    else:
        q = solve_actuated(mech, dict(fixed or {}), seed=start).q
    return joint_values(mech, q)


def write_files(name: str, directory: Path, texts: Mapping[str, str], toml: str, check: bool = True) -> Path:
    """Write ``texts`` (file name -> text) into ``directory``; returns the path of ``toml``.

    Refuses (before writing anything) to replace a file the builder did not write
    (:func:`pinmob.builder.text.is_generated`). With ``check`` the files are first
    written to a temporary folder and loaded, and every named configuration is
    closed there (a pose assembled, joint values checked).

    Raises:
        ConfigurationError: a foreign file in the way, or a configuration that does not close.
    """
    from pinmob.assembly import closed_configuration
    from pinmob.io import load_toml

    for fname in texts:
        if (directory / fname).exists() and not is_generated(directory / fname):
            raise ConfigurationError(
                f"{directory / fname} exists and was not written by pinmob.builder: not overwritten; move it or "
                "choose another stem"
            )
    if check:
        with tempfile.TemporaryDirectory() as tmp:
            for fname, text in texts.items():
                (Path(tmp) / fname).write_text(text, encoding="utf-8")
            mech = load_toml(Path(tmp) / toml)
            for cname in mech.configurations:
                try:
                    closed_configuration(mech, cname)
                except PinmobError as exc:
                    raise ConfigurationError(f"{name!r}, configuration {cname!r}: {exc}") from None
    directory.mkdir(parents=True, exist_ok=True)
    for fname, text in texts.items():
        (directory / fname).write_text(text, encoding="utf-8")  # TOML is UTF-8 whatever the locale
    return directory / toml
