"""Families of built-in models: a design function of named dimensions, for design-space sweeps (``pinmob sweep``).

Each :class:`Family` builds, from its parameters (a value per name, the
defaults being those of the built-in model), the same
:data:`~pinmob.catalog.registry.Definition` as the catalogue's entry: the
builder, the named configurations and the length scale.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from pinmob.exceptions import ConfigurationError
from pinmob.name_matching import choices

from .delta import delta_3ruu_design
from .puu import three_puu_design
from .registry import Definition


@dataclass(frozen=True)
class Parameter:
    """One design parameter of a family: name, default value, unit and meaning."""

    name: str
    default: float
    unit: str
    doc: str


@dataclass(frozen=True)
class Family:
    """A family of mechanisms: a name, its parameters and the function building one member."""

    name: str
    description: str
    parameters: tuple[Parameter, ...]
    design: Callable[..., Definition]

    def names(self) -> tuple[str, ...]:
        """The parameter names, in order."""
        return tuple(p.name for p in self.parameters)

    def units(self) -> dict[str, str]:
        """Unit of each parameter."""
        return {p.name: p.unit for p in self.parameters}

    def build(self, values: dict[str, float]) -> Definition:
        """The member with these parameter values (the others at their defaults).

        Raises:
            ConfigurationError: an unknown parameter (the message lists the valid ones), or values the design refuses.
        """
        unknown = sorted(set(values) - set(self.names()))
        if unknown:
            raise ConfigurationError(
                f"family {self.name!r} has no parameter {unknown[0]!r}; valid: {choices(self.names())}"
            )
        full: dict[str, Any] = {p.name: p.default for p in self.parameters} | {k: float(v) for k, v in values.items()}
        return self.design(**full)


FAMILIES: dict[str, Family] = {
    f.name: f
    for f in (
        Family(
            "3-PUU",
            "the seed paper's 3-PUU (model 3-PUU): vertical guides, U-U links, platform below the sliders",
            (
                Parameter("big_r", 0.3, "m", "radius of the circle of the slider guides, R"),
                Parameter("small_r", 0.15, "m", "platform circumradius, r"),
                Parameter("link", 0.25, "m", "link length between the two U joints (longer than |R - r|)"),
                Parameter("stroke", 1.0, "m", "slider travel each way from the reference"),
            ),
            three_puu_design,
        ),
        Family(
            "Delta-3RUU",
            "the Delta with U-U rods (model Delta-3RUU)",
            (
                Parameter("base_r", 0.2, "m", "radius of the circle of the actuated revolutes, R"),
                Parameter("plat_r", 0.05, "m", "platform circumradius, r"),
                Parameter("arm", 0.25, "m", "arm length"),
                Parameter("rod", 0.3, "m", "rod length"),
                Parameter("arm_angle", float(np.pi / 3), "rad", "arm angle below the horizontal at the reference"),
            ),
            delta_3ruu_design,
        ),
    )
}


def family(name: str) -> Family:
    """The family of that name.

    Raises:
        ConfigurationError: no such family (the message lists them).
    """
    if name not in FAMILIES:
        raise ConfigurationError(f"unknown family {name!r}; valid: {choices(FAMILIES)}")
    return FAMILIES[name]
