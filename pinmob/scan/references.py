"""Where a scan starts: named configurations and platform poses, closed.

:func:`resolve_pose` reads a ``--at``, ``--from`` or ``--to`` that is a configuration name or a pose
``x,y,z,roll,pitch,yaw``; :func:`nearest_seed` picks the named configuration nearest a pose to assemble it from;
:func:`reference` closes either, and with a raised closure tolerance holds its CAD gaps
(:mod:`pinmob.assembly.cad_gaps`).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmob.assembly import Gaps, assemble_pose, closed_configuration, frame_gaps, gaps_closed, pose_from_vector
from pinmob.exceptions import ConfigurationError, PinmobError
from pinmob.model import CLOSURE_TOL, Mechanism, borrowed
from pinmob.name_matching import choices
from pinmob.screw import Array


def platform_pose(mech: Mechanism, q: Array, data: pin.Data | None = None) -> pin.SE3:
    """World pose of the platform frame at q (in ``data``, else in a pooled ``pin.Data``: a new one costs more)."""
    if data is None:
        with borrowed(mech.model) as pooled:
            return platform_pose(mech, q, pooled)
    pin.framesForwardKinematics(mech.model, data, q)
    return pin.SE3(data.oMf[mech.platform_id])


def resolve_pose(mech: Mechanism, text: str, closure_tol: float = CLOSURE_TOL) -> tuple[pin.SE3, Array]:
    """A named configuration, or ``x,y,z,roll,pitch,yaw`` [m, rad]: (platform pose, q closed within ``closure_tol``).

    q is empty for a pose (:func:`reference` assembles it).
    """
    if any(text.casefold() == name.casefold() for name in mech.configurations):
        q = closed_configuration(mech, text, closure_tol)
        return platform_pose(mech, q), q
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 6 or not np.all(np.isfinite(values)):
        raise ConfigurationError(
            f"{text!r} is neither a configuration of {mech.name!r} ({choices(mech.configurations)}) "
            "nor a pose 'x,y,z,roll,pitch,yaw' [m, rad]"
        )
    return pose_from_vector(np.array(values)), np.array([])


def nearest_seed(mech: Mechanism, pose: pin.SE3, closure_tol: float = CLOSURE_TOL) -> tuple[Array, bool]:
    """The named configuration (closed within ``closure_tol``) whose platform pose is nearest to ``pose``, and True.

    Without one that closes: the neutral configuration, unchecked, and False.
    """
    best, seed = np.inf, mech.neutral()
    for name in mech.configurations:
        try:
            q = closed_configuration(mech, name, closure_tol)
        except PinmobError:
            continue
        d = float(np.linalg.norm(pin.log6(platform_pose(mech, q).actInv(pose)).vector))
        if d < best:
            best, seed = d, q
    return seed, bool(np.isfinite(best))


def reference(mech: Mechanism, text: str, closure_tol: float = CLOSURE_TOL) -> tuple[pin.SE3, Array, Gaps]:
    """Where a scan starts (``--at``, ``--from``): platform pose, closed q, and the CAD gaps it holds.

    A pose is assembled from the nearest named configuration (:func:`nearest_seed`). With ``closure_tol`` above
    the default the gaps are those of the configuration named, or of that seed
    (:func:`pinmob.assembly.cad_gaps.frame_gaps`; the pose is assembled with them held); else none, and none
    when no named configuration closes (the seed is then the neutral configuration, whose misses are open loops).
    """
    pose, q = resolve_pose(mech, text, closure_tol)
    cad = closure_tol > CLOSURE_TOL
    if q.size:
        return pose, q, frame_gaps(mech, q, closure_tol) if cad else ()
    seed, closed = nearest_seed(mech, pose, closure_tol)
    gaps = frame_gaps(mech, seed, closure_tol) if cad and closed else ()
    return pose, assemble_pose(gaps_closed(mech, gaps), pose, seed, closure_tol), gaps
