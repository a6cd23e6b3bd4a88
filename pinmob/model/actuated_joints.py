"""Which joints are actuated: a mechanism's actuation given after loading (e.g. ``--actuated`` on the command line)."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import replace

from pinmob.exceptions import ConfigurationError, FrameError
from pinmob.model.joints import joint_names
from pinmob.model.mechanism import Mechanism
from pinmob.name_matching import choices, did_you_mean


def with_actuated(mech: Mechanism, names: Sequence[str]) -> Mechanism:
    """A copy of ``mech`` whose actuated joints are ``names`` (each limb gets those of its chain), and no other actuator.

    The actuators of the file are replaced, those on tendons too (:attr:`Mechanism.actuated_tendons`), and their
    names (:attr:`Mechanism.joint_actuators`).

    Raises:
        FrameError: a name is not a joint of the model (the message lists them).
        ConfigurationError: a joint named twice.
    """
    valid = joint_names(mech.model)
    for a in names:
        if a not in valid:
            raise FrameError(
                f"actuated joint {a!r} does not exist in {mech.name!r}{did_you_mean(a, valid)}; valid: {choices(valid)}"
            )
    if len(set(names)) != len(names):
        raise ConfigurationError(f"actuated joints must be named once each, got {list(names)}")
    limbs = tuple(replace(b, actuated=tuple(a for a in names if a in b.joints)) for b in mech.limbs)
    in_limbs = {a for b in limbs for a in b.actuated}
    extra = tuple(a for a in names if a not in in_limbs)
    return replace(mech, limbs=limbs, extra_actuated=extra, actuated_tendons=(), joint_actuators=())
