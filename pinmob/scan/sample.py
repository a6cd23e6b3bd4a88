"""One scan sample on its own: its target assembled warm-started, and its row from the single-sample analysis.

The single-sample path of :mod:`pinmob.scan.chunk` (every sample with ``engine="single"``; with the batched
engine the samples the batch cannot decide, and the refinements' trial points).
"""

from __future__ import annotations

from typing import Any

from pinmob.analysis import Configuration, generic_constraint_rank, platform_mobility
from pinmob.analysis.singularity import Singularity, singularity  # its face: pinmob.analysis cannot export it
from pinmob.assembly import assemble_coordinates, assemble_joints, assemble_pose, pose_vector
from pinmob.model import CLOSURE_TOL, Mechanism
from pinmob.scan.scan_spec import POSE_COORDS
from pinmob.scan.unreachable import SV_COLUMNS, VERDICT_COLUMNS
from pinmob.screw import RTOL, Array

#: Iterations of the closure solver per sample (warm starts converge in a few; unreachable targets fail fast).
MAX_ITER = 40

#: A sample's platform-pose assembly gives up when its cost gained less than 0.1% over this many damped
#: iterations (:func:`pinmob.assembly.solver.solve`'s ``stall_window``; 20 elsewhere, and in the refinements,
#: whose trials next to an edge of the reachable set converge slowly): a sample out of reach costs about 6
#: iterations instead of 20 to 40. The iterates do not depend on it, only where an unconverged solve stops.
STALL_WINDOW = 5


def assemble_target(
    mech: Mechanism,
    target: tuple[str, Any],
    seed: Array,
    max_iter: int = MAX_ITER,
    tol: float = CLOSURE_TOL,
    stall_window: int | None = None,
) -> Array:
    """A closed configuration at a scan target, warm-started from ``seed``.

    The target is a platform pose, actuated joint values, or (a grid's) some pose coordinates and joint values,
    the rest following (:func:`pinmob.assembly.partial_pose.assemble_coordinates`). ``stall_window`` of a pose
    target's solver: None for a sample's (``STALL_WINDOW``).
    """
    kind, value = target
    window = STALL_WINDOW if stall_window is None else stall_window
    if kind == "pose":
        return assemble_pose(mech, value, seed, tol, max_iter=max_iter, stall_window=window, compiled=True)
    if kind == "coords":
        return assemble_coordinates(mech, value[0], value[1], seed, tol, max_iter=max_iter, stall_window=window)
    return assemble_joints(mech, value, seed, tol, max_iter=max_iter)


def evaluate(
    mech: Mechanism, q: Array, rtol: float = RTOL, generic_rank: int | None = None, closure_tol: float = CLOSURE_TOL
) -> dict[str, Any]:
    """One scan row at a closed configuration: pose, DoF, motion type, singularity, singular values.

    With ``closure_tol`` above the default, as :func:`pinmob.analyze` at that tolerance: the rank tolerance is
    :meth:`~pinmob.analysis.configuration.Configuration.rank_rtol` (at least 10 x q's closure residual), and the
    row adds ``residual`` and ``rank_rtol``.
    """
    return _evaluate(mech, q, rtol, generic_rank, closure_tol)[0]


#: A configuration examined for its distances (:func:`examine`): its state, the rank tolerance there, its singularity.
Examined = tuple[Configuration, float, Singularity]


def examine(
    mech: Mechanism, q: Array, rtol: float, generic_rank: int | None, closure_tol: float = CLOSURE_TOL
) -> Examined:
    """The :class:`Configuration` at q, the rank tolerance used there and its singularity (with the distances).

    A refinement's trial point needs its distances only; the row of the one kept reuses all three
    (:func:`_evaluate` with ``examined``), the quantities the singularity computed cached on the configuration.
    """
    g = generic_constraint_rank(mech, rtol=rtol) if generic_rank is None else generic_rank
    conf = Configuration(mech, q, closure_tol=closure_tol)
    cad = closure_tol > CLOSURE_TOL  # loops closed to CAD accuracy: analyze's rank tolerance at this residual
    rtol = conf.rank_rtol(rtol) if cad else rtol
    return conf, rtol, singularity(conf, rtol, g)


def _evaluate(
    mech: Mechanism,
    q: Array,
    rtol: float,
    generic_rank: int | None,
    closure_tol: float = CLOSURE_TOL,
    examined: Examined | None = None,
) -> tuple[dict[str, Any], dict[str, float]]:
    """The row and the distance of each question, from one :class:`Configuration` (one kinematics computation).

    ``examined``: :func:`examine`'s at q, already computed (None: computed here).
    """
    conf, rtol, sing = examine(mech, q, rtol, generic_rank, closure_tol) if examined is None else examined
    cad = closure_tol > CLOSURE_TOL
    mob = platform_mobility(conf, rtol)
    row: dict[str, Any] = dict(zip(POSE_COORDS, pose_vector(conf.frame_placement(mech.platform_id)).tolist()))
    verdict = dict(
        reachable=True,
        dof=mob.dof,
        motion_type=mob.motion_type,
        constraint_rank=mob.constraint_rank,
        locked_dof=sing.locked_dof,
        singularity=sing.label,
        near_singular=sing.near_singular,
        closest=sing.closest_all[0],  # the first of those tied within round-off: not decided by it
        singular_limbs=";".join(sing.limbs),
        dependent_limbs=";".join(sing.dependent_limbs),
        uncontrolled=";".join(m.label for m in sing.uncontrolled),
        distance=sing.distance,
    )
    row.update((k, verdict[k]) for k in VERDICT_COLUMNS)  # in the columns' order, each named
    row.update(zip(SV_COLUMNS, [*sing.constraint_singular_values.tolist(), *sing.actuation_singular_values.tolist()]))
    if cad:
        row.update(residual=conf.residual, rank_rtol=rtol)
    return row, sing.distances
