"""The viewer examples run headless (--html); the ones for models not built in yet say so."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import pinmob

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


@pytest.mark.parametrize(
    ("script", "model"),
    [
        ("3puu_show.py", "3-PUU-flat"),
        ("3puu_translational_show.py", "3-PUU"),
        ("spherical_show.py", "3-RRR-spherical"),
        ("schoenflies_show.py", "4-RUU"),
    ],
)
def test_example_writes_html(script, model, tmp_path):
    out = subprocess.run(
        [sys.executable, str(EXAMPLES / script), "--html", str(tmp_path / "x.html")],
        capture_output=True,
        text=True,
        timeout=120,
    )
    if model in pinmob.builtin_models():
        assert out.returncode == 0, out.stderr
        assert (tmp_path / "x.html").exists() and "wrote" in out.stdout
    else:
        assert out.returncode == 2 and f"no built-in model {model!r}" in out.stderr
