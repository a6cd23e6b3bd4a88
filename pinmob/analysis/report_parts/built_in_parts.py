"""pinmob's own report parts, registered in the order of their sections (:mod:`~pinmob.analysis.report_parts.report_part`).

The minimal closures, the actuator sets, the seed paper's view, the finite mobility. The minimal closures are
computed for every report, where some closure equation is redundant (their section before the rank notes, their
key ``null`` in the JSON otherwise); the others only when asked for, and the paper's view and the finite analysis
import their modules then.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from pinmob.analysis.chain.actuation import actuator_sets, default_end_frames
from pinmob.analysis.finite.higher_order import ORDER, ORDERS
from pinmob.analysis.minimal import MinimalClosures, minimal_closures
from pinmob.analysis.report_parts.report_part import PartOption, ReportLike, ReportPart, register_part

if TYPE_CHECKING:
    from pinmob.analysis.finite.finite_mobility import FiniteMobility
    from pinmob.analysis.mobility import Mobility


def _minimal_closures(report: ReportLike) -> MinimalClosures | None:
    if not report.mechanism_mobility.redundant_constraints:
        return None
    return minimal_closures(report.state, report.rtol)


def _actuator_sets(report: ReportLike) -> tuple[tuple[str, ...], ...] | None:
    if (k := report.options.value("actuator_search")) is None:
        return None
    outs = default_end_frames(report.state.mechanism)
    return tuple(actuator_sets(report.state, None, k, outputs=outs, rtol=report.rtol))


def _actuator_lines(report: ReportLike, sets: tuple[tuple[str, ...], ...]) -> str:
    lines = [f"valid sets of {report.options.value('actuator_search')} actuated joints: {len(sets)}"]
    lines += ["  " + ", ".join(x) for x in sets[:50]]
    if len(sets) > 50:
        lines.append(f"  ... ({len(sets) - 50} more)")
    return "\n".join(lines)


def _paper(report: ReportLike) -> Mobility | None:
    if not report.options.value("paper"):
        return None
    from pinmob.analysis.paper import paper_mobility  # only on request

    return paper_mobility(report.state, report.rtol, report.options.value("approach"))


def _paper_text(report: ReportLike, paper: Mobility) -> str | None:
    if not report.has_limbs or (mob := report.mobility) is None:  # the whole chain's report has no paper's view
        return None
    text = str(paper)
    if (paper.dof, paper.motion_type) != (mob.dof, mob.motion_type):
        text += (
            f"\ndifference: the paper's view gives {paper.motion_type} ({paper.dof} DoF), the wrenches at the "
            f"configuration give {mob.motion_type} ({mob.dof} DoF); serially singular limbs: "
            f"{', '.join(mob.serially_singular_limbs) or 'none'}"
        )
    return text


def _finite(report: ReportLike) -> FiniteMobility | None:
    if not report.options.value("finite"):
        return None
    platform = report.mobility if report.has_limbs else report.platform_frame
    motions = None if platform is None else platform.motions
    sing = report.singularity if report.state.mechanism.actuated else None
    locked = sing.uncontrolled if sing is not None and sing.actuation is not None else None
    from pinmob.analysis.finite.finite_mobility import finite_mobility  # its modules load when it is asked for

    order = report.options.value("finite_order")
    return finite_mobility(report.state, report.rtol, order, motions=motions, locked_motions=locked)


register_part(
    ReportPart(
        "minimal_closures",
        "minimal closures",
        _minimal_closures,
        terms=("minimal closures",),
        json_before="rank_tolerance_note",
        json_null=True,
        text_before="rank notes",
        gap=False,
    )
)
register_part(
    ReportPart(
        "actuator_sets",
        "actuator sets",
        _actuator_sets,
        options=(
            PartOption(
                "actuator_search",
                "search-actuators",
                "also list every valid set of K actuated joints (exhaustive)",
                metavar="K",
            ),
        ),
        text=_actuator_lines,
        entries=lambda report, sets: {"valid_actuator_sets": [list(x) for x in sets]},
        terms=("actuation valid",),
        gap=False,
    )
)
register_part(
    ReportPart(
        "paper",
        "the seed paper's view",
        _paper,
        options=(
            PartOption(
                "paper",
                "paper-view",
                "also show the seed paper's view: generic limb wrenches carried to the configuration",
                default=False,
            ),
            PartOption("approach"),
        ),
        text=_paper_text,
        entries=lambda report, paper: {"paper_view": paper.to_dict()} if report.has_limbs else {},
        json_before="singularity",
        terms=("seed paper",),
    )
)
register_part(
    ReportPart(
        "finite",
        "finite mobility",
        _finite,
        options=(
            PartOption(
                "finite",
                "finite",
                "also tell finite from instantaneous mobility: which free motions exist at finite amplitude "
                "(higher-order conditions, tracing, closed samples)",
                default=False,
            ),
            PartOption(
                "finite_order",
                "finite-order",
                f"the highest order of the conditions the finite analysis checks ({ORDERS[0]}..{ORDERS[-1]}, default {ORDER})",
                metavar="K",
                default=ORDER,
                implies="finite",
            ),
        ),
        entries=lambda report, finite: finite.report_entries(),
        brief=lambda report, finite: f"finite: {finite.brief()}",
        terms=("finite",),
    )
)
