"""The platform's free twists from the global loop-closure Jacobian: a second, independent method.

The limb-wise method (:mod:`pinmob.analysis.mobility`) stacks each limb's constraint wrenches; this one
takes the null space of every closure's Jacobian and maps it through one limb to the platform. The tests
check that both agree on every built-in model and configuration.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from pinmob.analysis.configuration import Configuration, as_configuration
from pinmob.assembly import CLOSURE_TOL, stacked_error
from pinmob.blas import one_blas_thread
from pinmob.model import Mechanism
from pinmob.screw import RTOL, Array, check_rtol, decide_rank, shift_twists, twist_scaling


@one_blas_thread
def closure_jacobian_twists(
    mech: Mechanism | Configuration,
    q: ArrayLike | str | Configuration | None = None,
    rtol: float = RTOL,
    *,
    closure_tol: float = CLOSURE_TOL,
) -> Array:
    """Free platform twists from the global loop-closure Jacobian (an independent method).

    Closure rows ``K = [J_2 - J_1; ...; J_k - J_1]`` (tip Jacobians over all
    joints, carried to the platform origin), followed by the rows of the
    mechanism's own closures (loops inside limbs, lengths divided by L, see
    :func:`~pinmob.assembly.residual.stacked_error`); the closed chain's joint
    velocities are ``null(K)``; the platform twists are their image ``J_1 null(K)``.
    Joint columns are scaled to comparable units before the rank decision.

    Args:
        mech: the mechanism, or a :class:`~pinmob.analysis.configuration.Configuration` (then ``q`` is None).
        q: a configuration vector, a configuration name, or a Configuration.
        rtol: relative rank tolerance, raised where the loops close only to CAD accuracy
            (:meth:`~pinmob.analysis.configuration.Configuration.rank_rtol`).
        closure_tol: closure tolerance for a vector or a name.

    Returns:
        (6, m) orthonormal (dimensionless) basis, in SI, of the platform's free twists.
    """
    conf = as_configuration(mech, q, closure_tol=closure_tol)
    rtol = conf.rank_rtol(check_rtol(rtol))
    mech = conf.mechanism
    model, data = mech.model, conf.data
    p = conf.platform_origin
    scale = twist_scaling(mech.length_scale)[:, None]
    full = [
        scale * shift_twists(conf.frame_jacobian(limb.tip_id), p - data.oMf[limb.tip_id].translation)
        for limb in mech.limbs
    ]
    col = np.linalg.norm(np.sum(np.abs(np.stack(full)), axis=0), axis=0)
    col = np.where(col > 0, 1.0 / np.where(col > 0, col, 1.0), 1.0)
    rows = [f - full[0] for f in full[1:]]
    if mech.closures:  # loops inside limbs (e.g. parallelograms): their rows, dimensionless like the tip rows
        rows.append(stacked_error(mech, model, data, mech.closures)[1])
    if rows:
        k = np.vstack(rows) * col
        dq = decide_rank(k, rtol, n=model.nv).null_space.T * col[:, None]
    else:
        dq = np.diag(col)
    # rank of the image against the size of the platform Jacobian itself: when every closed-chain motion
    # leaves the platform still (e.g. limbs folding at a dead centre) the image is round-off only
    image = full[0] @ dq
    reference = float(np.linalg.norm(full[0] * col, 2))
    if image.size == 0 or float(np.linalg.norm(image, 2)) <= rtol * reference:
        return np.zeros((6, 0))
    dec = decide_rank(image.T, rtol, n=6, reference=reference)
    return dec.row_space.T / scale
