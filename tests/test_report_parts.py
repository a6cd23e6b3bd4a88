"""The report section protocol (issue 34, item 2): a new analysis is its function plus one ``register_part`` call.

A toy analysis registered here, and nowhere else, shows up in ``str(report)``, ``to_dict()``, the notebook's HTML,
``brief()``, as keywords of :func:`pinmob.analyze` and as options of ``pinmob analyze`` (worded as options in the
text the command line prints). The truth is a hand count: a 3-PRS limb has a prismatic, a revolute and a spherical
joint (three revolutes in the file), 1 + 1 + 3 = 5 joints, so the three limbs have 15.
"""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path

import pytest

import pinmob
from pinmob import glossary
from pinmob.analysis.report import Report
from pinmob.analysis.report_parts import REPORT_PARTS, PartOption, ReportPart, register_part, unregister_part
from pinmob.cli import main
from pinmob.cli.parser import build_parser

DATA = Path(__file__).resolve().parent / "data"


def joint_tally(report: Report) -> dict[str, int] | None:
    """The toy analysis: each limb's number of joints, for the limbs with at least ``tally_min`` joints."""
    if not report.options.value("tally"):
        return None
    least = report.options.value("tally_min")
    return {limb.name: len(limb.joints) for limb in report.state.mechanism.limbs if len(limb.joints) >= least}


@pytest.fixture
def toy() -> Iterator[ReportPart]:
    """The toy registered for one test, removed after it."""
    part = register_part(
        ReportPart(
            "tally",
            "joint tally",
            joint_tally,
            options=(
                PartOption("tally", "tally", "also count each limb's joints", default=False),
                PartOption("tally_min", "tally-min", "only limbs of at least K joints", metavar="K", default=1,
                           implies="tally"),
            ),
            text=lambda report, t: f"joints per limb: {t} (asked for with `tally=True`)",
            brief=lambda report, t: f"joints: {sum(t.values())}",
            terms=("joint tally",),
            glossary="- **joint tally** (`tally`): each limb's number of joints.",
        )
    )  # fmt: skip
    yield part
    unregister_part("tally")


def test_a_toy_part_is_in_every_output_of_the_report(toy: ReportPart) -> None:
    report = pinmob.analyze("3-PRS", "home", tally=True)
    assert report.part("tally") == {"A": 5, "B": 5, "C": 5}  # by hand: P + R + S(3)
    text = str(report)
    assert text.endswith("\n\njoints per limb: {'A': 5, 'B': 5, 'C': 5} (asked for with `tally=True`)")
    assert report.to_dict()["tally"] == {"A": 5, "B": 5, "C": 5} and list(report.to_dict())[-1] == "tally"
    assert report.brief().endswith("; joints: 15")
    page = report._repr_html_()
    assert "<strong>joint tally</strong>" in page and "joints per limb: {&#x27;A&#x27;: 5" in page
    assert [s.title for s in report.sections()][-1] == "joint tally"
    assert pinmob.analyze("3-PRS", "home", tally=True, tally_min=6).part("tally") == {}


def test_a_toy_part_not_asked_for_is_absent(toy: ReportPart) -> None:
    report = pinmob.analyze("3-PRS", "home")
    assert report.part("tally") is None
    assert "joint tally" not in [s.title for s in report.sections()] and "tally" not in report.to_dict()
    assert "joints:" not in report.brief()


def test_a_toy_part_is_an_option_of_pinmob_analyze(toy: ReportPart, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["analyze", "3-PRS", "--config", "home", "--tally"]) == 0
    out = capsys.readouterr().out
    assert out.endswith("joints per limb: {'A': 5, 'B': 5, 'C': 5} (asked for with --tally)\n")  # worded as the option
    assert main(["analyze", "3-PRS", "--config", "home", "--tally-min", "6", "--json"]) == 0  # implies --tally
    assert json.loads(capsys.readouterr().out)["tally"] == {}
    assert main(["analyze", "3-PRS", "--config", "home", "--tally", "--brief"]) == 0
    assert capsys.readouterr().out.endswith("; joints: 15\n")
    helped = build_parser()._subparsers._group_actions[0].choices["analyze"].format_help()  # type: ignore[union-attr]
    assert "--tally-min K" in helped and "only limbs of at least K joints; implies --tally" in helped


def test_a_part_without_an_option_is_computed_unasked() -> None:
    """A part such as "minimal closures": always computed, shown where it has something to say, no option."""

    def points(report: Report) -> int | None:
        return sum(c.type == "3d" for c in report.state.mechanism.closures) or None

    register_part(ReportPart("points", "point closures", points, text=lambda report, n: f"3d closures: {n}"))
    try:
        assert all(not p.options for p in REPORT_PARTS.values() if p.name == "points")
        delta = pinmob.analyze("Delta")  # its file: closures A_b, B_b, C_b, each 3d (pinmob models)
        assert delta.part("points") == 3 and delta.sections()[-1].text == "3d closures: 3"
        assert delta.to_dict()["points"] == 3
        prs = pinmob.analyze("3-PRS", "home")  # limbs welded to the platform, no closure declared
        assert prs.part("points") is None and "point closures" not in [s.title for s in prs.sections()]
        assert not [a for a in build_parser()._actions if "--points" in a.option_strings]
    finally:
        unregister_part("points")


def test_a_part_option_of_another_type(capsys: pytest.CaptureFixture[str]) -> None:
    """``type=float``: ``--scale 0.5`` reaches the part as 0.5 (three limbs: 1.5); a word is refused by argparse."""

    def scaled(report: Report) -> float | None:
        scale = report.options.value("scale")
        return None if scale is None else scale * len(report.state.mechanism.limbs)

    register_part(
        ReportPart("scaled", "scaled", scaled, options=(PartOption("scale", "scale", "a scale", "S", float),))
    )
    try:
        assert main(["analyze", "3-PRS", "--config", "home", "--scale", "0.5", "--json"]) == 0
        assert json.loads(capsys.readouterr().out)["scaled"] == 1.5
        with pytest.raises(SystemExit) as refused:
            main(["analyze", "3-PRS", "--config", "home", "--scale", "half"])
        assert refused.value.code == 2
        assert "argument --scale: invalid float value: 'half'" in capsys.readouterr().err
    finally:
        unregister_part("scaled")


def test_registering_refuses_a_taken_name_or_keyword(toy: ReportPart) -> None:
    with pytest.raises(pinmob.ArgumentError, match="'tally' is registered already"):
        register_part(ReportPart("tally", "again", joint_tally))
    with pytest.raises(pinmob.ArgumentError, match="another part's: finite"):
        register_part(ReportPart("other", "other", joint_tally, options=(PartOption("finite"),)))
    assert "other" not in REPORT_PARTS


def test_analyze_refuses_a_keyword_no_part_has(toy: ReportPart) -> None:
    with pytest.raises(pinmob.ArgumentError, match=r"analyze has no keyword 'taly' \(did you mean 'tally'"):
        pinmob.analyze("3-PRS", "home", taly=True)


def test_a_part_s_entries_go_where_it_says(toy: ReportPart) -> None:
    """``json_before``: the seed paper's view stays before ``singularity`` in the document, as before the protocol."""
    doc = pinmob.analyze("3-PUU-flat", "flat", paper=True, tally=True).to_dict()
    keys = list(doc)
    assert keys.index("paper_view") == keys.index("singularity") - 1 and keys[-1] == "tally"


def test_a_part_s_section_and_null_entry_go_where_it_says() -> None:
    """``text_before`` puts a section before the one it names; ``json_null`` keeps the key, null, where it is None."""
    register_part(
        ReportPart(
            "legs",
            "legs",
            lambda report: len(report.state.mechanism.limbs) or None,
            text=lambda report, n: f"legs: {n}",
            terms=("limb",),
            json_null=True,
            text_before="mechanism",
        )
    )
    try:
        limbs, chain = pinmob.analyze("3-PRS", "home"), pinmob.analyze(pinmob.load(DATA / "fourbar.toml"))
        titles = [s.title for s in limbs.sections()]
        assert titles[titles.index("mechanism") - 1] == "legs" and "legs: 3\n\n" in str(limbs)  # by hand: A, B, C
        assert limbs.to_dict()["legs"] == 3 and chain.part("legs") is None and chain.to_dict()["legs"] is None
        assert "legs" not in [s.title for s in chain.sections()]
    finally:
        unregister_part("legs")


def test_the_minimal_closures_are_a_registered_part() -> None:
    """Before the rank notes and the other parts, ``null`` in the JSON where no closure equation is redundant."""
    planar = pinmob.analyze("3-RRR-planar", "generic", actuator_search=3)  # 12 closure rows of rank 6 (planar)
    assert planar.minimal_closures is planar.part("minimal_closures") and planar.minimal_closures is not None
    titles, keys = [s.title for s in planar.sections()], list(planar.to_dict())
    assert titles.index("minimal closures") < titles.index("actuator sets")
    assert keys.index("minimal_closures") == keys.index("rank_tolerance_note") - 1
    assert planar.to_dict()["minimal_closures"] == planar.minimal_closures.to_dict()
    # a CAD gap of 1 um (tests/test_cad_gaps.py): 2 of 6 closure equations redundant, the rank tolerance raised
    noted = pinmob.analyze(pinmob.load(DATA / "cad_gaps" / "spherical_3rrr" / "robot.urdf"), closure_tol=1e-4)
    titles = [s.title for s in noted.sections()]
    assert titles.index("minimal closures") == titles.index("rank notes") - 1
    prs = pinmob.analyze("3-PRS", "home")  # 3 limbs of 3 wrenches each, rank 3 + 3 by hand: nothing redundant
    assert prs.minimal_closures is None and prs.to_dict()["minimal_closures"] is None
    assert "minimal closures" not in [s.title for s in prs.sections()]


def test_the_built_in_parts_are_registered_in_their_order() -> None:
    assert list(REPORT_PARTS)[:4] == ["minimal_closures", "actuator_sets", "paper", "finite"]
    report = pinmob.analyze("3-PRS", "home")
    assert (report.paper, report.actuator_sets, report.finite) == (None, None, None)
    with pytest.raises(pinmob.ArgumentError, match=r"no report part 'papr' \(did you mean 'paper'"):
        report.part("papr")


def test_each_part_s_words_are_in_the_glossary() -> None:
    for part in REPORT_PARTS.values():
        assert part.terms, f"{part.name}: no glossary term"
        for term in part.terms:
            assert glossary.lookup(term), term


def test_a_toy_part_brings_its_glossary_entry(toy: ReportPart, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["glossary", "joint tally"]) == 0
    assert (
        capsys.readouterr().out
        == "Registered report parts:\n- **joint tally** (`tally`): each limb's number of joints.\n"
    )
    assert main(["glossary"]) == 0
    whole = capsys.readouterr().out
    assert whole.startswith(glossary.text().rstrip("\n")) and whole.endswith(
        "(`tally`): each limb's number of joints.\n"
    )
    assert all(glossary.lookup(term, whole) for term in toy.terms)
