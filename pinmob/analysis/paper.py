"""The seed paper's view: each limb's generic constraint wrenches carried to the configuration.

Where no limb is serially singular at q, the generic wrenches are the wrenches
at q and this view equals :func:`pinmob.analysis.mobility.platform_mobility`.
Otherwise it reproduces the seed paper's procedure: it derives each limb's
reciprocal screws at a generic configuration and substitutes the special
configuration into that formula (e.g. beta = 0 in its eq. 20). A limb at a
serial singularity has more wrenches at q than that limit; the analysis at q
counts them, this view does not.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pinocchio as pin

from pinmob.analysis.configuration import Configuration
from pinmob.analysis.generic import generic_twist_ranks
from pinmob.analysis.limbs import limb_twists, limb_wrenches, rate_scale
from pinmob.analysis.mobility import Mobility, mobility_from_wrenches
from pinmob.analysis.motion import View
from pinmob.assembly import closed_configuration
from pinmob.blas import one_blas_thread
from pinmob.exceptions import ConfigurationError
from pinmob.model import Mechanism, has_joint, joint_names
from pinmob.name_matching import choices, did_you_mean
from pinmob.screw import Array, reciprocal_wrenches, wrench_scaling

#: name of the configuration the paper view comes from when none is declared
GENERIC = "generic"


def _direction(mech: Mechanism, approach: Array | Mapping[str, float]) -> Array:
    """Joint-space direction (nv,) from an array or from rates by joint name (one-dof joints)."""
    model = mech.model
    if isinstance(approach, Mapping):
        dv = np.zeros(model.nv)
        for name, value in approach.items():
            if not has_joint(model, name):
                raise ConfigurationError(
                    f"approach names unknown joint {name!r}{did_you_mean(name, joint_names(model))}; "
                    f"valid: {choices(joint_names(model))}"
                )
            joint = model.joints[model.getJointId(name)]
            if joint.nv != 1:
                raise ConfigurationError(
                    f"approach: joint {name!r} has {joint.nv} velocity coordinates; give the whole (nv,) direction"
                )
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
                raise ConfigurationError(f"approach: rate of joint {name!r} must be a number, got {value!r}")
            dv[joint.idx_v] = float(value)
    else:
        try:
            dv = np.array(approach, dtype=float)
        except (TypeError, ValueError):
            raise ConfigurationError(
                f"approach direction must be an array of {model.nv} numbers, got {approach!r}"
            ) from None
        if dv.shape != (model.nv,):
            raise ConfigurationError(f"approach direction must have shape ({model.nv},), got {dv.shape}")
    if not np.all(np.isfinite(dv)):
        raise ConfigurationError(
            f"approach direction must be finite, got non-finite values at {np.flatnonzero(~np.isfinite(dv)).tolist()}"
        )
    return dv


@one_blas_thread
def paper_mobility(
    conf: Configuration,
    rtol: float,
    approach: Array | Mapping[str, float] | None = None,
    *,
    eps: float = 1e-3,
) -> Mobility:
    """Mobility allowed by each limb's *generic* constraint wrenches, carried to the configuration.

    Each limb's wrench space is followed along ``q(s) = integrate(q, s * dv)``
    (limbs are serial chains, so q(s) need not close) and its limit for
    s -> 0+ is taken by Richardson extrapolation of the projectors:
    ``P0 = 2 P(eps/2) - P(eps)``, keeping as many wrenches as the limb has at
    ``q(eps)``.

    Args:
        conf: the closed configuration.
        rtol: relative tolerance of every rank decision.
        approach: joint-space direction (nv,) or joint values by name; default
            (None or an empty mapping): the named configuration's declared
            ``approach``, else the direction from q toward the mechanism's
            ``generic`` configuration (``pin.difference(model, q, q_generic)``).
        eps: step along the approach direction (the direction is normalised in dimensionless rates: slides per L).

    Raises:
        ConfigurationError: the approach direction is invalid, or none is available where one is needed.
    """
    if not (np.isfinite(eps) and eps > 0):
        raise ConfigurationError(f"eps must be a positive step, got {eps!r}")
    mech = conf.mechanism
    configuration = conf.name
    if isinstance(approach, Mapping) and not approach:
        approach = None
    if approach is None and configuration is not None and configuration in mech.configurations:
        approach = mech.configurations[configuration].approach or None
    given = approach is not None  # by the caller or declared by the configuration
    model = mech.model
    length = mech.length_scale
    here = limb_wrenches(conf, rtol)
    if all(rank >= generic for (_, rank), generic in zip(here, generic_twist_ranks(mech))):
        # no limb is serially singular: its generic wrenches are its wrenches here
        return mobility_from_wrenches(conf, here, rtol, View.PAPER)
    q = conf.q
    if approach is None and configuration != GENERIC and GENERIC in mech.configurations:
        approach = pin.difference(model, q, closed_configuration(mech, GENERIC, conf.closure_tol))
    dv = np.zeros(0) if approach is None else _direction(mech, approach)
    norm = float(np.linalg.norm(dv / rate_scale(mech))) if dv.size else 0.0  # dimensionless: slides per L
    if given and norm == 0.0:
        raise ConfigurationError("the approach direction is zero; give a non-zero joint-space direction")
    if norm == 0.0:
        declared_in = [name for name, c in mech.configurations.items() if c.approach]
        where = f"configuration {configuration!r}" if configuration else "this configuration"
        raise ConfigurationError(
            f"the paper's view needs an approach direction and {where} of {mech.name!r} has none (no declared "
            f"'approach' and no distinct '{GENERIC}' configuration to come from): add "
            f"'approach = {{ <joint> = <rate>, ... }}' to [configurations.<name>] in the mechanism file (in Python: "
            f"pinmob.paper_view(..., approach=...)); configurations of {mech.name!r} that declare one: {choices(declared_in)}"
        )
    dv /= norm
    sw = wrench_scaling(length)[:, None]

    def limb_spaces(s: float) -> list[tuple[Array, int]]:
        moved = Configuration.unchecked(mech, pin.integrate(model, q, s * dv))
        out = []
        for twists in limb_twists(moved, rtol):
            w, dec = reciprocal_wrenches(twists, length, rtol)
            out.append((sw * w, dec.rank))
        return out

    at_eps, at_half = limb_spaces(eps), limb_spaces(eps / 2)
    rows = []
    for (w1, r1), (w2, _) in zip(at_eps, at_half):
        k = w1.shape[1]
        proj = 2 * w2 @ w2.T - w1 @ w1.T
        vals, vecs = np.linalg.eigh(0.5 * (proj + proj.T))
        basis = vecs[:, np.argsort(vals)[::-1][:k]]
        rows.append((basis / sw, r1))
    return mobility_from_wrenches(conf, rows, rtol, View.PAPER)
