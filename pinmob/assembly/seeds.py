"""Several seeds: a closed configuration from random restarts.

:func:`find_closed` projects the neutral configuration, then seeded random
ones, until one closes (the distinct assembly modes are found by
:func:`pinmob.analysis.modes.assembly_modes`).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pinocchio as pin

from pinmob.assembly.assemble import Assembly, project
from pinmob.assembly.residual import CLOSURE_TOL, worst_residual
from pinmob.exceptions import ArgumentError, ClosureError
from pinmob.model import Mechanism, linear_velocity_mask
from pinmob.progress import step
from pinmob.screw import Array

RESTARTS = 20
"""Random restarts of a search for a closed configuration, by default (the command line's default too)."""


def random_configuration(mech: Mechanism, rng: np.random.Generator, spread: float = np.pi) -> Array:
    """A seed: neutral moved by uniform random joint velocities in [-spread, spread] (lengths times L / pi)."""
    lin = linear_velocity_mask(mech.model)
    dv = rng.uniform(-spread, spread, mech.model.nv) * np.where(lin, mech.length_scale / np.pi, 1.0)
    return pin.integrate(mech.model, mech.neutral(), dv)


def find_closed(
    mech: Mechanism, q0: Array | None = None, restarts: int = RESTARTS, seed: int = 0, tol: float = CLOSURE_TOL
) -> Assembly:
    """A closed configuration: projection from q0 (default neutral), then from seeded random restarts.

    Returns the first that closes to the default tolerance (``min(tol, CLOSURE_TOL)``); when none does, the
    first that closes within ``tol`` (a looser tolerance accepts loops that close only to CAD accuracy; the
    first, not the smallest residual, so that round-off does not choose among equal misses). Its
    ``method`` says which: ``neutral`` or
    ``given`` (closed as it is), ``projection from neutral`` (or ``given``), or ``projection from random
    restart k (seed s)``.

    Raises:
        ClosureError: nothing closed; carries the residuals of the best attempt
            (smallest :func:`worst_residual`).
        ArgumentError: restarts is negative.
    """
    if restarts < 0:
        raise ArgumentError(
            f"the number of random restarts (restarts) must be at least 0, got {restarts}", "restarts", restarts
        )
    rng = np.random.default_rng(seed)
    best: ClosureError | None = None
    loose: Assembly | None = None  # the first attempt within tol, not within the default tolerance
    length, strict = mech.length_scale, min(tol, CLOSURE_TOL)
    with step(f"closing the loops of {mech.name} (restarts)", total=restarts + 1) as bar:
        for k in range(restarts + 1):
            if k == 0:
                q_start, label = (mech.neutral(), "neutral") if q0 is None else (q0, "given")
            else:
                q_start, label = random_configuration(mech, rng), f"random restart {k} (seed {seed})"
            try:
                found = project(mech, q_start, tol=tol, method=f"projection from {label}")
                found = found if found.iterations else replace(found, method=label)
                if found.residual <= strict:
                    return found
                loose = found if loose is None else loose
            except ClosureError as exc:
                if best is None or worst_residual(exc.residuals, length) < worst_residual(best.residuals, length):
                    best = exc
            bar.update()
    if loose is not None:
        return loose
    assert best is not None  # restarts >= 0: at least one attempt
    raise ClosureError(
        f"no closed configuration of {mech.name!r} found from the neutral configuration and {restarts} random restarts; best: {best}",
        best.residuals,
    )


def configuration_distance(mech: Mechanism, q1: Array, q2: Array) -> float:
    """Largest joint difference between two configurations [rad, or m / L]; revolute angles modulo 2 pi."""
    d = pin.difference(mech.model, q1, q2)
    lin = linear_velocity_mask(mech.model)
    d = np.where(lin, d / mech.length_scale, np.angle(np.exp(1j * d)))
    return float(np.max(np.abs(d))) if d.size else 0.0
