"""The viewer examples run headless (--html) and show their model; one asked for a model not built in says so."""

from __future__ import annotations

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

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
    """As the docstrings say: ``python examples/X.py --html FILE`` prints the model's mobility and writes FILE."""
    html = tmp_path / "x.html"
    out = subprocess.run(
        [sys.executable, str(EXAMPLES / script), "--html", str(html)], capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith(f"{model}"), out.stdout
    assert f"wrote {html}: clips " in out.stdout and html.stat().st_size > 100_000


def test_example_with_a_model_not_built_in_says_so(tmp_path, capsys):
    """The shared main of the examples refuses a model this pinmob does not have, in one line, exit status 2."""
    spec = importlib.util.spec_from_file_location("show_3puu", EXAMPLES / "3puu_show.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    assert module.main(["--html", str(tmp_path / "x.html")], model="no-such-robot") == 2
    err = capsys.readouterr().err
    assert err.startswith("error: this pinmob has no built-in model 'no-such-robot'; it has: ") and "3-PUU" in err
    assert list(tmp_path.iterdir()) == []
