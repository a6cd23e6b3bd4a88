"""Design-space sweeps: thousands of geometries, each with its mobility and a workspace scan, on Dask.

:mod:`~pinmob.sweeps.spec_file` reads a sweep spec (a built-in family with its
parameters, or a mechanism file as a template with ``{parameter}``
placeholders; a grid, random, Latin-hypercube or table design set; the scan of
each design as ``pinmob scan`` takes it) into a :class:`~pinmob.sweeps.sweep_spec.SweepSpec`;
:mod:`~pinmob.sweeps.designs` gives each design's values,
:mod:`~pinmob.sweeps.source` its mechanism, :mod:`~pinmob.sweeps.record` its
record (:mod:`~pinmob.sweeps.fields`); :func:`~pinmob.sweeps.sweep_run.sweep` runs them
in process or on Dask (:mod:`pinmob.parallel`); :mod:`~pinmob.sweeps.store` streams
the records to a resumable Parquet file; :mod:`~pinmob.sweeps.sweep_plot` draws the
atlas and the Pareto front. Dask and pyarrow are imported only when used.
"""

from pinmob.sweeps.spec_file import load_spec
from pinmob.sweeps.store import Store, read_records
from pinmob.sweeps.sweep_plot import plot_atlas, plot_pareto, written_by
from pinmob.sweeps.sweep_run import SweepRun, sweep
from pinmob.sweeps.sweep_spec import ScanSettings, SweepSpec

__all__ = [
    "ScanSettings",
    "Store",
    "SweepRun",
    "SweepSpec",
    "load_spec",
    "plot_atlas",
    "plot_pareto",
    "read_records",
    "sweep",
    "written_by",
]
