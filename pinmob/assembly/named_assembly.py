"""Named configurations of a mechanism file, and joint values given by name, closed: checked, solved or assembled."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from pinmob.assembly.assemble import assemble_pose, solve_actuated
from pinmob.assembly.residual import CLOSURE_TOL, check_closed
from pinmob.exceptions import ClosureError, ConfigurationError
from pinmob.model import Mechanism
from pinmob.screw import Array


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

    A pose is assembled (and so checked) once per mechanism and tolerance (the
    vector is kept in the mechanism's cache, a copy is returned); joint values
    are returned as they are, for a caller that checks the closure itself (a
    :class:`~pinmob.analysis.configuration.Configuration` does, with the kinematics
    it computes anyway, and says the same as :func:`closed_configuration` when it
    does not close).

    Raises:
        ConfigurationError: no configuration ``name`` (the message lists them), or one whose joint values are
            not finite.
        ClosureError: its pose cannot be assembled.
    """
    name = mech.configuration_name(name)
    conf = mech.configurations[name]
    if conf.pose is not None:
        pose, seed = conf.pose, conf.seed

        def assembled() -> Array:
            q = assemble_pose(mech, pose, mech.q_from_joints(seed), tol)
            q.flags.writeable = False  # kept in the mechanism's cache, read-only as its other arrays
            return q

        return mech.memo(("named pose", name, tol), assembled).copy(), True
    base = None if conf.vector is None else np.array(conf.vector)
    q = mech.q_from_joints(conf.joints, base)
    if not np.isfinite(q).all():  # a keyframe's qpos of nan or inf (MuJoCo compiles it as given)
        model = mech.model
        bad = [
            model.names[j]
            for j in range(1, model.njoints)
            if not np.isfinite(q[model.joints[j].idx_q : model.joints[j].idx_q + model.joints[j].nq]).all()
        ]
        raise ConfigurationError(
            f"configuration {name!r} of {mech.name!r} gives joint(s) {', '.join(map(repr, bad))} a value that is not "
            "a finite number; give finite values (or another configuration)"
        )
    return q, False


def close_joint_values(
    mech: Mechanism, values: Mapping[str, float], base: Array | None = None, tol: float = CLOSURE_TOL
) -> tuple[Array, bool]:
    """A closed configuration with the given joint values, and whether the other joints had to be solved.

    The other joints come from ``base`` (default: Pinocchio's neutral); when that does not close within
    ``tol``, they are solved with the given joints held (:func:`~pinmob.assembly.assemble.solve_actuated`,
    seeded there).

    Raises:
        FrameError: an unknown joint (the message lists them).
        ConfigurationError: a value that is not finite, or a joint of several coordinates.
        ClosureError: the loops cannot be closed with these values from there.
    """
    q = mech.q_from_joints(values, base)
    try:
        check_closed(mech, q, tol, "joint values given")
        return q, False
    except ClosureError:
        return solve_actuated(mech, values, seed=q, tol=tol).q, True
