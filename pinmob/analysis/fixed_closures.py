"""The mechanism with its minimal closures (:mod:`pinmob.analysis.minimal`), and its check at every named configuration.

:func:`fix_closures` replaces each closure the proposal changes: a declared closure takes the proposed type and
axes (or goes, when every equation of it is implied); a limb whose tip weld to the platform loses equations
becomes a closure ``limb_<name>`` between the platform and its tip (its actuated joints stay actuated). The
other limbs, the named configurations and their expected mobilities are kept.

:func:`check_fixed` re-analyses both mechanisms at every named configuration (or the default one) and lists
what differs: the configuration found, the mechanism DoF, the idle motions, the platform's (or output frames')
motion type, and the redundant equations left.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from numpy.typing import ArrayLike

from pinmob.analysis.configuration import Configuration
from pinmob.analysis.entry_point import analyze
from pinmob.analysis.minimal import MinimalClosures
from pinmob.analysis.report import Report
from pinmob.assembly import CLOSURE_TOL
from pinmob.exceptions import ConfigurationError
from pinmob.model import Closure, Mechanism, NamedConfiguration
from pinmob.screw import RTOL

#: Joint values [rad or m] within which a named configuration counts as the same after the fix.
SAME_Q = 1e-6


def minimal_closures(
    mech: Mechanism | Configuration,
    q: ArrayLike | str | Configuration | None = None,
    *,
    rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL,
) -> MinimalClosures | None:
    """Per closure, the closure with exactly its independent equations at q (``pinmob.analyze(...).minimal_closures``).

    Args: as :func:`pinmob.analyze`'s (q: a configuration, its name, or None for the default one).

    Returns:
        the :class:`~pinmob.analysis.minimal.MinimalClosures`, or None where no closure equation is redundant.
    """
    return analyze(mech, q, rtol=rtol, closure_tol=closure_tol).minimal_closures


def chosen_proposal(
    mech: Mechanism, rtol: float = RTOL, closure_tol: float = CLOSURE_TOL
) -> tuple[str | None, MinimalClosures | None]:
    """The configuration whose proposal fixes the file, and that proposal (None: nothing to fix).

    A proposal holds where it was computed; at a singular configuration more equations are dependent than
    elsewhere (the 3-PUU-vertical's 'vertical'), and dropping them there would free motions at the others.
    So: the named configuration where the closure rank is largest; where some named configuration has no
    redundant equation at all, there is nothing to fix (the redundancy is that of singular configurations).
    Without named configurations, the default one of :func:`pinmob.analyze`.
    """
    best: tuple[str | None, MinimalClosures | None] = (None, None)
    names: list[str | None] = [*mech.configurations] or [None]
    for name in names:
        minimal = minimal_closures(mech, name, rtol=rtol, closure_tol=closure_tol)
        if minimal is None:
            return name, None
        if best[1] is None or minimal.rank > best[1].rank:
            best = (name, minimal)
    return best


def fix_closures(
    mech: Mechanism,
    minimal: MinimalClosures | None = None,
    configuration: str | None = None,
    closure_tol: float = CLOSURE_TOL,
) -> Mechanism:
    """``mech`` with the minimal closures (see the module docstring); ``mech`` itself when nothing is redundant.

    Each named configuration given by a platform pose gets the joint values ``mech`` assembles there as its
    ``seed`` (joints of one coordinate), so that the solver finds the same configuration: the fewer equations
    may also close elsewhere.

    Args:
        mech: the mechanism.
        minimal: the proposal (default: computed at ``configuration``, else at the configuration
            :func:`chosen_proposal` chooses).
        configuration: where to compute it when not given.
        closure_tol: the closure tolerance of the analyses (as :func:`pinmob.analyze`'s).

    Raises:
        ConfigurationError: a closure could not be reduced (none of the vocabulary has exactly its equations).
    """
    if minimal is None:
        minimal = (
            minimal_closures(mech, configuration, closure_tol=closure_tol)
            if configuration
            else chosen_proposal(mech, closure_tol=closure_tol)[1]
        )
    if minimal is None or not minimal.changes:
        return mech
    missing = [c.name for c in minimal.closures if not c.found and c.type not in ("joint", "tendon")]  # couplings kept
    if missing:
        raise ConfigurationError(
            f"no closure of pinmob's vocabulary has exactly the independent equations of {', '.join(missing)}"
        )
    change = {c.name: c for c in minimal.changes}
    limbs, converted, actuated = [], [], {}
    extra = list(mech.extra_actuated)
    for limb in mech.limbs:
        c = change.get(f"limb {limb.name}")
        if c is None:
            limbs.append((limb.name, limb.tip))
            actuated[limb.name] = list(limb.actuated)
            continue
        extra += limb.actuated
        if c.proposed is not None:
            converted.append(replace(c.proposed, name=_free_name(mech, f"limb_{limb.name}")))
    closures: list[Closure] = []
    for closure in mech.closures:
        c = change.get(closure.name)
        if c is None:
            closures.append(closure)
        elif c.proposed is not None:
            closures.append(c.proposed)
    actuated[""] = extra
    fixed = Mechanism.from_model(
        mech.model,
        limbs,
        name=mech.name,
        platform=mech.platform or None,
        actuated=actuated,
        length_scale=mech.length_scale,
        configurations=_seeded(mech, closure_tol),
        expected=mech.expected,
        description=mech.description,
        source=mech.source,
        geometry=mech.geometry,
        generic_rank=mech.generic_rank,
        closures=converted + closures,
    )
    return replace(
        fixed,
        actuated_tendons=mech.actuated_tendons,
        joint_actuators=mech.joint_actuators,
        quaternion_wxyz=mech.quaternion_wxyz,
    )


def _seeded(mech: Mechanism, closure_tol: float) -> dict[str, NamedConfiguration]:
    """``mech``'s named configurations, those given by a pose seeded with the joint values ``mech`` closes there."""
    out = dict(mech.configurations)
    model = mech.model
    for name, conf in mech.configurations.items():
        if conf.pose is None:
            continue
        q = analyze(mech, name, closure_tol=closure_tol).state.q
        seed = {
            model.names[j]: float(q[model.joints[j].idx_q]) for j in range(1, model.njoints) if model.joints[j].nq == 1
        }
        out[name] = replace(conf, seed=seed)
    return out


def _free_name(mech: Mechanism, name: str) -> str:
    taken = {c.name for c in mech.closures}
    out, k = name, 2
    while out in taken:
        out, k = f"{name}_{k}", k + 1
    return out


@dataclass(frozen=True)
class FixCheck:
    """What :func:`check_fixed` compared, per configuration, and what differs.

    Attributes:
        configurations: the configurations compared (``None``: the default one).
        rows: per configuration, (closure equations before, after, redundant after: more than 0 only where the
            mechanism is singular, a configuration other than the one the proposal was computed at).
        differences: one sentence per difference (empty: the same answers everywhere).
    """

    configurations: tuple[str | None, ...]
    rows: tuple[tuple[int, int, int], ...]
    differences: tuple[str, ...]

    @property
    def same(self) -> bool:
        """Nothing differs."""
        return not self.differences

    @property
    def redundant_left(self) -> dict[str | None, int]:
        """The configurations where redundant equations remain (a singular one), with how many."""
        return {n: r[2] for n, r in zip(self.configurations, self.rows) if r[2]}


def _motion_types(report: Report) -> dict[str, str]:
    chain = report.mechanism_mobility
    return {f.frame: f.motion_type for f in chain.frames if f.frame in chain.end_frames}


def check_fixed(
    original: Mechanism, fixed: Mechanism, rtol: float = RTOL, closure_tol: float = CLOSURE_TOL
) -> FixCheck:
    """Analyse both at every named configuration (else the default one) and list what differs (:class:`FixCheck`)."""
    names: list[str | None] = list(original.configurations) or [None]
    rows, differences = [], []
    for name in names:
        before = analyze(original, name, rtol=rtol, closure_tol=closure_tol)
        after = analyze(fixed, name if name else before.state.q, rtol=rtol, closure_tol=closure_tol)  # unnamed: same q
        where = f"at {name!r}" if name else "at the default configuration"
        a, b = before.mechanism_mobility, after.mechanism_mobility
        rows.append((a.rows, b.rows, b.redundant_constraints))
        if not np.allclose(before.state.q, after.state.q, atol=SAME_Q, rtol=0.0):
            differences.append(f"{where}: the configuration found differs")
        for what, x, y in (
            ("mechanism DoF", a.mechanism_dof, b.mechanism_dof),
            ("idle motions", a.idle_dof, b.idle_dof),
            ("motion types", _motion_types(before), _motion_types(after)),
        ):
            if x != y:
                differences.append(f"{where}: {what} {x} before, {y} after")
    return FixCheck(tuple(names), tuple(rows), tuple(differences))
