"""The sweep's Parquet file: streamed, resumable, never left corrupt by an interruption.

Records go, as they come and in design order, to a journal beside the target
(``.NAME.pinmob-journal``, Arrow IPC stream batches: the first record at once, then every
``BATCH_RECORDS`` records or ``BATCH_SECONDS`` seconds). Leaving the :class:`Store`
merges the target's records (when they are this sweep's and kept) with the journal's,
by design index, into a temporary Parquet file in the target's folder (row groups of
``ROW_GROUP`` records, so the same records make the same file), renames it over the
target and removes the journal. The target is thus only ever replaced whole: an
interruption that pinmob handles (Ctrl-C, SIGTERM, SIGHUP, an error) publishes the
records so far, marked incomplete (signals during the merge are held back until it
ends: :func:`pinmob.signals.deferred_interrupts`); one it cannot handle (SIGKILL, a power
cut) leaves the previous file as it was and the journal, whose complete batches the next
run recovers. Nothing is published while no record exists: an interruption before the
first design leaves the target as it was (or absent). Memory is flat in the number of
designs: records stream through batches; a byte per design says which are written.

The file's schema metadata ``pinmob.sweep`` (JSON) holds the sweep's identity
(:meth:`~pinmob.sweeps.sweep_spec.SweepSpec.identity`: the spec and pinmob's code), the
spec's own digest, pinmob's version, the number of designs, how many are written
and whether it is complete. The rule for an existing target:

- without ``force``: a file of this sweep (same identity) is resumed, the designs
  written skipped, and a journal this sweep left (SIGKILL) recovered first; any other
  file (another sweep's, this spec's computed by another pinmob, not a sweep file) is
  refused, and so is a journal of another sweep;
- with ``force``: the sweep starts over, whatever the target and the journal hold
  (this sweep's records included); the old file stays until the new one replaces it.

One sweep at a time writes a target: a lock file beside it (``.NAME.pinmob-lock``,
``flock``), removed on leaving.
"""

from __future__ import annotations

import contextlib
import heapq
import json
import time
from pathlib import Path
from typing import Any

import numpy as np

from pinmob.exceptions import ConfigurationError
from pinmob.output_files import TEMP_SUFFIX, Replacing, check_target
from pinmob.signals import deferred_interrupts
from pinmob.sweeps.lock import TargetLock
from pinmob.sweeps.reading import (
    META,
    ROW_GROUP,
    groups,
    journal_identity,
    journal_records,
    read_records,
    records_of,
    unique,
)
from pinmob.sweeps.sweep_spec import SweepSpec, pinmob_version

#: Journal batches every so many records or seconds.
BATCH_RECORDS, BATCH_SECONDS = 256, 5.0

_ARROW = {"int": "int64", "float": "float64", "bool": "bool_", "str": "string"}


def schema(spec: SweepSpec, complete: bool = False, written: int = 0) -> Any:
    """The Arrow schema of the sweep's records, with its ``pinmob.sweep`` metadata."""
    import pyarrow as pa

    meta = {"identity": spec.identity(), "spec": spec.spec_digest(), "pinmob": pinmob_version(), "name": spec.name,
            "designs": spec.count, "written": written, "complete": complete,
            "units": {n: spec.unit(n) for n, _ in spec.fields() if spec.unit(n)}}  # fmt: skip
    fields = [pa.field(name, getattr(pa, _ARROW[kind])()) for name, kind in spec.fields()]
    return pa.schema(fields, metadata={META: json.dumps(meta, sort_keys=True).encode()})


def sweep_metadata(path: Path) -> dict[str, Any] | None:
    """The ``pinmob.sweep`` metadata of a Parquet file (None: not a sweep file, or not Parquet)."""
    import pyarrow.parquet as pq

    try:
        meta = pq.read_schema(path).metadata or {}
        return dict(json.loads(meta[META])) if META in meta else None
    except Exception:  # noqa: BLE001  (any file that is not a sweep's Parquet file)
        return None


class Store:
    """The sweep's records on disk (a context manager; see the module docstring for the rules).

    Args:
        target: the Parquet file.
        spec: the sweep.
        force: start over: replace whatever the target holds (another sweep's records, this sweep's, any
            file) and drop any journal beside it.

    Attributes:
        done: (count,) booleans, True for the designs already in the file (or recovered from a journal).
        resumed: designs found written when the store opened.
        written: records written by this run.
        in_file: designs the target holds since this run last published it (None: not published by this run).
    """

    def __init__(self, target: str | Path, spec: SweepSpec, force: bool = False) -> None:
        spec.check_count()
        self.target = check_target("`target`", target, force=True)
        self.spec, self.force = spec, force
        self.journal = self.target.with_name(f".{self.target.name}.pinmob-journal")
        self.lock = TargetLock(self.target.with_name(f".{self.target.name}.pinmob-lock"), self.target)
        self.done = np.zeros(spec.count, bool)
        self.resumed = 0
        self.written = 0
        self.in_file: int | None = None
        self._keep = False  # the target holds this sweep's records: merged into what is published
        self._batch: list[dict[str, Any]] = []
        self._last = -float("inf")  # the first record is flushed at once: the journal holds a design early
        self._writer: Any = None
        self._sink: Any = None
        self.check()
        self._schema = schema(spec)

    def check(self) -> None:
        """Refuse, before any work, a target this sweep may not resume nor replace (see the module docstring)."""
        shown = f"`target` {str(self.target)!r}"
        if self.force or not self.target.exists():
            return
        meta = sweep_metadata(self.target)
        if meta is not None and meta.get("identity") == self.spec.identity():
            self._keep = True  # this sweep's own file: resumed
            return
        if meta is None:
            raise _refused(
                f"{shown} exists and is not a pinmob sweep file; choose another file name, or replace it (`force=True`)"
            )
        if meta.get("spec") == self.spec.spec_digest():
            raise _refused(
                f"{shown} holds this sweep's records computed by another pinmob (version {meta.get('pinmob')!r}, or "
                "its code changed since): they are not resumed; choose another file name, or start over (`force=True`)"
            )
        raise _refused(
            f"{shown} holds the records of another sweep ({meta.get('name')!r}, {meta.get('written')} of "
            f"{meta.get('designs')} designs); choose another file name, or replace it (`force=True`)"
        )

    def __enter__(self) -> Store:
        import pyarrow as pa

        self.lock.acquire()
        try:
            with deferred_interrupts():  # a recovery runs whole
                for stale in self.target.parent.glob(f".{self.target.name}.*{TEMP_SUFFIX}"):
                    stale.unlink(missing_ok=True)  # a merge cut short by SIGKILL
                if self.journal.exists():
                    if self.force:
                        self.journal.unlink()  # starting over
                    elif journal_identity(self.journal) == self.spec.identity():
                        self._publish(complete=False)  # a run killed hard: keep its complete batches
                    else:
                        raise _refused(
                            f"{str(self.journal)!r} holds the unfinished records of another sweep (or of another "
                            f"pinmob) into {str(self.target)!r}; run that sweep again to finish it, or start over "
                            "(`force=True`)"
                        )
            if self._keep and self.target.exists():
                try:
                    for record in records_of(self.target, ["design"]):
                        self.done[record["design"]] = True
                except (pa.ArrowException, OSError, KeyError, IndexError) as exc:
                    raise _refused(
                        f"`target` {str(self.target)!r} cannot be read ({' '.join(str(exc).split())}); choose another "
                        "file name, or start over (`force=True`)"
                    ) from None
            self.resumed = int(self.done.sum())
            self._sink = pa.OSFile(str(self.journal), "wb")
            self._writer = pa.ipc.new_stream(self._sink, self._schema)
        except BaseException:
            self.lock.release()
            raise
        return self

    def write(self, record: dict[str, Any]) -> None:
        """Add one record (in design order); flushed to the journal in batches (signals held back meanwhile)."""
        with deferred_interrupts():
            self._batch.append(record)
            self.done[record["design"]] = True
            self.written += 1
            if len(self._batch) >= BATCH_RECORDS or time.monotonic() - self._last > BATCH_SECONDS:
                self._flush()

    def _flush(self) -> None:
        import pyarrow as pa

        if self._batch:
            self._writer.write_table(pa.Table.from_pylist(self._batch, schema=self._schema))
            self._sink.flush()
            self._batch = []
        self._last = time.monotonic()

    @property
    def complete(self) -> bool:
        """Every design is in the file or the journal."""
        return bool(self.done.all())

    def state(self) -> str:
        """Where the records are, in words: ``12 of 16 designs are in out.parquet``, or that nothing was written."""
        if self.in_file is not None:
            return f"{self.in_file} of {self.spec.count} designs are in {self.target}"
        if self.target.exists():
            return f"no record written; {self.target} left as it was"
        return f"no record written; {self.target} not created"

    def __exit__(self, *exc: object) -> None:
        try:
            if self._writer is not None:
                with deferred_interrupts():  # the journal closed and the file published whole; a signal raised after
                    self._flush()
                    self._writer.close()
                    self._sink.close()
                    self._writer = None
                    self._publish(complete=self.complete)
        finally:
            self.lock.release()

    def _publish(self, complete: bool) -> None:
        """Merge the target's records (if kept) with the journal's into a new target (renamed over it), drop the journal.

        Nothing is written when there is no record at all (the target, if any, stays as it was).

        Raises:
            ConfigurationError: the new file cannot be written (e.g. a full disk); the journal is kept.
        """
        import pyarrow as pa
        import pyarrow.parquet as pq

        keep_old = self._keep and self.target.exists()
        present = np.zeros(self.spec.count, bool)  # the designs the new file holds (its metadata says how many)
        for source in (records_of(self.target, ["design"]) if keep_old else iter(()), journal_records(self.journal)):
            for record in source:
                present[record["design"]] = True
        count = int(present.sum())
        if count == 0:
            self.journal.unlink(missing_ok=True)
            return
        old = records_of(self.target) if keep_old else iter(())
        merged = unique(heapq.merge(old, journal_records(self.journal), key=lambda r: r["design"]))
        final = schema(self.spec, complete and count == self.spec.count, count)
        replacing = Replacing(self.target)
        try:
            with replacing as tmp:
                with contextlib.closing(pq.ParquetWriter(tmp, final)) as writer:
                    for group in groups(merged, ROW_GROUP):
                        writer.write_table(pa.Table.from_pylist(group, schema=final))
                replacing.commit()
        except OSError as exc:
            raise _refused(
                f"cannot write `target` {str(self.target)!r}: {' '.join(str(exc).split())}; the records so far are kept "
                f"in {str(self.journal)!r}, which the next run of this sweep recovers"
            ) from None
        self.journal.unlink(missing_ok=True)
        self._keep = True  # the target now holds this sweep's records
        self.in_file = count


def _refused(message: str) -> ConfigurationError:
    """The error of a refusal that names the ``target`` and ``force`` parameters (the command line: --out, --force)."""
    return ConfigurationError(message).naming("target", "force")


__all__ = ["META", "Store", "read_records", "schema", "sweep_metadata"]
