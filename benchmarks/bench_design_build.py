"""What building one design of a sweep costs: ``Source.mechanism`` for every design of the example sweep.

For each design of ``examples/3puu_sweep.toml`` that builds (45 of its 49), the CPU time (``time.process_time``,
best of ``--runs``) per design of:

* ``Source.mechanism``: the design's files built, written into a folder and loaded (what a sweep does);
* ``files``: ``Source.files`` alone (the family's builder, its URDF and TOML texts);
* ``write``: writing those files;
* ``load``: the rest of ``Source.mechanism`` (loading the written files), its total minus the two above.

``--profile`` adds cProfile's table of three passes over the designs (sorted by own time).

    python benchmarks/bench_design_build.py [--runs 7] [--profile]
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import tempfile
import time
from pathlib import Path

import pinmob

EXAMPLE = Path(__file__).resolve().parent.parent / "examples" / "3puu_sweep.toml"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--profile", action="store_true")
    args = parser.parse_args()

    spec = pinmob.load_spec(EXAMPLE)
    source = spec.source
    designs = []
    for i in range(spec.count):
        try:
            source.files(spec.values(i))
        except pinmob.ConfigurationError:  # links too short for the guides' radius: a failed record, not built
            continue
        designs.append(spec.values(i))

    def whole(folder: Path) -> float:
        t0 = time.process_time()
        for values in designs:
            source.mechanism(values, folder)
        return (time.process_time() - t0) / len(designs)

    def parts(folder: Path) -> tuple[float, float]:
        files = write = 0.0
        for values in designs:
            t0 = time.process_time()
            texts = source.files(values)
            t1 = time.process_time()
            for name, text in texts.items():
                (folder / name).write_text(text, encoding="utf-8")
            files, write = files + t1 - t0, write + time.process_time() - t1
        return files / len(designs), write / len(designs)

    with tempfile.TemporaryDirectory(prefix="pinmob-bench-") as tmp:
        folder = Path(tmp)
        whole(folder)  # warm-up: imports, caches
        total = min(whole(folder) for _ in range(args.runs))
        files, write = (min(x) for x in zip(*(parts(folder) for _ in range(args.runs)), strict=True))
        print(
            f"{len(designs)} designs of {spec.count} that build, CPU ms per design, best of {args.runs}: "
            f"Source.mechanism {total * 1e3:.3f} (files {files * 1e3:.3f}, write {write * 1e3:.3f}, "
            f"load {(total - files - write) * 1e3:.3f})"
        )
        if args.profile:
            profile = cProfile.Profile()
            profile.runcall(lambda: [whole(folder) for _ in range(3)])
            pstats.Stats(profile).sort_stats("tottime").print_stats(25)


if __name__ == "__main__":
    main()
