"""``pinmob sweep``: a design-space sweep, each design's mobility and workspace scan, to Parquet, CSV and plots."""

from __future__ import annotations

import argparse
import csv
import tempfile
import time
from collections import Counter
from pathlib import Path
from typing import Any

from pinmob.cli.common import check_distinct, signals_interrupt
from pinmob.exceptions import ConfigurationError
from pinmob.output_files import Replacing, check_target
from pinmob.sweeps import Store, SweepSpec, load_spec, plot_atlas, plot_pareto, read_records, sweep, written_by


def run(args: argparse.Namespace) -> int:
    """``pinmob sweep``: SIGTERM and SIGHUP stop it as Ctrl-C does, with the records so far kept (resumable)."""
    with signals_interrupt():
        return _run(args)


def _run(args: argparse.Namespace) -> int:
    spec = load_spec(args.spec)
    spec.check_count()
    if args.out and Path(args.out).suffix.lower() != ".parquet":
        raise ConfigurationError(
            f"--out {args.out!r}: the records go to a Parquet file; give a name ending in .parquet"
        )
    plots = _plot_targets(args, spec)
    check_distinct({"--out": args.out, "--csv": args.csv} | {f"--{name}": png for name, png in plots.items()})
    for name, png in plots.items():
        ours = png.is_file() and not png.is_symlink() and written_by(png) == f"pinmob sweep {spec.identity()}"
        check_target(f"--{name}", png, args.force or ours)
    if args.csv:
        check_target("--csv", args.csv, args.force)
    with tempfile.TemporaryDirectory(prefix="pinmob-sweep-") as scratch:
        out = Path(args.out) if args.out else Path(scratch) / "records.parquet"
        store = Store(out, spec, force=args.force)
        records = sweep(spec, args.workers, args.scheduler, False if args.no_progress else None, store.done)
        source = f"family {spec.source.family!r}" if spec.source.family else f"template {spec.source.name!r}"
        print(f"sweep {spec.name!r}: {spec.count} designs ({spec.designs.describe()}) of {source}")
        print(f"  per design: {spec.scan.describe()}")
        if spec.finite_order is not None:
            print(
                f"  and the finite-mobility analysis at the reference configuration (order bound {spec.finite_order})"
            )
        counts: Counter[str] = Counter()
        reasons: Counter[str] = Counter()
        t0 = time.perf_counter()
        try:
            with store:
                if store.resumed:
                    print(f"resuming {out}: {store.resumed} of {spec.count} designs already written, skipped")
                elif args.force and args.out:
                    print(f"starting over (--force): {out} is replaced when this run publishes its records")
                for record in records:
                    store.write(record)
                    _tally(record, counts, reasons)
        except KeyboardInterrupt:
            if args.out:
                again = " without --force" if args.force else ""
                resume = f" (marked incomplete); run the same command{again} to resume" if store.in_file else ""
                print(f"interrupted: {store.state()}{resume}")
            raise
        elapsed = time.perf_counter() - t0
        _summary(spec, counts, reasons, store.written, elapsed, records.where, records.lost_workers)
        if args.out:
            state = "complete" if store.complete else "incomplete"
            print(f"records: {out} ({int(store.done.sum())} of {spec.count} designs, {state})")
        if args.csv:
            _write_csv(out, Path(args.csv), spec)
            print(f"csv: {args.csv}")
        for name, png in plots.items():
            (plot_atlas if name == "atlas" else plot_pareto)(out, png, spec)
            print(f"{name}: {png}")
    return 0


def _plot_targets(args: argparse.Namespace, spec: SweepSpec) -> dict[str, Path]:
    """The plots to write: --atlas/--pareto, else beside --out (STEM_atlas.png, STEM_pareto.png)."""
    if args.no_plots:
        return {}
    out = Path(args.out) if args.out else None
    wanted = {
        "atlas": args.atlas or (out.with_name(out.stem + "_atlas.png") if out and "atlas" in spec.plots else None),
        "pareto": args.pareto or (out.with_name(out.stem + "_pareto.png") if out else None),
    }
    targets = {}
    for name, png in wanted.items():
        if png is None:
            continue
        if name not in spec.plots:
            raise ConfigurationError(
                f"--{name}: the sweep sweeps fewer than two parameters; give [plots.atlas] x and y"
            )
        png = Path(png)
        if png.suffix.lower() != ".png":
            raise ConfigurationError(f"--{name} {str(png)!r}: the plot is a PNG image; give a file name ending in .png")
        targets[name] = png
    return targets


def _tally(record: dict[str, Any], counts: Counter[str], reasons: Counter[str]) -> None:
    if record["status"] == "ok":
        counts[f"{record['dof']} DoF {record['motion_type']}"] += 1
    else:
        counts["failed"] += 1
        reasons[record["reason"]] += 1


def _summary(spec: SweepSpec, counts: Counter[str], reasons: Counter[str], n: int, elapsed: float, where: str,
             lost: int) -> None:  # fmt: skip
    rate = n / elapsed if elapsed > 0 else 0.0
    print(f"{n} designs computed in {elapsed:.1f} s ({rate:.2f} designs/s, {where})")
    if lost:
        print(f"  {lost} worker(s) lost and replaced; their designs were computed again")
    for key, k in sorted(counts.items()):
        print(f"  {k:5d} x {key}" + (" at the reference configuration" if key != "failed" else ""))
    for reason, k in reasons.most_common(3):
        print(f"        {k} x {reason[:160]}")
    if len(reasons) > 3:
        print(f"        ... ({len(reasons) - 3} other reasons in the records)")


def _write_csv(parquet: Path, target: Path, spec: SweepSpec) -> None:
    """The records as CSV (blank for missing values), through a temporary file renamed at the end."""
    names = [n for n, _ in spec.fields()]
    replacing = Replacing(target)
    with replacing as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, names)
        writer.writeheader()
        for record in read_records(parquet):
            writer.writerow(
                {k: ("" if v is None else f"{v:.10g}" if isinstance(v, float) else v) for k, v in record.items()}
            )
        fh.flush()
        replacing.commit()
