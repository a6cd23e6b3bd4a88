"""Singularities at a configuration, in the classes of Zlatanov, Bonev and Gosselin (2002).

With ``T_i`` (6, n_i) the joint screws of limb i at the platform origin and
``W_i`` (6, 6 - rank T_i) the wrenches reciprocal to them (see
:mod:`pinmob.analysis.mobility`), three questions are asked, each on dimensionless
matrices (``[v / L; w]`` for twists, ``[f L; tau]`` for wrenches):

* **limb (Type I, serial) singularity**: ``rank U_i`` is below the limb's
  generic twist rank, ``U_i`` being the dimensionless joint screws with each
  column scaled to unit length (so that neither the unit of length nor the
  unit of a joint's rate, rad/s or m/s or mm/s, matters). The joints taking
  part are those with a coefficient above ``sqrt(rtol)`` in a unit vector of
  ``null(U_i)``.
* **constraint singularity**: ``d = rank [W_1 ... W_k]`` is below the
  mechanism's generic constraint rank ``g`` (declared as ``generic_rank`` in
  the mechanism file, else estimated from random closed configurations): the
  platform gains freedom. The *dependent limbs* are the limbs of the minimal
  sets S of limbs whose own stacked wrenches lost rank: ``rank [W_i, i in S]``
  below its value at generic configurations (:func:`dependent_limbs`).
* **actuation (Type II, parallel) singularity**: with the actuated joints
  locked, limb i keeps the screws ``T_i^u`` of its unactuated joints and is
  reciprocal to ``W_i^u = null((T_i^u)^T)``, which holds ``W_i`` plus one
  actuation wrench per actuated joint. The platform keeps
  ``locked_dof = 6 - rank [W_1^u ... W_k^u]`` free motions, the *uncontrolled*
  twists. A configuration is actuation-singular when ``locked_dof`` exceeds its
  generic value ``max(0, 6 - g - n_actuated)``. Without any actuated joint the
  question does not apply (``actuation`` None, no uncontrolled motion).

Distance to singularity (dimensionless, in [0, 1], unit-invariant): for each
question, ``sigma_r / sigma_1`` of the very matrix whose rank is decided, ``r``
being its generic rank: the stacked limb wrenches (r = g), the stacked
locked-limb wrenches (r = 6 - generic locked dof) and each limb's ``U_i`` (its
generic twist rank). Ranks count the singular values above ``rtol * sigma_1``,
so each class is present exactly when its distance is at most ``rtol``. A
configuration with no class present but a distance below ``NEAR_FACTOR * rtol``
is *near-singular*.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pinmob.analysis.motion import Motion
from pinmob.frozen import ReadOnlyArrays
from pinmob.model import Mechanism
from pinmob.screw import RTOL, Array

#: Near-singular band: no class present but ``distance < NEAR_FACTOR * rtol``.
NEAR_FACTOR = 1e3
#: A distance ties the smallest within this fraction of it plus this much: the round-off of the dimensionless
#: singular values (two tests both singular at a configuration give ~1e-15 each, in an order round-off decides).
TIE_RTOL, TIE_ATOL = 1e-6, 1e-13


def tied(distances: Any, smallest: Any) -> Any:
    """Where ``distances`` tie ``smallest`` within round-off (:data:`TIE_RTOL`, :data:`TIE_ATOL`); numbers or arrays."""
    return distances <= smallest * (1 + TIE_RTOL) + TIE_ATOL


@dataclass(frozen=True)
class Singularity(ReadOnlyArrays):
    """Singularity classes and distances at one closed configuration.

    Attributes:
        mechanism, configuration: names (configuration may be None).
        constraint: constraint singularity (constraint rank below ``generic_rank``).
        actuation: actuation (Type II) singularity; None when no joint is actuated.
        limbs: names of the serially singular (Type I) limbs.
        limb_joints: per serially singular limb, the joints taking part.
        dependent_limbs: limbs of the minimal limb sets whose wrenches lost rank (constraint singularity only).
        constraint_rank, generic_rank: d here and at generic configurations.
        locked_dof: platform DoF with the actuated joints locked (the DoF when none is actuated).
        generic_locked_dof: its generic value ``max(0, 6 - generic_rank - n_actuated)``.
        uncontrolled: canonical uncontrolled motions (free motions with actuators locked; empty without actuators).
        uncontrolled_twists: (6, len(uncontrolled)) their unit twists ``[v; w]``.
        actuation_wrenches: (6, m) the actuation wrenches ``[f; tau]`` [N, N m per unit] found.
        distance: smallest of ``distances`` (dimensionless, [0, 1]).
        distances: per question (``constraint``, ``actuation``, ``limb <name>``), ``sigma_r / sigma_1``.
        limb_ranks, generic_limb_ranks: twist rank of each limb here and at generic configurations.
        constraint_singular_values: (6,) of the stacked dimensionless limb wrenches (NaN where absent).
        actuation_singular_values: (6,) of the stacked dimensionless locked-limb wrenches (NaN where absent).
        rtol: relative tolerance of the rank decisions.
    """

    mechanism: str
    configuration: str | None
    constraint: bool
    actuation: bool | None
    limbs: tuple[str, ...]
    limb_joints: dict[str, tuple[str, ...]]
    dependent_limbs: tuple[str, ...]
    constraint_rank: int
    generic_rank: int
    locked_dof: int
    generic_locked_dof: int
    uncontrolled: tuple[Motion, ...]
    uncontrolled_twists: Array = field(repr=False)
    actuation_wrenches: Array = field(repr=False)
    distance: float = 1.0
    distances: dict[str, float] = field(default_factory=dict)
    limb_ranks: dict[str, int] = field(default_factory=dict)
    generic_limb_ranks: dict[str, int] = field(default_factory=dict)
    constraint_singular_values: Array = field(default_factory=lambda: np.full(6, np.nan), repr=False)
    actuation_singular_values: Array = field(default_factory=lambda: np.full(6, np.nan), repr=False)
    rtol: float = RTOL

    @property
    def classes(self) -> tuple[str, ...]:
        """Names of the singularity classes present: ``constraint``, ``actuation``, ``limb``."""
        out = ["constraint"] if self.constraint else []
        out += ["actuation"] if self.actuation else []
        out += ["limb"] if self.limbs else []
        return tuple(out)

    @property
    def label(self) -> str:
        """``none`` or the classes joined by ``+``, e.g. ``actuation+limb``."""
        return "+".join(self.classes) or "none"

    @property
    def near_singular(self) -> bool:
        """No class present, but ``distance < NEAR_FACTOR * rtol``."""
        return not self.classes and self.distance < self.near_band

    @property
    def closest(self) -> str:
        """The question with the smallest distance (``constraint``, ``actuation`` or ``limb <name>``)."""
        return min(self.distances, key=self.distances.__getitem__) if self.distances else ""

    @property
    def closest_all(self) -> tuple[str, ...]:
        """Every question whose distance ties the smallest (within round-off): the text's ``closest:``."""
        return tuple(k for k, v in self.distances.items() if tied(v, self.distance))

    @property
    def near_band(self) -> float:
        """``NEAR_FACTOR * rtol``: below this distance, a configuration with no class present is near-singular."""
        return NEAR_FACTOR * self.rtol

    @property
    def rank_gap(self) -> dict[str, int]:
        """Rank lost per question (``constraint``, ``actuation``, ``limb <name>``): generic minus here, at least 0."""
        gap = {
            "constraint": max(0, self.generic_rank - self.constraint_rank),
            "actuation": max(0, self.locked_dof - self.generic_locked_dof),
        }
        for name, rank in self.limb_ranks.items():
            gap[f"limb {name}"] = max(0, self.generic_limb_ranks[name] - rank)
        return gap

    def to_dict(self) -> dict[str, Any]:
        """The ``singularity`` entry of ``pinmob analyze --json``."""
        return {
            "constraint": self.constraint,
            "actuation": self.actuation,
            "limbs": list(self.limbs),
            "locked_dof": self.locked_dof,
            "uncontrolled": [m.to_dict() for m in self.uncontrolled],
            "distance": self.distance,
            "generic_rank": self.generic_rank,
            "classes": list(self.classes),
            "near_singular": self.near_singular,
            "limb_joints": {k: list(v) for k, v in self.limb_joints.items()},
            "dependent_limbs": list(self.dependent_limbs),
            "rank_gap": self.rank_gap,
            "distances": dict(self.distances),
        }

    def __str__(self) -> str:
        """The singularity section of the text report."""
        near = f"; near-singular (below {self.near_band:.0e})" if self.near_singular else ""
        ties = self.closest_all
        closest = f", closest: {', '.join(ties)}" if ties else ""
        lines = [
            f"singularity: {self.label} (distance {self._shown(self.distance)}{closest}; 0 = singular, 1 = best "
            f"conditioned{near})"
        ]
        gap = self.rank_gap
        lines.append(
            f"  constraint: {'SINGULAR' if self.constraint else 'no'} (rank {self.constraint_rank}, generic {self.generic_rank}"
            + (
                f", lost {gap['constraint']}; dependent limbs {', '.join(self.dependent_limbs) or '-'}"
                if self.constraint
                else ""
            )
            + ")"
        )
        if self.actuation is None:
            lines.append("  actuation (Type II): not applicable (no actuated joint declared)")
        else:
            unc = ", ".join(m.label for m in self.uncontrolled) or "none"
            lines.append(
                f"  actuation (Type II): {'SINGULAR' if self.actuation else 'no'} (actuators locked: {self.locked_dof} DoF "
                f"left, generic {self.generic_locked_dof}; uncontrolled: {unc})"
            )
        if self.limbs:
            for name in self.limbs:
                lines.append(
                    f"  limb (Type I): {name} SINGULAR (rank {self.limb_ranks[name]}, generic "
                    f"{self.generic_limb_ranks[name]}; joints {', '.join(self.limb_joints[name])})"
                )
        else:
            lines.append("  limb (Type I): no")
        lines.append("  distances: " + ", ".join(f"{k} {self._shown(v)}" for k, v in self.distances.items()))
        return "\n".join(lines)

    def _shown(self, distance: float) -> str:
        """A distance as printed: ``<= rtol`` at a singularity, where the figure is round-off (the JSON keeps it)."""
        return f"<= {self.rtol:g}" if distance <= self.rtol else f"{distance:.3g}"


# --------------------------------------------------------------------------- helpers


def ratio(singular_values: NDArray[np.floating], rank: int) -> Array:
    """``sigma_rank / sigma_1`` (1-based) of each row of (N, m) singular values; 1 when rank is 0, 0 when m < rank."""
    s = np.atleast_2d(np.asarray(singular_values, float))
    if rank <= 0:
        return np.ones(s.shape[0])
    if s.shape[1] < rank:
        return np.zeros(s.shape[0])
    top = s[:, 0]
    return np.where(top > 0, s[:, rank - 1] / np.where(top > 0, top, 1.0), 0.0)


def distance_of(singular_values: ArrayLike, rank: int) -> float:
    """``sigma_rank / sigma_1`` of one set of singular values (see :func:`ratio`, the same for rows of them)."""
    s = np.asarray(singular_values, float)
    if rank <= 0:
        return 1.0
    if s.size < rank:
        return 0.0
    top = float(s[0])
    return float(s[rank - 1]) / top if top > 0 else 0.0


def padded(values: Array) -> Array:
    """The first six values, NaN-padded to (6,)."""
    out = np.full(6, np.nan)
    out[: min(6, values.size)] = values[:6]
    return out


def generic_locked_dof(mech: Mechanism, generic_rank: int) -> int:
    """Platform DoF with the actuators locked at a generic configuration: ``max(0, 6 - g - n_actuated)``."""
    return max(0, 6 - generic_rank - len(mech.actuated))
