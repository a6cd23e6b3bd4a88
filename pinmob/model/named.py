"""A mechanism file's named configurations and the mobility the literature states for them (plain data)."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import pinocchio as pin


@dataclass(frozen=True)
class NamedConfiguration:
    """A named configuration: joint values, or a platform pose to assemble.

    Attributes:
        name: configuration name.
        joints: joint values by joint name [m or rad]; omitted joints are neutral.
        pose: platform pose (``pin.SE3``) to be assembled, or ``None``.
        seed: joint values that start the closure solver (select the assembly mode).
        approach: joint-space direction by joint name used by the paper's view
            (:func:`pinmob.paper_view`); empty when not declared.
        vector: the whole configuration vector (nq,) the joint values start from (e.g. an MJCF
            keyframe, with its free and ball joints), or ``None`` for Pinocchio's neutral.
        start: a starting point only (an MJCF keyframe, or MuJoCo's ``qpos0``, that does not close as
            given): when no configuration is asked for, the analysis searches for a closed configuration
            from each start in turn instead of refusing the first.
    """

    name: str
    joints: Mapping[str, float] = field(default_factory=dict)
    pose: pin.SE3 | None = None
    seed: Mapping[str, float] = field(default_factory=dict)
    approach: Mapping[str, float] = field(default_factory=dict)
    vector: tuple[float, ...] | None = None
    start: bool = False


@dataclass(frozen=True)
class Expectation:
    """Mobility stated by the literature for a named configuration."""

    dof: int
    motion_type: str
    source: str = ""
