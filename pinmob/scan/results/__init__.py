"""What a scan gives back: its rows as columns, the files they are written to, the report, and the plots.

:mod:`~pinmob.scan.results.table` (:class:`ScanTable`: one array per column), :mod:`~pinmob.scan.results.output`
(rows streamed to CSV, JSON and Parquet, and columns read back), :mod:`~pinmob.scan.results.scan_report`
(:class:`ScanReport`, what :func:`pinmob.scan.scan` returns), :mod:`~pinmob.scan.results.scan_plot` (PNG plots
along a path) and :mod:`~pinmob.scan.results.workspace_map` (PNG maps of grids). Their names are exported by
:mod:`pinmob.scan`; this subpackage's ``__init__`` imports nothing, so the scan's engine can use its modules
without loading the others.
"""
