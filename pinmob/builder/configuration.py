"""Closed configurations for the builder's files: joint values by name, and checked writing."""

from __future__ import annotations

import tempfile
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike

from pinmob.exceptions import ConfigurationError, PinmobError

from .layout import check_rotation, point
from .text import is_generated

if TYPE_CHECKING:
    from pinmob.model.mechanism import Mechanism
    from pinmob.screw.algebra import Array


def joint_values(mech: Mechanism, q: Array) -> dict[str, float]:
    """Non-zero values [rad or m] of the one-degree joints of ``mech`` at q, by name (for a ``joints`` table).

    A continuous joint's value is ``atan2(sin, cos)`` of its two coordinates.
    """
    model = mech.model
    out = {}
    for j in range(1, model.njoints):
        joint = model.joints[j]
        if joint.nv != 1:
            continue
        x = float(np.arctan2(q[joint.idx_q + 1], q[joint.idx_q])) if joint.nq == 2 else float(q[joint.idx_q])
        if abs(x) > 1e-12:
            out[model.names[j]] = x
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

    from pinmob.assembly.assemble import assemble_pose, solve_actuated

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
    from pinmob.assembly.named import closed_configuration
    from pinmob.io.toml_file import load_toml

    for fname in texts:
        if (directory / fname).exists() and not is_generated(directory / fname):
            raise ConfigurationError(
                f"{directory / fname} exists and was not written by pinmob.builder: not overwritten; move it or "
                "choose another stem"
            )
    if check:
        with tempfile.TemporaryDirectory() as tmp:
            for fname, text in texts.items():
                (Path(tmp) / fname).write_text(text)
            mech = load_toml(Path(tmp) / toml)
            for cname in mech.configurations:
                try:
                    closed_configuration(mech, cname)
                except PinmobError as exc:
                    raise ConfigurationError(f"{name!r}, configuration {cname!r}: {exc}") from None
    directory.mkdir(parents=True, exist_ok=True)
    for fname, text in texts.items():
        (directory / fname).write_text(text)
    return directory / toml
