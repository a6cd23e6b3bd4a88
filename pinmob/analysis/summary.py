"""The one-line answer (``pinmob analyze --brief``, :meth:`pinmob.analysis.report.Report.brief`)."""

from __future__ import annotations

import numpy as np

from pinmob.analysis.chain.mechanism_mobility import MechanismMobility
from pinmob.analysis.mobility import Mobility
from pinmob.analysis.motion import KIND_WORDS, Motion, numbers
from pinmob.analysis.singularity.result import Singularity
from pinmob.screw import Array, MotionKind


def _vector(a: Array, digits: int) -> str:
    return numbers(a, digits).replace(" ", "").replace(",", ", ")


def motion_words(motion: Motion, origin: Array, length: float) -> str:
    """``T1 z translation along [0, 0, 1]``, ``R1 z rotation about [0, 0, 1] through [0, 0, 0] m`` (world), ...

    Args:
        motion: the motion.
        origin: (3,) world position [m] of the origin its axis point is relative to.
        length: the mechanism's length scale L [m].
    """
    d = _vector(motion.direction, 3)
    if motion.kind is MotionKind.TRANSLATION:
        return f"{motion.label} translation along {d}"
    point = motion.world_point(origin, length)
    p = _vector(point if point is not None else np.zeros(3), 4)
    text = f"{motion.label} {KIND_WORDS[motion.kind]} about {d} through {p} m"
    return text + (f", pitch {motion.pitch:.3g} m/rad" if motion.kind is MotionKind.SCREW else "")


def summary_line(
    mechanism: str,
    configuration: str | None,
    mobility: Mobility | None,
    singularity: Singularity | None,
    chain: MechanismMobility | None,
) -> str:
    """One line: the platform's DoF, motion type and motions (world axis points) and the singularity class.

    A configuration with no class present but within the near-singular band says so as the full text does:
    ``singularity: none, near-singular (below 1e-03; distance 6.32e-05, closest: actuation)``.

    Without a platform frame (``mobility`` None): the mechanism DoF and each output frame's DoF and
    motion type, from ``chain``.
    """
    where = f"{mechanism}" + (f" at {configuration!r}" if configuration else "")
    if mobility is None:
        if chain is None:
            return f"{where}: no platform frame"
        frames = "; ".join(f"frame {f.frame!r}: {f.dof} DoF, {f.motion_type}" for f in chain.frames)
        return f"{where}: mechanism DoF {chain.mechanism_dof}" + (f"; {frames}" if frames else "")
    motions = "; ".join(motion_words(m, mobility.platform_origin, mobility.length_scale) for m in mobility.motions)
    centre = mobility.rotation_centre
    if centre is not None:
        motions += f"; the rotation axes meet at {_vector(centre, 4)} m"
    text = f"{where}: {mobility.dof} DoF, {mobility.motion_type}" + (f" ({motions})" if motions else "")
    if singularity is not None:
        text += f"; singularity: {singularity.label}"
        if singularity.near_singular:  # as the full text: none present, but within the band
            closest = ", ".join(singularity.closest_all)
            text += f", near-singular (below {singularity.near_band:.0e}; distance {singularity.distance:.3g}, closest: {closest})"
    return text
