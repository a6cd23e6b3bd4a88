"""Plain URDF files with onshape-to-robot's closing frames: a loop closure per ``closing_<name>_1/_2`` pair.

onshape-to-robot (and placo, which reads its exports) marks each loop of a URDF with two frames, links
named ``closing_<name>_1`` and ``closing_<name>_2`` fixed on the two bodies the loop joins; the loop is
closed when their origins meet (a point closure: what the exporter writes for MuJoCo, ``<connect
site1 site2>``, and what placo solves). Each pair is a ``3d`` :class:`~pinmob.model.closure.Closure`
named ``<name>``. Each ``<mimic>`` joint is a ``joint`` coupling (:mod:`pinmob.io.mimic`): a URDF with
mimic joints and no closing frame is a coupled mechanism. A URDF says nothing of actuation: the actuated joints are given on the command line
(``--actuated a,b``) or with :meth:`pinmob.model.mechanism.Mechanism.with_actuated`. The mechanism's
name is the file's ``<robot name>`` (the file's stem when it gives none).
"""

from __future__ import annotations

import re
import warnings
from pathlib import Path

import pinocchio as pin

from pinmob.bounds import bound
from pinmob.io.gazebo_joints import urdf_loop_joints, urdf_text
from pinmob.io.mimic import mimic_couplings, unique
from pinmob.io.schema import errors_at, file_error
from pinmob.io.urdf import load_geometry, read_urdf
from pinmob.model import Mechanism, make_closure

#: A closing frame's name: ``closing_<name>_1`` or ``closing_<name>_2``.
CLOSING = re.compile(r"^closing_(.+)_([12])$")


def closing_pairs(path: Path, model: pin.Model, couplings: int = 0) -> dict[str, tuple[str, str]]:
    """``{loop name: (frame _1, frame _2)}`` of the URDF's closing frames (its links, BODY frames).

    ``couplings`` is the number of the URDF's mimic couplings and Gazebo loop joints: with at least one, a URDF
    without closing frames is a closed or coupled mechanism (no pair).

    Raises:
        MechanismFileError: a frame without its partner, or neither a closing frame, a mimic joint nor a Gazebo
            loop joint (the
            message says what to add).
    """
    sides: dict[str, dict[str, str]] = {}
    for frame in model.frames:
        match = CLOSING.match(frame.name)
        if match and frame.type == pin.FrameType.BODY:
            sides.setdefault(match.group(1), {})[match.group(2)] = frame.name
    if not sides and not couplings:
        raise file_error(
            path,
            "a plain URDF without a <mimic> joint between moving joints has no loop closure: add onshape-to-robot's "
            "closing frames (links closing_<name>_1 and closing_<name>_2 on the two bodies each loop joins), a loop "
            "joint for Gazebo (<gazebo><joint>), or describe the loops in a pinmob TOML file or an "
            "Extended URDF YAML sidecar beside it (see docs/closed-chains.md#formats)",
        )
    lonely = sorted(f"closing_{n}_{'2' if '1' in s else '1'}" for n, s in sides.items() if len(s) < 2)
    if lonely:
        raise file_error(path, f"closing frame(s) without a partner: missing {', '.join(lonely)}")
    return {n: (s["1"], s["2"]) for n, s in sorted(sides.items())}


def load_closing_urdf(path: str | Path, text: str | None = None) -> Mechanism:
    """Load a URDF with onshape-to-robot closing frames and mimic joints (see the module docstring); no actuated joint.

    ``text``: the URDF itself (expanded from the xacro file ``path``: no geometry is loaded).
    """
    path = Path(path)
    model = read_urdf(path, text)
    try:  # loop joints written for Gazebo, and the <constraint> elements pinmob does not read
        loop_joints, ignored = urdf_loop_joints(model, text or urdf_text(path, bound("bytes")))
    except ValueError as exc:
        raise file_error(path, str(exc)) from None
    couplings = mimic_couplings(path, model, text)
    pairs = closing_pairs(path, model, len(couplings) + len(loop_joints))
    if ignored:
        warnings.warn(f"{path.name}: not read: {'; '.join(ignored)}", stacklevel=3)
    with errors_at(path):
        closures = [make_closure(model, name, a, b, "3d") for name, (a, b) in pairs.items()] + loop_joints
        return Mechanism.from_model(
            model,
            [],
            name=model.name or path.stem,
            description=f"URDF {path.name} with {described(len(pairs), len(couplings), len(loop_joints))}",
            source=path,
            geometry=load_geometry(model, path) if text is None else None,
            closures=unique(path, closures + couplings),
        ).with_ignored(ignored)


def described(pairs: int, couplings: int, loops: int = 0) -> str:
    """``onshape-to-robot closing frames``, ``N mimic joint(s)``, ``N Gazebo loop joint(s)``: a URDF's closures."""
    said = ["onshape-to-robot closing frames"] if pairs else []
    said += [f"{loops} Gazebo loop joint{'s' * (loops != 1)}"] if loops else []
    said += [f"{couplings} mimic joint{'s' * (couplings != 1)}"] if couplings else []
    return " and ".join(said)
