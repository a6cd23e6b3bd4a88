"""Notebooks: a Report's HTML and text displays, the viewer in a cell, and the example notebook executed.

The HTML is read back with the standard library's parser and checked against what is known of each
model without pinmob (the hand derivations of tests/test_three_puu.py and tests/test_external_robots.py):
its DoF and motion type, one table row per free motion with its kind, direction and axis, and a mechanism
whose names are markup (from its files) must come out as text, never as tags. The viewer's cell in a browser: tests/test_browser.py.
The example notebook runs in a fresh kernel of this interpreter (a kernel spec written for
``sys.executable``, found first: a new ``.venv`` runs it, whatever other kernels the machine has).
"""

from __future__ import annotations

import html
import json
import sys
import warnings
from html.parser import HTMLParser
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob import viewer

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOK = ROOT / "examples" / "notebook.ipynb"
MODELS = Path(pinmob.io.builtin_dir())
FIVE_BAR = ROOT / "tests" / "data" / "example-parallel-robots" / "5bar_linkage_iso3d" / "robot.yaml"
HOSTILE = "<script>alert('x')</script>"


class Tags(HTMLParser):
    """Every start tag (with its attributes), every table's rows of cell texts, every <pre>'s text."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: list[tuple[str, dict[str, str | None]]] = []
        self.tables: list[list[list[str]]] = []
        self.pres: list[str] = []
        self.summaries: list[str] = []
        self._cell: list[str] | None = None
        self._pre: list[str] | None = None
        self._summary: list[str] | None = None

    def handle_starttag(self, tag, attrs):
        self.tags.append((tag, dict(attrs)))
        if tag == "table":
            self.tables.append([])
        elif tag == "tr":
            self.tables[-1].append([])
        elif tag in ("td", "th"):
            self._cell = []
        elif tag == "pre":
            self._pre = []
        elif tag == "summary":
            self._summary = []

    def handle_endtag(self, tag):
        if tag in ("td", "th") and self._cell is not None:
            self.tables[-1][-1].append("".join(self._cell))
            self._cell = None
        elif tag == "pre" and self._pre is not None:
            self.pres.append("".join(self._pre))
            self._pre = None
        elif tag == "summary" and self._summary is not None:
            self.summaries.append("".join(self._summary))
            self._summary = None

    def handle_data(self, data):
        for part in (self._cell, self._pre, self._summary):
            if part is not None:
                part.append(data)


def parsed(text: str) -> Tags:
    tags = Tags()
    tags.feed(text)
    tags.close()
    return tags


@pytest.fixture(scope="module")
def flat_report() -> pinmob.Report:
    return pinmob.analyze(pinmob.load("3-PUU-flat"), "flat")


def vector(cell: str) -> np.ndarray:
    """A cell's ``[ 0,  0,  1]`` as numbers."""
    return np.array(json.loads(cell), float)


def test_report_html_says_what_the_hand_derivation_says(flat_report):
    """3-PUU-flat (tests/test_three_puu.py, by hand): 2 DoF, 1T1R, a translation along z and a rotation about
    the z axis through the platform's centre (the origin); 5 joints x 3 limbs = 15, closure rank 10: mechanism
    DoF 5. The answer's table, one row per motion, then the sections under their titles."""
    page = parsed(flat_report._repr_html_())
    facts, motions = dict(page.tables[0]), page.tables[1]
    assert facts["mechanism"] == "3-PUU-flat" and facts["configuration"] == "flat"
    assert facts["platform"] == "2 DoF, 1T1R" and facts["mechanism DoF"] == "5"
    assert motions[0] == ["motion", "kind", "direction", "axis through [m]", "pitch [m/rad]"]
    assert len(motions) == 1 + 2  # the header and one row per free motion
    (t_label, t_kind, t_dir, t_point, t_pitch), (r_label, r_kind, r_dir, r_point, r_pitch) = motions[1:]
    assert (t_label, t_kind, t_point, t_pitch) == ("T1 z", "translation", "", "")  # a translation has no axis
    assert (r_label, r_kind, r_pitch) == ("R1 z", "rotation", "")
    assert_allclose(vector(t_dir), [0, 0, 1], atol=1e-4)
    assert_allclose(vector(r_dir), [0, 0, 1], atol=1e-4)
    assert_allclose(vector(r_point), [0, 0, 0], atol=1e-4)
    assert page.summaries[:3] == ["platform", "singularity", "expected"] and "mechanism" in page.summaries
    assert page.pres[0].startswith("3-PUU-flat at 'flat': 2 DoF, 1T1R\n")
    assert "SINGULAR" in page.pres[1]  # every limb at a serial singularity (the hand derivation's twist rank 4 of 5)


def test_report_html_of_the_generic_3puu():
    """3-PUU at 'generic' (the seed paper's eq. 38): 3 DoF, 3T; three rows, translations along x, y and z."""
    page = parsed(pinmob.analyze(pinmob.load("3-PUU"), "generic")._repr_html_())
    facts, motions = dict(page.tables[0]), page.tables[1]
    assert facts["platform"] == "3 DoF, 3T"
    assert len(motions) == 1 + 3
    assert [row[1] for row in motions[1:]] == ["translation"] * 3
    assert all(row[3] == row[4] == "" for row in motions[1:])
    assert_allclose(np.array([vector(row[2]) for row in motions[1:]]), np.eye(3), atol=1e-4)


def test_report_html_without_limbs():
    """The Extended URDF five-bar with a ball (closures only): each output frame's DoF, no motion table, the text's sections."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # its meshes are not shipped
        report = pinmob.analyze(pinmob.load(FIVE_BAR), frames=["effector"])
    page = parsed(report._repr_html_())
    facts = dict(page.tables[0])
    assert len(page.tables) == 1 and "platform" not in facts and "singularity" not in facts
    assert facts["mechanism DoF"] == "2"  # 5 joints - closure rank 3 (derived in tests/test_external_robots.py)
    frames = report.mechanism_mobility.frames
    assert [f.frame for f in frames] == ["effector"]
    shown = facts["frame 'effector'"]
    assert shown == f"{frames[0].dof} DoF, {frames[0].motion_type}" and f"frame 'effector': {shown}" in str(report)
    assert page.summaries[:2] == ["closed configuration", "mechanism"]
    assert "mechanism DoF 2 (nv 5 - closure rank 3)" in page.pres[1]


def test_repr_pretty_is_the_text(flat_report):
    """IPython's text display is the printed report, not the dataclass's line of fields."""
    from IPython.lib.pretty import pretty

    assert pretty(flat_report) == str(flat_report)
    assert pretty([flat_report]).startswith("[3-PUU-flat at 'flat': 2 DoF, 1T1R\n")


def hostile_mechanism(tmp_path: Path) -> pinmob.Mechanism:
    """3-PUU-flat whose mechanism, limb, joint and configuration names are markup."""
    toml = (MODELS / "3puu_flat.toml").read_text()
    urdf = (MODELS / "3puu_flat.urdf").read_text()
    joint = "A<b>slider</b>&amp;"
    toml = toml.replace('name = "3-PUU-flat"', f'name = "{HOSTILE}"').replace('name = "A"', 'name = "<i>A</i>"')
    toml = (
        toml.replace('"A_slider"', f'"{joint}"')
        .replace("A_slider", f'"{joint}"')
        .replace("[configurations.flat]", '[configurations."<u>flat</u>"]')
    )
    (tmp_path / "3puu_flat.toml").write_text(toml)
    (tmp_path / "3puu_flat.urdf").write_text(urdf.replace('"A_slider"', f'"{html.escape(joint)}"'))
    mech = pinmob.load(tmp_path / "3puu_flat.toml")
    assert mech.name == HOSTILE and joint in mech.model.names
    return mech


def test_report_html_escapes_names_from_files(tmp_path):
    """A mechanism named <script>...: every name comes out as text, the only tags are the report's own."""
    report = pinmob.analyze(hostile_mechanism(tmp_path), "<u>flat</u>")
    out = report._repr_html_()
    page = parsed(out)
    assert {tag for tag, _ in page.tags} == {
        "div",
        "table",
        "tr",
        "th",
        "td",
        "p",
        "strong",
        "details",
        "summary",
        "pre",
    }
    assert "<script" not in out and "<i>" not in out and "<b>" not in out and "<u>" not in out
    assert dict(page.tables[0])["mechanism"] == HOSTILE and dict(page.tables[0])["configuration"] == "<u>flat</u>"
    assert page.pres[0].startswith(f"{HOSTILE} at '<u>flat</u>': 2 DoF, 1T1R\n")  # the names read back as text
    assert "limb (Type I): <i>A</i> SINGULAR" in page.pres[1] and "A<b>slider</b>&amp;" in page.pres[1]
    assert html.escape(HOSTILE, quote=True) in out  # escaped in the page, read back as the name


def test_viewer_in_a_cell_is_the_exported_page(flat_report):
    """notebook(report): the self-contained page of export_html in a sandboxed iframe, ASCII, no server."""
    cell = viewer.notebook(flat_report, height=300)
    assert cell.scene.clips == ("T1 z", "R1 z") and cell.scene.url is None and cell.scene.server is None
    out = cell._repr_html_()
    assert out.isascii()
    page = parsed(out)
    assert [tag for tag, _ in page.tags] == ["iframe"]
    attrs = page.tags[0][1]
    assert attrs["sandbox"] == "allow-scripts" and "height: 300px" in (attrs["style"] or "")
    assert attrs["srcdoc"] == cell.page  # the whole page, unescaped by the parser as a browser does
    assert cell.page.startswith("<!DOCTYPE html>") and "MeshCat.Viewer" in cell.page and "pinmob.install" in cell.page
    same = viewer.notebook(flat_report.state.mechanism, "flat", height=300)
    assert same.scene.clips == cell.scene.clips


@pytest.mark.parametrize(
    ("call", "message"),
    [
        (lambda m, r: viewer.notebook(m), "give the configuration to show '3-PUU-flat' at: joint values or a "),
        (lambda m, r: viewer.notebook(r, "flat"), "a Report carries its configuration"),
        (lambda m, r: viewer.notebook(r, height=0), "height must be a positive whole number of pixels, not 0"),
        (lambda m, r: viewer.notebook("3-PUU-flat", "flat"), "notebook shows a Report or a Mechanism, not a str"),
    ],
)
def test_viewer_in_a_cell_refuses_bad_input(flat_report, call, message):
    with pytest.raises(pinmob.ConfigurationError) as err:
        call(flat_report.state.mechanism, flat_report)
    assert str(err.value).startswith(message) and "\n" not in str(err.value)
    if "configuration to show" in message:
        assert "'flat', 'flat-raised'" in str(err.value)


def test_example_notebook_runs(tmp_path, monkeypatch):
    """examples/notebook.ipynb, stored without outputs, runs in a kernel of this interpreter; its Report shows as HTML."""
    import nbformat
    from ipykernel.kernelspec import write_kernel_spec
    from nbclient import NotebookClient

    nb = nbformat.read(NOTEBOOK, as_version=4)
    nbformat.validate(nb)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert all(c.outputs == [] and c.execution_count is None for c in code), "store the notebook without outputs"
    # a kernel spec of this interpreter, found first (JUPYTER_PATH): not whatever 'python3' the machine has
    kernels = tmp_path / "jupyter" / "kernels"
    spec = Path(write_kernel_spec(str(kernels / "pinmob-test")))
    assert json.loads((spec / "kernel.json").read_text())["argv"][0] == sys.executable
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    work = tmp_path / "work"
    work.mkdir()
    client = NotebookClient(
        nb, kernel_name="pinmob-test", timeout=600, resources={"metadata": {"path": str(work)}}, allow_errors=False
    )
    client.execute()  # raises CellExecutionError on any error
    outputs = {c.source.splitlines()[-1]: c.outputs for c in code}
    shown = outputs["report"][0]
    assert shown["output_type"] == "execute_result"
    report_html = parsed(shown["data"]["text/html"])
    assert dict(report_html.tables[0])["platform"] == "2 DoF, 1T1R"
    assert shown["data"]["text/plain"].startswith("3-PUU-flat at 'flat': 2 DoF, 1T1R\n  T1 z     translation")
    cell = outputs["pinmob.viewer.notebook(report, height=520)"][0]["data"]["text/html"]
    assert cell.startswith("<iframe ") and 'sandbox="allow-scripts"' in cell and len(cell) > 500_000
    assert list(work.iterdir()) == []  # nothing written beside the notebook
