"""The garbage collector's automatic passes paused while a scan's group of samples runs.

A group (:func:`pinmob.scan.lockstep.run_group`) makes a dozen small objects a sample (its pending entry, head,
row and joint values) that live until the group's table is made: tens of thousands of allocations that trigger
the collector's passes, and its full passes walk every object of the process (Pinocchio's, numpy's, numba's and
pinmob's modules). A 41 x 41 scan of the 3-PUU spent about 5 ms of its 52 in the collector, with hardly a reference
cycle to find (5 objects a scan): what a group makes is freed by reference counting.

:data:`collector_paused` (a context manager and a decorator) disables the automatic passes for the duration of
the block and enables them again when the outermost block ends, if they were enabled when it began: a collector
the user disabled stays disabled, and nested or concurrent blocks (Dask's threads) keep it paused until the last
one leaves. ``gc.collect()`` still runs when called. The objects are the same and so are the results; only when
the collector runs changes. Where a block makes reference cycles, the collector frees them only once it ends: a
scan with finite DoF (each sample's finite analysis refers back to its configuration) runs its groups unpaused.
"""

from __future__ import annotations

import gc

from pinmob.held_setting import HeldSetting


class _CollectorPaused(HeldSetting):
    """Re-entrant, thread-safe pause of the collector's automatic passes (see the module docstring)."""

    def __init__(self) -> None:
        super().__init__()
        self._was_enabled = False

    def _hold(self) -> None:
        self._was_enabled = gc.isenabled()
        gc.disable()

    def _release(self) -> None:
        if self._was_enabled:
            gc.enable()


#: ``with collector_paused:`` or ``@collector_paused``: no automatic garbage collection inside the block.
collector_paused = _CollectorPaused()
