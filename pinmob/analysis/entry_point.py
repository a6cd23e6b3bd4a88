"""The one entry point: :func:`analyze` gives the whole :class:`~pinmob.analysis.report.Report`."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from numpy.typing import ArrayLike

from pinmob.analysis.configuration import Configuration, as_configuration
from pinmob.analysis.configuration_choice import chosen_configuration
from pinmob.analysis.finite.higher_order import ORDER, check_order
from pinmob.analysis.mobility import platform_mobility
from pinmob.analysis.report import Report
from pinmob.analysis.report_parts import Options, part_keywords
from pinmob.assembly import (
    CLOSURE_TOL,
    RESTARTS,
    Residuals,
    check_closure_tol,
    find_closed,
    find_closed_relaxed,
    format_worst,
    named_vector,
    project,
    relaxable,
    tolerance_hint,
    unclosable,
    worst_first,
    worst_residual,
)
from pinmob.bounds import check_bound
from pinmob.exceptions import ArgumentError, ClosureError, ConfigurationError
from pinmob.io import load
from pinmob.model import Mechanism
from pinmob.name_matching import choices, did_you_mean
from pinmob.screw import RTOL, check_rtol


def from_starts(mech: Mechanism, closure_tol: float) -> tuple[Configuration | None, str, Residuals]:
    """A closed configuration projected from the mechanism's starts (MJCF keyframes that do not close), in order.

    Returns it (None when no start closes), a sentence on the starts that did not close, and the residuals of
    the best failed start (smallest worst residual; empty when every start closed or there is none).
    """
    failed: list[str] = []
    best: Residuals = {}
    length = mech.length_scale
    for name, named in mech.configurations.items():
        if not named.start:
            continue
        try:
            found = project(mech, named_vector(mech, name, closure_tol)[0], tol=closure_tol)
        except (ClosureError, ConfigurationError) as exc:
            failed.append(repr(name))
            residuals = getattr(exc, "residuals", None) or {}
            if residuals and (not best or worst_residual(residuals, length) < worst_residual(best, length)):
                best = residuals
            continue
        before = f" ({', '.join(failed)} did not close from there)" if failed else ""
        source = f"projection from {name!r}, a start that does not close as given{before}"
        return Configuration.from_checked(mech, found.q, closure_tol, source=source), "", {}
    return None, (f"nor from its starts that do not close as given ({', '.join(failed)})" if failed else ""), best


def found_configuration(
    mech: Mechanism, restarts: int, relax: bool, closure_tol: float
) -> tuple[Configuration, tuple[str, ...]]:
    """A closed configuration of a mechanism that names none that closes: from its starts, then from neutral.

    Projection from each start of the mechanism (an MJCF keyframe or ``qpos0`` that does not close as given:
    the first that closes, and the report says which), then from neutral and random restarts. Every attempt is
    accepted within ``closure_tol`` (checked by the caller). When none is, and the best misses by what CAD
    geometry explains, the error says which ``closure_tol`` would accept it (:mod:`pinmob.assembly.closure_miss`).
    """
    if not relax:
        found_start, missed, start_residuals = from_starts(mech, closure_tol)
        if found_start is not None:
            return found_start, ()
    else:
        missed, start_residuals = "", {}
    try:
        if relax:  # raises as declared when nothing can be relaxed
            mech, found, relaxed = find_closed_relaxed(mech, restarts=restarts, tol=closure_tol)
        else:
            found, relaxed = find_closed(mech, restarts=restarts, tol=closure_tol), ()
    except ClosureError as exc:
        if relax and relaxable(mech):
            raise  # find_closed_relaxed's refusal: what it relaxed, and how far that still misses
        raise not_closed(mech, restarts, closure_tol, exc.residuals, missed, start_residuals) from None
    source = found.method + (f" (none of {mech.name!r}'s keyframes closed: searched from them first)" if missed else "")
    return Configuration.from_checked(mech, found.q, closure_tol, source=source), relaxed


def asked_configuration(
    mech: Mechanism,
    config: str | None,
    joints: Mapping[str, float] | None,
    *,
    closure_tol: float,
    restarts: int,
    relax: bool,
    name: str | None = None,
) -> tuple[Configuration, tuple[str, ...]]:
    """The configuration :func:`analyze` (and ``pinmob show``) works at, ``closure_tol`` checked once.

    :func:`~pinmob.analysis.configuration_choice.chosen_configuration` (by joint values, by name, or the mechanism's
    first); when the mechanism names none, a closed one found (:func:`found_configuration`). Returns it with the
    closures relaxed to find it (``relax``).
    """
    chosen = chosen_configuration(mech, config, joints, closure_tol=closure_tol, name=name)
    if chosen is not None:
        return chosen, ()
    return found_configuration(mech, restarts, relax, check_closure_tol(closure_tol))  # names none: find one


def not_closed(
    mech: Mechanism,
    restarts: int,
    closure_tol: float,
    residuals: Residuals,
    missed: str = "",
    start_residuals: Residuals | None = None,
) -> ClosureError:
    """The error of :func:`found_configuration` when nothing closed; ``residuals``: those of the best attempt.

    ``missed`` names the starts tried first (:func:`from_starts`), ``start_residuals`` the best of them: the
    best attempt is the better of the two.
    """
    length = mech.length_scale
    if start_residuals and (
        not residuals or worst_residual(start_residuals, length) < worst_residual(residuals, length)
    ):
        residuals = start_residuals
    tried = f", {missed}" if missed else ""
    start = (
        f"{mech.name!r} (as declared) could not be closed from the neutral configuration nor {restarts} random "
        f"restarts{tried}"
    )
    hint = tolerance_hint(residuals, length)
    if hint:  # a CAD gap: a looser tolerance, not relaxing, is the answer
        return ClosureError(
            f"{start} within the closure tolerance {closure_tol:g}: best attempt's residuals "
            f"{format_worst(residuals, length, closure_tol)}{hint}",
            residuals,
        ).naming("closure_tol")
    bad = unclosable(mech, tol=closure_tol)
    found = f"closures that cannot close even on their own: {', '.join(bad)}. " if bad else ""
    if relaxable(mech):
        advice = "Rerun with relax=True to turn the over-constraining closures into 3d (ball) closures. "
    else:
        advice = f"Relaxing cannot help: {nothing_to_relax(mech)}. "
    worst = worst_first(residuals, length)[0][0] if residuals else "-"
    return ClosureError(
        f"{start}. {found}{advice}Largest residual of the best attempt: "
        f"{worst_residual(residuals, length):.2e} (m / L or rad), at {worst}",
        residuals,
    ).naming("relax")


def nothing_to_relax(mech: Mechanism) -> str:
    """Why relaxing closures to ``3d`` cannot change ``mech``: what its closures are, each kind named."""
    parts = []
    if mech.has_platform and mech.limbs:
        names = ", ".join(limb.name for limb in mech.limbs)
        parts.append(f"the limbs' tips ({names}) are welded to the platform by definition: check that each reaches it")
    points = [c.name for c in mech.closures if c.type == "3d"]
    couplings = [c.name for c in mech.closures if c.is_coupling]
    if points:
        parts.append(f"closures {', '.join(points)} are 3d (point) closures already")
    if couplings:
        parts.append(f"{', '.join(couplings)} are joint or tendon couplings, which relaxing leaves as they are")
    return "; ".join(parts) or "the mechanism has no closure"


def analyze(
    mech: Mechanism | Configuration | str | Path,
    q: ArrayLike | str | Configuration | None = None,
    *,
    configuration: str | None = None,
    joints: Mapping[str, float] | None = None,
    rtol: float = RTOL,
    closure_tol: float = CLOSURE_TOL,
    frames: Sequence[str] | None = None,
    outputs: Sequence[str] | None = None,
    actuated: Sequence[str] | None = None,
    paper: bool = False,
    approach: ArrayLike | Mapping[str, float] | None = None,
    actuator_search: int | None = None,
    generic_rank: int | None = None,
    restarts: int = RESTARTS,
    relax: bool = False,
    finite: bool = False,
    finite_order: int = ORDER,
    **parts: Any,
) -> Report:
    """Everything pinmob answers at a closed configuration, as one :class:`Report`.

    Args:
        mech: the mechanism, a :class:`~pinmob.analysis.configuration.Configuration`, or what
            :func:`pinmob.io.load` reads, as ``pinmob analyze`` does: a built-in model's name (any case) or a
            mechanism file's path.
        q: configuration (nq,), the name of one of ``mech.configurations``, or a
            Configuration. None: the mechanism's first named configuration, else a
            closed configuration found by projection from the neutral one and
            ``restarts`` random restarts (``relax=True`` relaxes closures that
            cannot close as declared to ``3d``, and the report says which).
        configuration: name reported with the results (set automatically when q is a name).
        joints: joint values by name [m or rad]: the configuration analysed has them, its other joints start
            from the configuration named by q (default: the first named, else neutral) and are solved when the
            values do not close the loops as they are (:func:`~pinmob.analysis.configuration_choice.joint_configuration`).
        rtol: relative tolerance of every rank decision (singular values below
            ``rtol * sigma_max`` count as zero); see :func:`~pinmob.screw.rank.check_rtol`.
        closure_tol: closure tolerance (position / L and rotation [rad]).
        frames: frames whose motion on the closed chain is also reported.
        outputs: frames that idle motions must leave at rest (default: the platform, else the free leaf bodies).
        actuated: actuated joints for the actuation verdict (default: the declared ones, tendon actuators too;
            joints given: those alone).
        paper: also compute the seed paper's view (:func:`~pinmob.analysis.paper.paper_mobility`).
        approach: the paper's view's approach direction (default: declared, else from ``generic``).
        actuator_search: also list every valid set of this many actuated joints (exhaustive).
        generic_rank: the generic constraint rank (default: declared, else estimated).
        restarts: random restarts when q is None and the mechanism names no configuration.
        relax: with q None and no named configuration, relax unclosable closures to ``3d``.
        finite: also compute finite versus instantaneous mobility (:mod:`pinmob.analysis.finite.finite_mobility`):
            ``report.finite``.
        finite_order: the highest order of the conditions the finite analysis checks (2..8).
        **parts: the keywords of the other registered report parts (:func:`~pinmob.analysis.report.register_part`),
            e.g. ``toy=True`` for a part registered with ``PartOption("toy")``: ``report.part("toy")``. The keywords
            above (``paper``, ``approach``, ``actuator_search``, ``finite``, ``finite_order``) are those of the
            built-in parts, named for their types and documentation.

    Each argument is checked once, here or where it is first used (``closure_tol`` by the Configuration built).

    Raises:
        ArgumentError: rtol, closure_tol, finite_order or restarts out of range, joints without a mechanism, or a
            keyword that no registered report part has.
        UnknownConfigurationError: q (or the base of ``joints``) names no configuration of the mechanism.
        ConfigurationError: another bad argument (shape, NaN, a Configuration of another mechanism).
        ClosureError: q does not close, or no closed configuration could be found.
    """
    if isinstance(mech, (str, Path)):
        mech = load(mech)
    elif not isinstance(mech, (Mechanism, Configuration)):
        raise ArgumentError(
            f"analyze takes a Mechanism, a Configuration, a built-in model's name or a file's path, got "
            f"{type(mech).__name__}",
            "mech",
            mech,
        )
    rtol = check_rtol(rtol)
    keywords = part_keywords()
    for keyword in parts:
        if keyword not in keywords:
            raise ArgumentError(
                f"analyze has no keyword {keyword!r}{did_you_mean(keyword, keywords)}; the report parts' "
                f"keywords: {choices(keywords)}",
                keyword,
                parts[keyword],
            )
    finite_order = check_order(finite_order)
    if isinstance(restarts, bool) or not isinstance(restarts, int) or restarts < 0:
        raise ArgumentError(
            f"the number of random restarts (restarts) must be at least 0, got {restarts!r}", "restarts", restarts
        )
    check_bound("restarts", restarts, "the closure search (restarts)", "restarts")
    relaxed: tuple[str, ...] = ()
    if joints is not None and not (isinstance(mech, Mechanism) and (q is None or isinstance(q, str))):
        raise ArgumentError(
            "joints is given with a Mechanism, and q the name of the configuration the other joints start from "
            "(or None)",
            "joints",
            joints,
        )
    if isinstance(mech, Mechanism) and (q is None or isinstance(q, str)):
        chosen, relaxed = asked_configuration(
            mech, q, joints, closure_tol=closure_tol, restarts=restarts, relax=relax, name=configuration
        )
        conf = as_configuration(chosen, configuration=configuration)
    else:
        conf = as_configuration(mech, q, configuration=configuration, closure_tol=closure_tol)
    asked, rtol = rtol, conf.rank_rtol(rtol)  # loops closed only to CAD accuracy: a coarser rank tolerance
    options = Options(
        frames=tuple(frames or ()),
        outputs=None if outputs is None else tuple(outputs),
        actuated=None if actuated is None else tuple(actuated),
        generic_rank=generic_rank,
        relaxed=relaxed,
        rtol_asked=asked,
        asked={
            "paper": paper,
            "approach": approach,
            "actuator_search": actuator_search,
            "finite": finite,
            "finite_order": finite_order,
            **parts,
        },
    )
    mobility = platform_mobility(conf, rtol) if conf.mechanism.has_platform else None
    return Report(conf, rtol, mobility, options)
