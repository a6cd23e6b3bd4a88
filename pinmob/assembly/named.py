"""Named configurations of a mechanism file, closed: joint values checked, platform poses assembled."""

from __future__ import annotations

import numpy as np

from pinmob.assembly.assemble import assemble_pose
from pinmob.assembly.residual import CLOSURE_TOL, check_closed
from pinmob.model.mechanism import Mechanism
from pinmob.screw.algebra import Array


def closed_configuration(mech: Mechanism, name: str, tol: float = CLOSURE_TOL) -> Array:
    """The named configuration ``name`` of ``mech`` as a closed configuration vector, shape (nq,).

    Joint values are checked for closure; a pose is assembled by
    :func:`~pinmob.assembly.assemble.assemble_pose` from the configuration's
    seed. Raises :class:`~pinmob.exceptions.ClosureError` when it does not close
    within ``tol`` (position / L and rotation [rad]).

    Raises:
        ConfigurationError: no configuration ``name``, even ignoring case (the message lists them).
        ClosureError: the configuration does not close, or its pose cannot be assembled.
    """
    q, checked = named_vector(mech, name, tol)
    if not checked:
        check_closed(mech, q, tol, f"configuration {name!r}")
    return q


def named_vector(mech: Mechanism, name: str, tol: float = CLOSURE_TOL) -> tuple[Array, bool]:
    """The named configuration's vector, and whether its closure was checked.

    A pose is assembled (and so checked); joint values are returned as they
    are, for a caller that checks the closure itself (a
    :class:`~pinmob.analysis.configuration.Configuration` does, with the kinematics
    it computes anyway, and says the same as :func:`closed_configuration` when it
    does not close).

    Raises:
        ConfigurationError: no configuration ``name`` (the message lists them).
        ClosureError: its pose cannot be assembled.
    """
    name = mech.configuration_name(name)
    conf = mech.configurations[name]
    if conf.pose is not None:
        return assemble_pose(mech, conf.pose, mech.q_from_joints(conf.seed), tol), True
    base = None if conf.vector is None else np.array(conf.vector)
    return mech.q_from_joints(conf.joints, base), False
