"""A limb: the serial chain of joints from the base to a tip frame that meets the platform."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from pinmob.screw import Array


@dataclass(frozen=True)
class Limb:
    """A serial chain from the base to the platform.

    Attributes:
        name: limb name.
        tip: name of the frame at the end of the chain.
        tip_id: Pinocchio frame index of ``tip``.
        joints: names of the joints supporting ``tip``, base to tip.
        v_indices: (nv_limb,) velocity indices of those joints in the model.
        actuated: names of this limb's actuated joints.
        closures: names of the closures internal to this limb (loops such as
            a parallelogram that involve its joints and no other limb's).
        loop_joints: joints in no limb that those closures involve (e.g. the
            second rod of a parallelogram), in model order.
        loop_v_indices: velocity indices of ``loop_joints``.
    """

    name: str
    tip: str
    tip_id: int
    joints: tuple[str, ...]
    v_indices: Array = field(repr=False)
    actuated: tuple[str, ...] = ()
    closures: tuple[str, ...] = ()
    loop_joints: tuple[str, ...] = ()
    loop_v_indices: Array = field(default_factory=lambda: np.zeros(0, int), repr=False)

    @property
    def screw_v_indices(self) -> Array:
        """Velocity indices of the joints whose rates move the limb: ``v_indices`` then ``loop_v_indices``."""
        return np.concatenate([self.v_indices, self.loop_v_indices]).astype(int)
