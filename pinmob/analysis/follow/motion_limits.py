"""What stops a followed motion: a limb reaching the edge of its workspace (a serial singularity).

A limb at a serial (Type I) singularity -- stretched or folded, its joint
screws dependent -- is at the edge of its workspace: the platform cannot go
further in the direction that would need the limb to reach beyond it. When
:func:`pinmob.analysis.follow.motion_path.follow_motion` cannot take another step,
:func:`limiting_limbs` asks whether a limb is there.

Each limb's distance to its serial singularity is ``d = sigma_r / sigma_1`` of
its dimensionless joint screws, ``r`` its generic twist rank
(:mod:`pinmob.analysis.singularity.result`). Near a fold of the limb's reach, ``d^2``
falls linearly with the distance ``s`` travelled along the motion, so from the
last two configurations of a path (``s_1 < s_2``, ``d_1 > d_2``) the limb becomes
singular at about

    s* = s_2 + d_2^2 (s_2 - s_1) / (d_1^2 - d_2^2).

A limb *limits* the motion when ``s*`` lies within the step the follower could
not take; a path that could not move at all is limited by the limbs already at
a serial singularity there (``d <= rtol``).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from pinmob.analysis.configuration import Configuration
from pinmob.analysis.generic import generic_twist_ranks
from pinmob.analysis.limbs import limb_decisions, limb_twists, limbwise_obstacle
from pinmob.analysis.singularity.result import distance_of
from pinmob.model import Mechanism
from pinmob.screw import Array


@dataclass(frozen=True)
class LimbLimit:
    """A limb that reaches a serial singularity where a followed motion stops.

    Attributes:
        limb: the limb's name.
        distance: its distance to the serial singularity at the last configuration reached.
        ahead: how much further along the motion it becomes singular [m or rad] (0: already there).
    """

    limb: str
    distance: float
    ahead: float


def limb_distances(mech: Mechanism, q: Array, rtol: float) -> dict[str, float]:
    """Each limb's distance to its serial singularity at the closed configuration q (see the module)."""
    conf = Configuration.unchecked(mech, q)
    decisions = limb_decisions(mech, limb_twists(conf, rtol), rtol)
    ranks = generic_twist_ranks(mech)
    return {limb.name: distance_of(d.singular_values, r) for limb, d, r in zip(mech.limbs, decisions, ranks)}


def limiting_limbs(
    mech: Mechanism, path: Sequence[Array], covered: Sequence[float], step: float, rtol: float
) -> tuple[LimbLimit, ...]:
    """The limbs whose serial singularity stops a motion followed along ``path``, nearest first.

    Args:
        mech: the mechanism.
        path: the closed configurations reached, the start first.
        covered: (len(path),) distance travelled along the motion at each [m or rad].
        step: the step that could not be taken [m or rad].
        rtol: relative tolerance of the rank decisions.

    Returns:
        the limiting limbs (empty when the limb-wise analysis does not apply, or no limb is near
        its serial singularity there).
    """
    if limbwise_obstacle(mech):
        return ()
    last = limb_distances(mech, path[-1], rtol)
    if len(path) < 2:
        return tuple(LimbLimit(name, d, 0.0) for name, d in last.items() if d <= rtol)
    before = limb_distances(mech, path[-2], rtol)
    travelled = float(covered[-1] - covered[-2])
    out = []
    for name, d2 in last.items():
        d1 = before[name]
        if d2 <= rtol:
            out.append(LimbLimit(name, d2, 0.0))
        elif d1 > d2 and travelled > 0:
            ahead = d2**2 * travelled / (d1**2 - d2**2)
            if ahead <= step:
                out.append(LimbLimit(name, d2, float(ahead)))
    return tuple(sorted(out, key=lambda limit: limit.ahead))


def describe(limits: Sequence[LimbLimit], unit: str) -> str:
    """The reason in words: which limbs reach the edge of their workspace, and how far ahead ("" when none)."""
    if not limits:
        return ""
    names = ", ".join(limit.limb for limit in limits)
    several = len(limits) > 1
    subject = f"limb{'s' if several else ''} {names}"
    edge = f"the edge of {'their' if several else 'its'} workspace (a serial singularity: stretched or folded)"
    if all(limit.ahead == 0.0 for limit in limits):
        return f"{subject} {'are' if several else 'is'} already at {edge}"
    return f"{subject} reach{'' if several else 'es'} {edge} about {limits[0].ahead:.2g} {unit} further"
