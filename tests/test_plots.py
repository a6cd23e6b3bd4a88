"""Scan plots a designer can read: units on every axis, a legend for every colour, no empty panel."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.scan.results import scan_plot as plot
from pinmob.scan.results import workspace_map as plot_map
from pinmob.scan.results.output import RowWriter, read_columns
from pinmob.scan.scan_run import columns, scan
from pinmob.scan.scan_spec import grid_spec, path_spec

UNIT = re.compile(r"\[(m|rad)\]")


def scanned(mech: pinmob.Mechanism, spec, path: Path) -> Path:
    with RowWriter(columns(spec), {}, str(path)) as writer:
        for row in scan(mech, spec, progress=False):
            writer.write(row)
    return path


def legend_labels(ax) -> list[str]:
    legend = ax.get_legend()
    return [t.get_text() for t in legend.get_texts()] if legend else []


def test_a_yaw_path_is_drawn_against_yaw_in_radians_without_an_empty_panel(tmp_path):
    # the 6-UPS has no constraint wrench (six 6-DoF limbs): no panel for that empty matrix;
    # the path turns the platform from yaw 0 to 2.0944 rad about its own origin, nothing else changes
    mech = pinmob.load("6-UPS")
    spec = path_spec(mech, "home", "0,0,0.4,0,0,2.0944", 7)
    c = read_columns(scanned(mech, spec, tmp_path / "p.csv"), plot.PATH_COLUMNS)
    axis = plot.path_abscissa(c, mech.length_scale)
    assert axis.label == "platform yaw [rad]"
    assert_allclose(axis.values[c["refined"] == 0], np.linspace(0, 2.0944, 7), atol=1e-9)
    fig = plot.path_figure(c, abscissa=axis)
    titled = [ax for ax in fig.axes if ax.get_title()]
    assert [ax.get_title() for ax in titled] == ["actuation: stacked locked-limb wrenches (actuators locked)"]
    assert not any("no wrench" in t.get_text() for ax in fig.axes for t in ax.texts)
    assert [ax.get_xlabel() for ax in fig.axes if ax.get_xlabel()] == ["platform yaw [rad]"]
    assert [ax.get_xlabel() for ax in fig.axes[0].child_axes] == ["path parameter s"]  # the top axis
    for ax in fig.axes:
        if ax.get_ylabel() and "relative" not in ax.get_ylabel():
            assert "DoF" in ax.get_ylabel() or "distance" in ax.get_ylabel()
    distance = next(ax for ax in fig.axes if ax.get_ylabel().startswith("distance"))
    line = next(ln for ln in distance.lines if ln.get_label() == "distance to singularity")
    assert_allclose(line.get_xdata(), np.linspace(0, 2.0944, 7), atol=1e-9)
    assert "platform DoF (right axis)" in legend_labels(distance)


def test_a_joint_path_is_drawn_against_the_joint_varying_most(tmp_path):
    mech = pinmob.load("3-PUU")
    spec = path_spec(mech, "generic", "offset", 5, joints=True)
    joint = plot.varied_joint(mech, spec)
    a, b = spec.a, spec.b
    k = int(np.argmax(np.abs(np.asarray(b) - np.asarray(a))))  # all three are sliders [m]
    assert joint == (mech.actuated[k], "m", a[k], b[k])
    png = tmp_path / "j.png"
    plot.plot_path(scanned(mech, spec, tmp_path / "j.csv"), png, rtol=1e-6, joint=joint)
    assert png.read_bytes()[:4] == b"\x89PNG"
    c = read_columns(tmp_path / "j.csv", plot.PATH_COLUMNS)
    assert plot.path_abscissa(c, joint=joint).label == f"actuated joint {mech.actuated[k]} [m]"


def test_unreachable_samples_have_a_legend_entry_on_paths_and_maps(tmp_path):
    # 3-PUU from 'generic' to x = 0.3 m: the far end cannot be assembled
    mech = pinmob.load("3-PUU")
    spec = path_spec(mech, "generic", "0.3,0,-0.2,0,0,0", 6)
    c = read_columns(scanned(mech, spec, tmp_path / "p.csv"), plot.PATH_COLUMNS)
    assert (c["reachable"] == 0).any()
    fig = plot.path_figure(c, abscissa=plot.path_abscissa(c, mech.length_scale))
    distance = next(ax for ax in fig.axes if ax.get_ylabel().startswith("distance"))
    assert "not assembled" in legend_labels(distance)
    assert next(ax.get_xlabel() for ax in fig.axes if ax.get_xlabel()) == "platform x [m]"

    # a grid over x and yaw would be refused: the 3-PUU (3T) cannot turn (pinmob.scan.coordinates); the 3-PRS can.
    # Rolled by +-3 rad its platform is nearly upside down, which its fixed 0.31 m links do not reach (neither
    # engine assembles it). The 3-RPS, whose legs are unbounded sliders, does assemble there: the batched engine
    # finds it at roll 3 rad, where the single-sample solver stopped short from its warm start.
    prs = pinmob.load("3-PRS")
    grid = grid_spec(prs, "home", [("roll", -3.0, 3.0, 5), ("z", 0.0, 0.4, 3)])
    cols = read_columns(scanned(prs, grid, tmp_path / "g.csv"), ["grid_roll", "grid_z", *plot_map.MAP_COLUMNS])
    assert (cols["reachable"] == 0).any()
    fig = plot_map.map_figure(cols, ["grid_roll", "grid_z"])
    maps = [ax for ax in fig.axes if ax.get_title()]
    assert len(maps) == 2
    for ax in maps:
        assert (ax.get_xlabel(), ax.get_ylabel()) == ("platform roll [rad]", "platform z [m]")
        assert "not assembled (blank)" in legend_labels(ax)
    colorbars = [ax for ax in fig.axes if not ax.get_title()]
    assert any(UNIT.search(ax.get_ylabel()) is None and "distance" in ax.get_ylabel() for ax in colorbars)


@pytest.mark.parametrize("grid", [False, True])
def test_the_cli_writes_plots_with_units(tmp_path, grid, capsys):
    from pinmob.cli import main

    png = tmp_path / "out.png"
    args = ["scan", "3-PUU", "--plot", str(png), "--no-progress"]
    args += (
        ["--grid", "x:-0.05:0.05:3", "y:-0.05:0.05:3"] if grid else ["--from", "generic", "--to", "offset", "-n", "4"]
    )
    assert main(args) == 0
    assert png.read_bytes()[:4] == b"\x89PNG" and f"plot: {png}" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("name", "start", "end", "n"),
    [("6-UPS", "home", "0,0,0.4,0,0,2.0944", 7), ("3-PUU", "generic", "-0.12,0,-0.2,0,0,0", 12)],
)
def test_the_top_s_axis_stands_over_the_samples(tmp_path, name, start, end, n):
    """The path plot's top axis (path parameter s) puts every row's s over that row's abscissa below, refined
    rows too, read through matplotlib's transforms (display x of s on the top axis, of the abscissa on the
    bottom one); the 3-PUU's x decreases along its path, so its axis runs right to left. Before, the top axis
    clamped s at the plot's margins (np.interp), so s = 0 and 1 sat at the edges, 13 px off the end samples."""
    mech = pinmob.load(name)
    spec = path_spec(mech, start, end, n)
    c = read_columns(scanned(mech, spec, tmp_path / "p.csv"), plot.PATH_COLUMNS)
    assert (c["refined"] == 1).any()
    axis = plot.path_abscissa(c, mech.length_scale)
    fig = plot.path_figure(c, abscissa=axis)
    fig.canvas.draw()
    ax = fig.axes[0]
    (top,) = ax.child_axes
    assert top.get_xlabel() == "path parameter s"
    assert ax.xaxis_inverted() == (name == "3-PUU")
    zero = np.zeros_like(c["s"])
    below = ax.transData.transform(np.column_stack([axis.values, zero]))[:, 0]
    above = top.transData.transform(np.column_stack([c["s"], zero]))[:, 0]
    assert_allclose(above, below, atol=0.5)  # pixels


def test_a_map_over_revolute_joints_has_units_and_colour_bars(tmp_path):
    """A 3-RPS grid over its passive revolute joints A_r and B_r: both maps label their axes ``joint A_r [rad]``
    and ``joint B_r [rad]`` (the units as the CLI gives them) and carry a colour bar: the motion types by name,
    and the distance to singularity (dimensionless: no unit) with the rtol and near-singular lines."""
    from pinmob.scan.coordinates import coordinate_unit

    rps = pinmob.load("3-RPS")
    grid = grid_spec(rps, "home", [("A_r", -0.1, 0.1, 3), ("B_r", -0.1, 0.1, 3)])
    keys = ["grid_A_r", "grid_B_r"]
    cols = read_columns(scanned(rps, grid, tmp_path / "r.csv"), [*keys, *plot_map.MAP_COLUMNS])
    types = sorted(set(cols["motion_type"][cols["reachable"] == 1]))
    assert types
    fig = plot_map.map_figure(cols, keys, units={k[5:]: coordinate_unit(rps, k[5:]) for k in keys})
    maps = [ax for ax in fig.axes if ax.get_title()]
    assert [(ax.get_xlabel(), ax.get_ylabel()) for ax in maps] == [("joint A_r [rad]", "joint B_r [rad]")] * 2
    bars = [ax for ax in fig.axes if not ax.get_title()]
    assert len(bars) == 2
    assert [t.get_text() for t in bars[0].get_yticklabels()] == types
    assert bars[1].get_ylabel() == "distance to singularity ($\\sigma_r / \\sigma_1$)" and len(bars[1].lines) == 2
