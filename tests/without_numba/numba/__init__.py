"""numba made absent: with this folder first on ``PYTHONPATH`` (``.ci/run``'s pass without numba), ``import numba``
fails in every process, the Dask workers included, as where the optional ``fast`` extra is not installed."""

raise ImportError("numba is not installed here (tests/without_numba: the test pass without the optional fast extra)")
