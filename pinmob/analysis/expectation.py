"""The mechanism file's expected mobility at a configuration (the literature's value), and whether it agrees."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from pinmob.analysis.chain.mechanism_mobility import FrameMobility
from pinmob.analysis.mobility import Mobility
from pinmob.model import Mechanism


@dataclass(frozen=True)
class ExpectationCheck:
    """The mechanism file's expected mobility at the configuration, and whether the analysis agrees."""

    dof: int
    motion_type: str
    source: str
    agrees: bool

    def to_dict(self) -> dict[str, Any]:
        """The ``expected`` entry of the JSON document."""
        return {"dof": self.dof, "motion_type": self.motion_type, "source": self.source, "agrees": self.agrees}

    def __str__(self) -> str:
        src = f" ({self.source})" if self.source else ""
        verdict = "agrees with" if self.agrees else "DIFFERS from"
        return f"expected {self.dof} DoF {self.motion_type}{src}: analysis {verdict} it"


def expectation_check(
    mech: Mechanism, configuration: str | None, found: Mobility | FrameMobility | None
) -> ExpectationCheck | None:
    """The file's expectation at ``configuration`` checked against the platform's ``found`` mobility (None if none).

    Args:
        mech: the mechanism (its ``expected`` table).
        configuration: the configuration's name (None: unnamed, no expectation).
        found: the platform's mobility (limb-wise), or its frame's on the closed chain; None without a platform.
    """
    exp = mech.expected.get(configuration) if configuration is not None else None
    if exp is None:
        return None
    agrees = found is not None and (found.dof, found.motion_type) == (exp.dof, exp.motion_type)
    return ExpectationCheck(exp.dof, exp.motion_type, exp.source, agrees)
