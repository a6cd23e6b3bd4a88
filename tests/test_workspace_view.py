"""The 3D workspace of a scan (pinmob.viewer.workspace): points, colours and marks against the scan's rows.

The colours are checked against matplotlib's viridis (the scale's nine stops are viridis at 0, 1/8, ...
1, interpolated in log10 of the distance between the samples' smallest and largest distance); the
singular marks against the rule of docs/singularities.md (a class is present exactly when the distance is
at most rtol); the mechanism at a chosen sample against Pinocchio's forward kinematics of the row's joint
values. The browser test of the page is in tests/test_browser.py.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest
from numpy.testing import assert_allclose

import pinmob
from pinmob.scan import grid_spec, scan
from pinmob.viewer.workspace import (
    CHOSEN_COLOR,
    REFINED_COLOR,
    SCALE,
    SINGULAR_COLOR,
    distance_colors,
    sample_configuration,
    workspace_cloud,
)

#: a small 3D grid of the 3-PUU: 75 samples, 3 singular (limb A stretched at x = -0.1, y = 0), refined points
GRID = [("z", 0.22, 0.34, 3), ("x", -0.1, 0.1, 5), ("y", -0.1, 0.1, 5)]


@pytest.fixture(scope="module")
def puu():
    mech = pinmob.load("3-PUU")
    spec = grid_spec(mech, "generic", GRID)
    return mech, spec, list(scan(mech, spec, progress=False))


def test_points_colours_and_marks_follow_the_rows(puu):
    from matplotlib import colormaps

    _, spec, rows = puu
    ws = workspace_cloud(rows, spec.rtol, chosen=None)
    reach = [r for r in rows if r["reachable"] and not r["refined"]]
    assert ws.total == 75 and len(ws.positions) == len(reach) > 0
    assert_allclose(ws.positions, [[r["x"], r["y"], r["z"]] for r in reach])
    d = np.array([r["distance"] for r in reach])
    lo, hi = d[d > spec.rtol].min(), d.max()  # the singular samples (marked) do not stretch the scale
    assert (ws.lo, ws.hi) == (lo, hi)
    t = (np.log10(np.clip(d, lo, hi)) - np.log10(lo)) / (np.log10(hi) - np.log10(lo))
    assert_allclose(ws.colors, colormaps["viridis"](t)[:, :3], atol=0.07)  # nine stops of viridis, linear between
    ends = [np.argmin(np.where(d > spec.rtol, d, np.inf)), np.argmax(d)]
    rgb = [np.array([(c >> 16) & 255, (c >> 8) & 255, c & 255]) / 255 for c in (SCALE[0], SCALE[-1])]
    assert_allclose(ws.colors[ends], rgb)  # the scale's ends are the samples' extremes
    singular = [r for r in reach if r["distance"] <= spec.rtol]
    assert len(singular) == 3 and all(r["x"] == pytest.approx(-0.1) and abs(r["y"]) < 1e-9 for r in singular)
    assert_allclose(ws.singular, [[r["x"], r["y"], r["z"]] for r in singular])
    refined = [r for r in rows if r["refined"] and r["reachable"]]
    assert len(refined) > 0 and len(ws.refined) == len(refined)
    assert all(r["distance"] <= spec.rtol for r in refined)
    legend = ws.legend()
    assert legend["count"] == len(reach) and legend["total"] == 75
    assert "[m]" in legend["points"] and "dimensionless" in legend["scale"]["words"]
    marks = " ".join(m["text"] for m in legend["marks"])
    assert "singular sample" in marks and f"refined singular point: {len(refined)}" in marks
    assert {m["color"] for m in legend["marks"]} == {f"#{SINGULAR_COLOR:06x}", f"#{REFINED_COLOR:06x}"}


def test_distance_colors_on_a_log_scale():
    colors = distance_colors(np.array([1e-9, 1e-4, 1e-2, 1.0, 5.0]), 1e-4, 1.0)
    stops = np.array([[(c >> 16) & 255, (c >> 8) & 255, c & 255] for c in SCALE]) / 255
    assert_allclose(colors, stops[[0, 0, 4, 8, 8]])  # 1e-2 is half-way from 1e-4 to 1 in log10
    assert_allclose(distance_colors(np.array([0.3]), 0.3, 0.3), stops[[8]])


def test_the_mechanism_at_a_chosen_sample(puu):
    mech, spec, rows = puu
    k = next(r["index"] for r in rows if r["reachable"] and not r["refined"] and r["singularity"] == "none")
    conf = sample_configuration(mech, rows, k, spec.q_ref)
    row = next(r for r in rows if r["index"] == k and not r["refined"])
    data = mech.model.createData()
    pin.framesForwardKinematics(mech.model, data, conf.q)
    assert_allclose(data.oMf[mech.platform_id].translation, [row["x"], row["y"], row["z"]], atol=1e-9)
    ws = workspace_cloud(rows, spec.rtol, chosen=k)
    assert_allclose(ws.chosen, [row["x"], row["y"], row["z"]])
    assert ws.legend()["marks"][-1]["color"] == f"#{CHOSEN_COLOR:06x}"
    lost = next(r["index"] for r in rows if not r["reachable"])
    with pytest.raises(pinmob.ConfigurationError, match=f"`index={lost}`: that sample was not assembled; valid: "):
        sample_configuration(mech, rows, lost, spec.q_ref)


def cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "pinmob", *args], capture_output=True, text=True, timeout=300)


def test_cli_view_options_refused_in_one_line(tmp_path):
    grid = ["--grid", "x:-0.1:0.1:3", "y:-0.1:0.1:3"]
    for extra, message in (
        (
            ["--sample", "3"],
            "--sample K chooses the sample the 3D view draws the mechanism at: add --show or --html "
            "(a path's number of samples is --samples N, or -n N)",
        ),  # before, --sample abbreviated --samples
        (["--show", "--html", str(tmp_path / "w.html")], "--show uses a meshcat server, --html writes a file"),
    ):
        proc = cli("scan", "3-PUU", *grid, *extra)
        assert proc.returncode == 2 and message in proc.stderr and "Traceback" not in proc.stderr
    proc = cli("scan", "3-PUU", *grid, "--html", str(tmp_path / "w.html"), "--sample", "999", "--json",
               str(tmp_path / "w.json"))  # fmt: skip
    assert proc.returncode == 2 and "--sample 999: that sample is not an index of the scan; valid: " in proc.stderr
    assert not (tmp_path / "w.html").exists()
    samples = json.loads((tmp_path / "w.json").read_text())["samples"]
    assert len(samples) >= 9
