"""Time to load and analyse a mechanism file that names many configurations (a recorded trajectory).

The file is the built-in 3-PUU (its URDF beside it) with its ``generic`` configuration first and N platform
poses after it (``c0`` ... on a small circle, every one reachable). For N = 2,000 and 20,000 it prints,
side by side:

* ``parse``: ``tomllib.loads`` of the text alone (the reference: nothing pinmob does can be faster);
* ``load``: :func:`pinmob.load` (the parse, the URDF, every configuration checked);
* ``analyze``: ``pinmob analyze FILE`` in process (the default configuration, the first, and the whole
  printed report, generic ranks included).

Linear time shows as ``load`` and ``analyze`` growing as ``parse`` does (x10 for 10 times the configurations,
with a constant for the URDF and the analysis); before the fix, analysing the default configuration looked up
every name in a list (quadratic) and assembled every pose for the generic ranks.

Usage: ``python benchmarks/bench_loading.py [--sizes 2000 20000]``; the last line printed is one JSON object.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import shutil
import tempfile
import time
import tomllib
from pathlib import Path

import pinmob
from pinmob.cli import main
from pinmob.io.builtin import builtin_models


def write_file(folder: Path, n: int) -> Path:
    """The 3-PUU's file with its ``generic`` configuration and ``n`` pose configurations ``c0``..., in ``folder``."""
    source = builtin_models()["3-PUU"]
    text = source.read_text()
    head = text[: text.index("[configurations.")]
    shutil.copy(source.with_suffix(".urdf"), folder / source.with_suffix(".urdf").name)
    parts = [head, "[configurations.generic]\njoints = { A_slider = 0.0, B_slider = 0.0, C_slider = 0.0 }\n"]
    for k in range(n):
        a = 2 * math.pi * k / n
        parts.append(
            f"[configurations.c{k}]\npose = {{ xyz = [{0.03 * math.cos(a):.6f}, {0.03 * math.sin(a):.6f}, -0.17] }}\n"
        )
    path = folder / f"many_{n}.toml"
    path.write_text("\n".join(parts))
    return path


def timed(work: object) -> float:
    """Seconds taken by ``work()``."""
    t0 = time.perf_counter()
    work()  # type: ignore[operator]
    return time.perf_counter() - t0


def measure(n: int) -> dict[str, float]:
    """Seconds to parse, load and analyse the file with ``n`` configurations, and its size in MB."""
    with tempfile.TemporaryDirectory() as tmp:
        path = write_file(Path(tmp), n)
        text = path.read_text()
        parse = timed(lambda: tomllib.loads(text))
        load = timed(lambda: pinmob.load(path))
        with contextlib.redirect_stdout(io.StringIO()) as out:
            analyze = timed(lambda: main(["analyze", str(path)]))
        assert "3-PUU at 'generic': 3 DoF, 3T" in out.getvalue()
        return {"configurations": n, "MB": len(text) / 1e6, "parse_s": parse, "load_s": load, "analyze_s": analyze}


def cli() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[2000, 20000])
    args = parser.parse_args()
    rows = [measure(n) for n in args.sizes]
    print(f"{'configurations':>14} {'MB':>6} {'parse [s]':>10} {'load [s]':>9} {'analyze [s]':>12}")
    for r in rows:
        print(
            f"{r['configurations']:>14} {r['MB']:>6.2f} {r['parse_s']:>10.3f} {r['load_s']:>9.3f} {r['analyze_s']:>12.3f}"
        )
    print(json.dumps(rows))


if __name__ == "__main__":
    cli()
