"""The whole answer at one closed configuration: :class:`Report`, from the one entry point :func:`analyze`.

``Report.to_dict()`` is the document ``pinmob analyze --json`` prints, ``str(report)`` the text ``pinmob analyze``
prints (the parameters it names in backticks, as ``paper=True``, worded as options). The platform mobility is
computed at once; the other parts when first used (``to_dict`` and ``str`` use them all):

* ``mechanism_mobility``: the whole closed chain (closure Jacobian, redundancy, idle motions, actuation,
  frame motions);
* ``singularity``: the singularity classes and distances (the first report of a mechanism also estimates
  its generic constraint rank, from random closed configurations, unless the file declares it);
* the registered parts (:mod:`pinmob.analysis.report_parts`), each its section, its JSON entries, its
  keywords of :func:`analyze` and its options of ``pinmob analyze`` from one registration
  (:func:`~pinmob.analysis.report_parts.register_part`), read as ``report.part(name)``: ``minimal_closures``,
  per closure, the closure with exactly its independent equations, only where some closure equation is redundant
  (:mod:`pinmob.analysis.minimal`; shown before the rank notes, and ``null`` in the JSON otherwise);
  ``actuator_sets``, every valid set of K actuated joints, only when asked (``actuator_search=K``); ``paper``, the
  seed paper's view, only when asked (``paper=True``); ``finite``, finite versus instantaneous mobility, only when
  asked (``finite=True``; :mod:`pinmob.analysis.finite`). Each of these four is also an attribute
  (``report.paper``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from typing import TYPE_CHECKING, Any

from pinmob.analysis.ambiguity import AmbiguousRank, ambiguous_ranks, raised_note
from pinmob.analysis.chain import FrameMobility, MechanismMobility
from pinmob.analysis.chain.mechanism_mobility import mechanism_mobility
from pinmob.analysis.configuration import Configuration
from pinmob.analysis.expectation import ExpectationCheck, expectation_check
from pinmob.analysis.generic import generic_constraint_rank
from pinmob.analysis.mobility import Mobility
from pinmob.analysis.report_html import Section, joined, report_html
from pinmob.analysis.report_parts import REPORT_PARTS, Options
from pinmob.analysis.singularity import Singularity, singularity
from pinmob.analysis.summary import summary_line
from pinmob.exceptions import ArgumentError, ConfigurationError
from pinmob.model import joint_layout, values_by_name
from pinmob.name_matching import choices, did_you_mean

if TYPE_CHECKING:
    from pinmob.analysis.finite.finite_mobility import FiniteMobility
    from pinmob.analysis.minimal import MinimalClosures


@dataclass(frozen=True, eq=False)
class Report:
    """Everything pinmob answers at one closed configuration (what ``pinmob analyze`` prints).

    Attributes:
        state: the :class:`~pinmob.analysis.configuration.Configuration` analysed.
        rtol: relative tolerance of every rank decision.
        mobility: the platform's mobility (None when the mechanism has no platform frame).
        options: what was asked for (:class:`Options`).

    The platform mobility's fields (``dof``, ``motion_type``, ``motions``, ``free_twists``, ``constraints``,
    ``constraint_rank``, ``limbs``, ...) are also readable on the report itself. Jupyter shows it as HTML
    (:mod:`pinmob.analysis.report_html`), IPython's text display as ``str(report)``.
    """

    state: Configuration = field(repr=False)
    rtol: float
    mobility: Mobility | None
    options: Options = field(default_factory=Options, repr=False)
    _parts: dict[str, Any] = field(default_factory=dict, init=False, repr=False, compare=False)

    # ------------------------------------------------------------------ parts

    @property
    def mechanism(self) -> str:
        """The mechanism's name."""
        return self.state.mechanism.name

    @property
    def configuration(self) -> str | None:
        """The configuration's name (None when unnamed)."""
        return self.state.name

    @property
    def has_limbs(self) -> bool:
        """The mechanism has limbs (else it is described by closures only)."""
        return bool(self.state.mechanism.limbs)

    @cached_property
    def mechanism_mobility(self) -> MechanismMobility:
        """The whole closed chain's mobility (computed when first used)."""
        o = self.options
        return mechanism_mobility(self.state, self.rtol, actuated=o.actuated, frames=o.frames, outputs=o.outputs)

    @cached_property
    def singularity(self) -> Singularity | None:
        """Singularity classes and distances; None where the limb-wise classes do not apply (computed when first used)."""
        if self.mobility is None or self.mobility.method_note or not self.has_limbs:
            return None
        g, asked = self.options.generic_rank, self.options.rtol_asked
        if g is None and asked is not None and asked < self.rtol:  # raised for this configuration's CAD gap only:
            g = generic_constraint_rank(self.state.mechanism, rtol=asked)  # the generic samples close exactly
        return singularity(self.state, self.rtol, g)

    def part(self, name: str) -> Any:
        """The registered part ``name``, computed when first read; None when not asked for or not applicable.

        Raises:
            ArgumentError: no part of that name is registered (:data:`~pinmob.analysis.report_parts.REPORT_PARTS`).
        """
        if name not in self._parts:
            if name not in REPORT_PARTS:
                raise ArgumentError(
                    f"no report part {name!r}{did_you_mean(name, REPORT_PARTS)}; parts: {choices(REPORT_PARTS)}",
                    "name",
                    name,
                )
            self._parts[name] = REPORT_PARTS[name].compute(self)
        return self._parts[name]

    @property
    def paper(self) -> Mobility | None:
        """The seed paper's view (only when asked for with ``paper=True``)."""
        return self.part("paper")

    @property
    def actuator_sets(self) -> tuple[tuple[str, ...], ...] | None:
        """Every valid set of K actuated joints (only when asked for with ``actuator_search=K``)."""
        return self.part("actuator_sets")

    @property
    def finite(self) -> FiniteMobility | None:
        """Finite versus instantaneous mobility (only when asked for with ``finite=True``)."""
        return self.part("finite")

    @property
    def minimal_closures(self) -> MinimalClosures | None:
        """Per closure, the closure with exactly its independent equations; None where none is redundant.

        Computed only where ``mechanism_mobility.redundant_constraints > 0`` (:mod:`pinmob.analysis.minimal`).
        """
        return self.part("minimal_closures")

    @property
    def platform_frame(self) -> FrameMobility | None:
        """The platform frame's motion on the whole closed chain (None without a platform)."""
        if not (mech := self.state.mechanism).has_platform:
            return None
        return next((f for f in self.mechanism_mobility.frames if f.frame == mech.platform), None)

    @property
    def expectation(self) -> ExpectationCheck | None:
        """The file's expected mobility at this configuration and whether the analysis agrees (None if none)."""
        found = self.mobility if self.has_limbs else self.platform_frame
        return expectation_check(self.state.mechanism, self.state.name, found)

    # ------------------------------------------------------------------ the platform mobility's fields

    def _platform(self) -> Mobility:
        if self.mobility is None:
            raise ConfigurationError(
                f"{self.mechanism!r} has no platform frame: see report.mechanism_mobility for the whole closed chain"
            )
        return self.mobility

    dof = property(lambda self: self._platform().dof, doc="Platform DoF.")
    motion_type = property(lambda self: self._platform().motion_type, doc="Platform motion type, e.g. ``3T``.")
    motions = property(lambda self: self._platform().motions, doc="The platform's free motions.")
    free_twists = property(lambda self: self._platform().free_twists, doc="(6, dof) free twists.")
    constraints = property(lambda self: self._platform().constraints, doc="Canonical constraint wrenches.")
    constraint_wrenches = property(lambda self: self._platform().constraint_wrenches, doc="(6, d) wrenches.")
    constraint_rank = property(lambda self: self._platform().constraint_rank, doc="Constraint rank d.")
    singular_values = property(lambda self: self._platform().singular_values, doc="(6,) singular values.")
    tolerance = property(lambda self: self._platform().tolerance, doc="Absolute rank tolerance.")
    length_scale = property(lambda self: self.state.mechanism.length_scale, doc="L [m].")
    limbs = property(lambda self: self._platform().limbs, doc="Per-limb details.")
    serially_singular_limbs = property(lambda self: self._platform().serially_singular_limbs, doc="Singular limbs.")
    method = property(lambda self: self._platform().method, doc="How the constraint space was obtained.")
    method_note = property(lambda self: self._platform().method_note, doc="Why that method.")
    view = property(lambda self: self._platform().view, doc="The view of the platform mobility.")
    translations = property(lambda self: self._platform().translations, doc="Free translations.")
    rotations = property(lambda self: self._platform().rotations, doc="Free rotations.")
    screws = property(lambda self: self._platform().screws, doc="Free screws.")
    platform_origin = property(lambda self: self._platform().platform_origin, doc="(3,) platform origin [m].")
    frame = property(lambda self: self._platform().frame, doc="The expression frame, in words.")

    # ------------------------------------------------------------------ outputs

    def to_dict(self) -> dict[str, Any]:
        """The document ``pinmob analyze --json`` prints (plain JSON, never NaN)."""
        if not self.has_limbs:
            out = self.mechanism_mobility.to_dict()
            out["closed_configuration"] = {
                "method": self.state.source,
                "residual": self.state.residual,
                "relaxed_closures": list(self.options.relaxed),
                "q": [float(x) for x in self.state.q],
            }
            platform = self.platform_frame
            if platform is not None:
                out["platform"] = platform.to_dict()
        else:
            mob = self._platform()
            out = mob.to_dict()
            mm = self.mechanism_mobility.to_dict()
            out.update({k: mm[k] for k in MECHANISM_KEYS})
            exp = self.expectation
            if exp is not None:
                out["expected"] = exp.to_dict()
            sing = self.singularity
            out["singularity"] = sing.to_dict() if sing is not None else None
        mech = self.state.mechanism
        layout = mech.memo("joint layout", lambda: joint_layout(mech.model))
        out["joint_values"] = values_by_name(mech.model, self.state.q, mech.quaternion_wxyz, layout)
        out["rank_tolerance_note"] = self._raised()
        out["ambiguous_ranks"] = [a.to_dict() for a in self.ambiguous_ranks]
        for name, part in REPORT_PARTS.items():  # the registered parts' entries, in their order
            if entries := part.document(self, self.part(name)):
                out = inserted(out, entries, part.json_before)
        return out

    def __str__(self) -> str:
        """The text ``pinmob analyze`` prints."""
        return joined(self.sections())

    def sections(self) -> list[Section]:
        """``str(report)`` in its parts, each with a title (the notebook's HTML shows them under their titles)."""
        if not self.has_limbs:
            closed = f"closed configuration: {self.state.source} (largest residual {self.state.residual:.1e})"
            if self.options.relaxed:
                closed += f"\nrelaxed to 3d (the file's closures cannot all close as declared): {', '.join(self.options.relaxed)}"
            out = [Section("closed configuration", closed), Section("mechanism", str(self.mechanism_mobility))]
        else:
            mob, sing, expected = self._platform(), self.singularity, self.expectation
            unseen = "singularity: not analysed (limb-wise classes)"
            out = [Section("platform", str(mob)), Section("singularity", unseen if sing is None else str(sing))]
            out += [Section("expected", str(expected))] if expected is not None else []
            out.append(Section("mechanism", str(self.mechanism_mobility), gap=True))
        if lines := self._rank_lines():
            out.append(Section("rank notes", "\n".join(lines)))
        for name, part in REPORT_PARTS.items():  # the registered parts' sections, in their order
            if (value := self.part(name)) is not None and (text := part.text(self, value)) is not None:
                out = placed(out, Section(part.title, text, gap=part.gap), part.text_before)
        return out

    def _repr_pretty_(self, p: Any, cycle: bool) -> None:  # IPython's text display: str(report), not the dataclass repr
        p.text(str(self))

    def _repr_html_(self) -> str:  # Jupyter's rich display: the sections as HTML (analysis/report_html.py)
        chain, sections = self.mechanism_mobility, self.sections()
        return report_html(self.mechanism, self.configuration, self.mobility, self.singularity, chain, sections)

    def brief(self) -> str:
        """``pinmob analyze --brief``'s line (:func:`~pinmob.analysis.summary.summary_line`), ambiguous ranks, the parts' words."""
        chain = self.mechanism_mobility if self.mobility is None else None
        line = summary_line(self.mechanism, self.configuration, self.mobility, self.singularity, chain)
        if self.state.mechanism.ignored:  # never a DoF without the elements it leaves out
            line += f"; ignoring what pinmob does not read: {'; '.join(self.state.mechanism.ignored)}"
        for a in self.ambiguous_ranks:  # never a confident count where the gap is not clear (the full text's note)
            line += f"; ambiguous {a.decision}: {a.rank} as counted, {' or '.join(map(str, a.alternatives))} possible"
        for name, part in REPORT_PARTS.items():  # the registered parts that have a word in it
            if part.brief is not None and (value := self.part(name)) is not None:
                line += f"; {part.brief(self, value)}"
        return line

    @cached_property
    def ambiguous_ranks(self) -> tuple[AmbiguousRank, ...]:
        """The rank decisions without a clear gap around their tolerance (:func:`ambiguous_ranks`)."""
        return ambiguous_ranks(self.mechanism_mobility, self.mobility)

    def _raised(self) -> str | None:
        asked = self.rtol if self.options.rtol_asked is None else self.options.rtol_asked
        return raised_note(asked, self.rtol, self.state.residual)

    def _rank_lines(self) -> list[str]:
        note = self._raised()
        return ([f"note: {note}"] if note else []) + [str(a) for a in self.ambiguous_ranks]


def inserted(document: dict[str, Any], entries: dict[str, Any], before: str | None) -> dict[str, Any]:
    """``document`` with ``entries`` added before its key ``before`` (at the end when None or absent)."""
    if before is None or before not in document:
        return {**document, **entries}
    out: dict[str, Any] = {}
    for key, value in document.items():
        if key == before:
            out.update(entries)
        out[key] = value
    return out


def placed(sections: list[Section], section: Section, before: str | None) -> list[Section]:
    """``sections`` with ``section`` added before the first titled ``before`` (at the end when None or absent)."""
    at = next((i for i, s in enumerate(sections) if before is not None and s.title == before), len(sections))
    return [*sections[:at], section, *sections[at:]]


#: keys of the whole-mechanism document added to the JSON of a limb-and-platform analysis
MECHANISM_KEYS = (
    "nv", "closure_rows", "closure_rank", "mechanism_dof", "internal_dof", "idle_dof", "idle_joints",
    "redundant_constraints", "redundant_by_closure", "redundant_by_closure_rule", "grubler", "grubler_by_own_rank",
    "motion_subgroup", "actuation", "closures", "end_frames", "frames", "ignored",
)  # fmt: skip
