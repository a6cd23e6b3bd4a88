"""A mechanism file that names thousands of configurations (a recorded trajectory) loads and analyses right.

The time it takes is measured by ``benchmarks/bench_loading.py`` (2,000 and 20,000 configurations side by
side, against the parse alone), not here.
"""

from __future__ import annotations

import math
import shutil
from pathlib import Path

import pytest
from numpy.testing import assert_allclose

import pinmob
import pinmob.assembly.named_assembly as named
from pinmob.io.builtin import builtin_models

N = 3000


def poses(n: int) -> list[tuple[float, float, float]]:
    """``n`` platform positions of the 3-PUU on a circle of 3 cm around its axis, 17 cm below the guides' tops."""
    return [(0.03 * math.cos(2 * math.pi * k / n), 0.03 * math.sin(2 * math.pi * k / n), -0.17) for k in range(n)]


def many(tmp_path: Path, n: int = N) -> Path:
    """The built-in 3-PUU's file with its ``generic`` joint values first and ``n`` pose configurations ``c0``..."""
    source = builtin_models()["3-PUU"]
    text = source.read_text()
    shutil.copy(source.with_suffix(".urdf"), tmp_path / source.with_suffix(".urdf").name)
    parts = [text[: text.index("[configurations.")]]
    parts.append("[configurations.generic]\njoints = { A_slider = 0.0, B_slider = 0.0, C_slider = 0.0 }\n")
    parts += [
        f"[configurations.c{k}]\npose = {{ xyz = [{x!r}, {y!r}, {z!r}] }}\n" for k, (x, y, z) in enumerate(poses(n))
    ]
    path = tmp_path / "trajectory.toml"
    path.write_text("\n".join(parts))
    return path


def test_many_configurations_load_in_order_and_the_default_is_the_first(tmp_path, monkeypatch):
    """3,000 configurations: every name kept in file order, the default is the first (``generic``: 3 DoF 3T,
    Zhao et al. eq. 38 for this 3-PUU), a name is found in any case, and a pose configuration puts the platform
    where the file says. Analysing the default assembles a few of the poses (``MAX_NAMED``) (for the generic
    ranks): the old code assembled all 3,000 there (and looked each name up in a list of all of them)."""
    path = many(tmp_path)
    mech = pinmob.load(path)
    assert list(mech.configurations) == ["generic"] + [f"c{k}" for k in range(N)]
    assembled: list[str] = []
    real = named.assemble_pose

    def counted(*args, **kwargs):  # the real assembly, counted
        assembled.append("pose")
        return real(*args, **kwargs)

    monkeypatch.setattr(named, "assemble_pose", counted)
    report = pinmob.analyze(mech)
    text = str(report)  # the whole report: singularity distances and generic ranks included
    assert report.configuration == "generic" and text.startswith("3-PUU at 'generic': 3 DoF, 3T")
    assert len(assembled) <= 10  # a few for the generic ranks (MAX_NAMED), not one per configuration
    assert mech.configuration_name("C2345") == "c2345"
    conf = pinmob.Configuration(mech, "c2345")
    assert_allclose(conf.platform_origin, poses(N)[2345], atol=1e-9)
    assert pinmob.analyze(mech, "c2345").mobility.dof == 3
    with pytest.raises(pinmob.ConfigurationError, match="no configuration 'c3000'"):
        mech.configuration_name("c3000")
