"""Relaxing over-constraining closures: which cannot close, and a closable copy of the mechanism.

A ``6d`` weld (or another lower closure) on a loop whose joints cannot bring
its two frames to the same pose never closes. :func:`unclosable` finds such
closures, :func:`relax` turns named closures into ``3d`` ones (the frames'
origins meet, orientation free) and :func:`find_closed_relaxed` does both only
where the mechanism cannot be closed as declared, saying what it changed.
"""

from __future__ import annotations

from dataclasses import replace

from pinmob.assembly.assemble import Assembly
from pinmob.assembly.closure_miss import format_worst
from pinmob.assembly.residual import CLOSURE_TOL, worst_residual
from pinmob.assembly.seeds import RESTARTS, find_closed
from pinmob.exceptions import ClosureError, ConfigurationError
from pinmob.model import ClosureType, Mechanism
from pinmob.name_matching import choices
from pinmob.progress import step


def unclosable(mech: Mechanism, restarts: int = 4, seed: int = 0, tol: float = CLOSURE_TOL) -> tuple[str, ...]:
    """Names of the closures of ``mech.closures`` that cannot be closed (within ``tol``) even on their own.

    Each closure alone (no limb, no other closure) is projected from the
    neutral configuration and ``restarts`` random seeds. A closure that never
    closes over-constrains its loop's joints: e.g. a ``6d`` weld on a loop
    whose joints cannot bring the two frames to the same orientation.
    """
    out = []
    with step(f"testing each closure of {mech.name} alone", total=len(mech.closures)) as bar:
        for c in mech.closures:
            bar.set_postfix_str(c.name)
            alone = replace(mech, limbs=(), platform="", closures=(c,))
            try:
                find_closed(alone, restarts=restarts, seed=seed, tol=tol)
            except ClosureError:
                out.append(c.name)
            bar.update()
    return tuple(out)


def relaxable(mech: Mechanism) -> tuple[str, ...]:
    """Names of the closures :func:`relax` can change: those between two frames that are not ``3d`` already."""
    return tuple(c.name for c in mech.closures if c.type != ClosureType.BALL and not c.is_coupling)


def relax(mech: Mechanism, names: tuple[str, ...] | list[str]) -> Mechanism:
    """A copy of ``mech`` whose named closures become ``3d`` (the frames' origins meet; orientation is free)."""
    known = {c.name for c in mech.closures}
    for n in names:
        if n not in known:
            raise ConfigurationError(f"no closure {n!r} in {mech.name!r}; valid: {choices(known)}")
    closures = tuple(
        replace(c, type=ClosureType.BALL, axis=None, axis_b=None) if c.name in names and not c.is_coupling else c
        for c in mech.closures
    )
    return replace(
        mech,
        closures=closures,
        description=(mech.description + f" [closures relaxed to 3d: {', '.join(names)}]").strip(),
    )


def find_closed_relaxed(
    mech: Mechanism, restarts: int = RESTARTS, seed: int = 0, relax_restarts: int = 0, tol: float = CLOSURE_TOL
) -> tuple[Mechanism, Assembly, tuple[str, ...]]:
    """Close ``mech``, relaxing over-constraining closures to ``3d`` only where it cannot be closed as declared.

    First :func:`find_closed` as declared; if that fails, relax the closures
    that cannot close on their own (:func:`unclosable`), then, while it still
    fails, the non-3d closure with the largest residual at the best attempt.
    Returns the (possibly relaxed) mechanism, the assembly and the relaxed
    closure names, so that a report can say exactly what was changed. ``tol``: the closure tolerance.
    """
    try:
        return mech, find_closed(mech, restarts=restarts, seed=seed, tol=tol), ()
    except ClosureError:
        if not relaxable(mech):
            raise  # nothing to relax: the failure as declared
    names = list(unclosable(mech, seed=seed, tol=tol))
    with step(f"relaxing closures of {mech.name} to 3d") as bar:
        while True:
            bar.set_postfix_str(f"relaxed: {', '.join(names) or 'none'}")
            current = relax(mech, names)
            try:
                return current, find_closed(current, restarts=relax_restarts, seed=seed, tol=tol), tuple(names)
            except ClosureError as exc:
                left = set(relaxable(current))
                worst = [(worst_residual({n: r}, mech.length_scale), n) for n, r in exc.residuals.items() if n in left]
                if not worst:
                    break
                names.append(max(worst)[1])
            bar.update()
    try:  # every closure that could be relaxed is: the whole search once more before refusing
        return current, find_closed(current, restarts=restarts, seed=seed, tol=tol), tuple(names)
    except ClosureError as exc:
        raise ClosureError(
            f"{mech.name!r} could not be closed even with closures {', '.join(names)} relaxed to 3d, from the neutral "
            f"configuration nor {restarts} random restarts; best attempt's residuals "
            f"{format_worst(exc.residuals, mech.length_scale, tol)}",
            exc.residuals,
        ) from None
