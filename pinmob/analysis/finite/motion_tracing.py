"""How far each instantaneous motion can be followed: the tracing that confirms a finite-mobility verdict.

:func:`trace_motion` follows a platform motion with the viewer's path follower
(:func:`pinmob.analysis.follow.motion_path.follow_motion`), :func:`trace_rates` joint rates (internal motions,
motions with joints held) with :func:`pinmob.analysis.follow.motion_path.follow_rates`, each from the analysed
Configuration (closed, its closure tolerance checked where it was made: not checked again); each returns the
farthest distance reached either way (0: it could not move at all), which
:func:`pinmob.analysis.finite.verdicts.judge` and :func:`~pinmob.analysis.finite.verdicts.settle` weigh.
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin

from pinmob.analysis.chain.closed_chain import frame_rows
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.follow.displacement import displacement
from pinmob.analysis.follow.motion_path import follow_motion, follow_rates
from pinmob.analysis.motion import Motion
from pinmob.assembly import compute_kinematics
from pinmob.screw import Array, MotionKind, twist_scaling

#: Distance each motion is traced: a fraction of L for translations, radians otherwise, joint metric for joints.
TRACE = 0.05
#: Halvings of a failed tracing step (the first step is TRACE / 2; the smallest tried TRACE / 2 / 2^HALVINGS).
HALVINGS = 2


def trace_motion(conf: Configuration, motion: Motion, rtol: float) -> float:
    """Distance the platform motion was followed (either way; m for a translation, rad otherwise)."""
    mech = conf.mechanism
    amp = TRACE * mech.length_scale if motion.kind is MotionKind.TRANSLATION else TRACE
    path = follow_motion(
        mech,
        conf,  # closed, its closure_tol checked: not checked again
        motion,
        amplitude=amp,
        steps=2,
        rtol=rtol,
        halvings=HALVINGS,
        either=True,  # the farthest reach is all that is used
    )
    return max(path.reached)


def trace_rates(
    conf: Configuration, rates: Array, held: tuple[int, ...], rtol: float, twist: Array | None = None
) -> float:
    """Distance the rates were followed (joint metric), with ``twist`` only as far as the platform follows it.

    With ``twist`` (a dimensionless platform twist), a direction whose end leaves the platform short of
    half the first-order prediction along ``twist`` counts as not followed (it moved internal joints only).
    """
    mech = conf.mechanism
    path = follow_rates(
        mech,
        conf,  # closed, its closure_tol checked: not checked again
        rates,
        amplitude=TRACE,
        steps=2,
        held=held,
        rtol=rtol,
        halvings=HALVINGS,
        either=True,  # the farthest reach and its end are all that is used
    )
    reached = max(path.reached)
    if twist is None or reached == 0.0:
        return reached
    sign, end = (1.0, path.forward[-1]) if path.reached[0] >= path.reached[1] else (-1.0, path.backward[-1])
    data = pin.Data(mech.model)
    compute_kinematics(mech.model, data, end)
    moved = twist_scaling(mech.length_scale) * displacement(
        conf.frame_placement(mech.platform_id), data.oMf[mech.platform_id]
    )
    predicted = sign * reached * (frame_rows(conf, mech.platform) @ rates) / np.linalg.norm(rates)
    unit = twist / np.linalg.norm(twist)
    along = predicted @ unit  # the end reached backwards lies along -twist: compare along the prediction's side
    return reached if np.sign(along) * (moved @ unit) >= 0.5 * abs(along) > 0 else 0.0
