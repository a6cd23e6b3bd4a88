"""The small 3-PUU sweep the sweep tests run: a grid of link lengths and base radii, a workspace grid each."""

from __future__ import annotations

SPEC = """
title = "{title}"
family = "3-PUU"
[parameters]
small_r = 0.15
[design]
method = "grid"
[design.parameters]
link = [{lo}, {hi}, {n}]
big_r = [0.25, 0.4, {n}]
[scan]
grid = ["x:-0.05:0.05:{m}", "y:-0.05:0.05:{m}"]
at = "generic"
"""
