"""Assembly modes: the distinct closed configurations reached from several seeds, modulo idle motions.

:func:`assembly_modes` solves from several seeds and keeps the distinct
solutions, compared modulo idle motions (:func:`mode_distance`): two solutions
are one mode when every joint centre, every closure point and the pose of every
end frame agree (a rod spinning between two ball joints moves none of them), and
so do the held joints. A continuum of solutions (the held joints do not fix the
mechanism) is refused, which needs the whole-mechanism analysis.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
import pinocchio as pin

from pinmob.analysis.chain.actuation import default_end_frames
from pinmob.analysis.chain.mechanism_mobility import mechanism_mobility
from pinmob.analysis.configuration import Configuration
from pinmob.assembly import CLOSURE_TOL, Assembly, joint_velocity_indices, project, random_configuration, solve_actuated
from pinmob.blas import one_blas_thread
from pinmob.exceptions import ClosureError, ConfigurationError
from pinmob.model import Mechanism, frame_id, linear_velocity_mask
from pinmob.name_matching import choices
from pinmob.progress import step
from pinmob.screw import RTOL, Array


@dataclass(frozen=True)
class ModeSignature:
    """What tells two assembly modes apart, modulo idle motions.

    Attributes:
        points: (k, 3) joint centres and origins of the closure frames that are
            not welds [m] (a weld's frames are inside one rigid body).
        rotations: (n, 3, 3) orientations of the end frames (their origins are
            in ``points``).
        held: (h,) values of the held joints (velocity order; angles [rad], lengths [m]).
    """

    points: Array
    rotations: Array
    held: Array


def mode_signature(mech: Mechanism, q: Array, frames: Sequence[str], held: Sequence[str] = ()) -> ModeSignature:
    """The :class:`ModeSignature` at q for the end ``frames`` and the ``held`` joints."""
    model = mech.model
    data = pin.Data(model)
    pin.framesForwardKinematics(model, data, q)
    ids = [frame_id(model, f) for f in frames]
    points = [data.oMi[j].translation for j in range(1, model.njoints)]
    points += [data.oMf[c.frame_a_id].translation for c in mech.all_closures if c.type != "6d"]
    points += [data.oMf[i].translation for i in ids]
    idx = joint_velocity_indices(mech, list(held))
    values = pin.difference(model, mech.neutral(), q)[idx]
    rotations = np.array([data.oMf[i].rotation for i in ids]).reshape(-1, 3, 3)
    return ModeSignature(np.array(points).reshape(-1, 3), rotations, values)


def mode_distance(mech: Mechanism, a: ModeSignature, b: ModeSignature, held: Sequence[str] = ()) -> float:
    """Dimensionless distance between two signatures.

    The largest of ``|p_a - p_b| / L`` over the points, the rotation angle ``|log3(R_a^T R_b)|``
    [rad] over the end frames, and the held joints' differences (angles modulo
    2 pi, lengths / L).
    """
    d = [float(np.max(np.linalg.norm(a.points - b.points, axis=1), initial=0.0)) / mech.length_scale]
    d += [float(np.linalg.norm(pin.log3(ra.T @ rb))) for ra, rb in zip(a.rotations, b.rotations)]
    if len(held):
        lin = linear_velocity_mask(mech.model)[joint_velocity_indices(mech, list(held))]
        diff = b.held - a.held
        d.append(float(np.max(np.where(lin, np.abs(diff) / mech.length_scale, np.abs(np.angle(np.exp(1j * diff)))))))
    return max(d)


def _moving(mech: Mechanism, q: Array, held: Sequence[str], frames: Sequence[str], tol: float) -> int:
    """Non-idle motions left at q with the ``held`` joints locked (locked minus idle, :mod:`pinmob.analysis.chain.actuation`)."""
    conf = Configuration(mech, q, closure_tol=tol)
    act = mechanism_mobility(conf, RTOL, actuated=list(held), frames=list(frames)).actuation
    return act.locked_dof - act.idle_dof


@one_blas_thread
def assembly_modes(
    mech: Mechanism,
    values: Mapping[str, float] | None = None,
    seeds: int = 16,
    seed: int = 0,
    tol: float = CLOSURE_TOL,
    distinct: float = 1e-3,
) -> list[Assembly]:
    """Distinct closed configurations reached from the neutral and ``seeds`` random seeds.

    With ``values`` (joint values held, e.g. the actuated ones), each is a
    forward-kinematics solution (:func:`solve_actuated`); otherwise a
    projection. Two solutions are one mode when :func:`mode_distance` of their
    signatures (end frames: :func:`pinmob.analysis.chain.actuation.default_end_frames`) is
    below ``distinct``: copies that differ only by idle motions count once.
    Seeds that fail to converge are skipped.

    Raises:
        ConfigurationError: the held joints do not fix the mechanism: at the
            first two distinct solutions, motions that are not idle remain
            (the closed configurations form a continuum, not discrete modes).
    """
    held = list(values or {})
    frames = default_end_frames(mech)
    rng = np.random.default_rng(seed)
    found: list[Assembly] = []
    signatures: list[ModeSignature] = []
    moving: list[int] = []
    rigid = False
    with step(f"searching the assembly modes of {mech.name}", total=seeds + 1) as bar:
        for k in range(seeds + 1):
            bar.update()
            start = mech.neutral() if k == 0 else random_configuration(mech, rng)
            label = "neutral" if k == 0 else f"random seed {k} (seed {seed})"
            try:
                sol = solve_actuated(mech, values, start, tol) if values else project(mech, start, tol)
            except ClosureError:
                continue
            sig = mode_signature(mech, sol.q, frames, held)
            if any(mode_distance(mech, sig, other, held) <= distinct for other in signatures):
                continue
            found.append(replace(sol, method=f"{sol.method} from {label}"))
            signatures.append(sig)
            if not rigid:
                left = _moving(mech, sol.q, held, frames, tol)
                rigid = left == 0
                moving += [left] if left else []
            if not rigid and len(moving) >= 2:
                what = f"with {', '.join(held)} held" if held else "with no joint held"
                raise ConfigurationError(
                    f"{mech.name!r} {what} still moves ({moving[0]} motion(s) that are not idle at each solution found): "
                    "its closed configurations form a continuum, not discrete assembly modes; hold more joints "
                    f"(declared actuated: {choices(mech.actuated)})"
                )
    return found
