"""The sweep's Parquet file: streamed, resumable, never left corrupt by an interruption.

Records go, as they come and in design order, to a journal beside the target
(``.NAME.pinmob-journal``, Arrow IPC stream batches: the first record at once, then every
``BATCH_RECORDS`` records or ``BATCH_SECONDS`` seconds). :meth:`Store.close`
merges the target's records (if any) with the journal's, by design index, into
a temporary Parquet file in the target's folder (row groups of ``ROW_GROUP``
records, so the same records make the same file), renames it over the target
and removes the journal. The target is thus only ever replaced whole: an
interruption that pinmob handles (Ctrl-C, SIGTERM, SIGHUP, an error) publishes
the records so far, marked incomplete (a second signal during that merge waits for it to end); one it cannot handle (SIGKILL, a power
cut) leaves the previous file as it was and the journal, whose complete batches
the next run recovers. Memory is flat in the number of designs: records stream
through batches; only a bitmap of the designs written is kept.

The file's schema metadata ``pinmob.sweep`` (JSON) holds the sweep's identity
(a digest of its spec), the number of designs, how many are written and
whether it is complete. Re-running the same sweep on the file resumes it (the
designs written are skipped); a file of another sweep is replaced only with
``force``.
"""

from __future__ import annotations

import contextlib
import fcntl
import heapq
import json
import os
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np

from pinmob.exceptions import ConfigurationError
from pinmob.scan.files import TEMP_SUFFIX, Replacing, check_target
from pinmob.sweeps.spec import SweepSpec

#: Metadata key of the sweep's description in the Parquet schema.
META = b"pinmob.sweep"
#: Records per Parquet row group; journal batches every so many records or seconds.
ROW_GROUP, BATCH_RECORDS, BATCH_SECONDS = 1024, 256, 5.0

_ARROW = {"int": "int64", "float": "float64", "bool": "bool_", "str": "string"}


def schema(spec: SweepSpec, complete: bool = False, written: int = 0) -> Any:
    """The Arrow schema of the sweep's records, with its ``pinmob.sweep`` metadata."""
    import pyarrow as pa

    meta = {"identity": spec.identity(), "name": spec.name, "designs": spec.count, "written": written,
            "complete": complete, "units": {n: spec.unit(n) for n, _ in spec.fields() if spec.unit(n)}}  # fmt: skip
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
    """The sweep's records on disk (a context manager; see the module docstring).

    Args:
        target: the Parquet file.
        spec: the sweep.
        force: replace a file that holds another sweep's records (or none).

    Attributes:
        done: (count,) booleans, True for the designs already in the file (or recovered from a journal).
        resumed: designs found written when the store opened.
    """

    def __init__(self, target: str | Path, spec: SweepSpec, force: bool = False) -> None:
        self.target = check_target("--out", target, force=True)
        self.spec, self.force = spec, force
        self.journal = self.target.with_name(f".{self.target.name}.pinmob-journal")
        self.done = np.zeros(spec.count, bool)
        self.resumed = 0
        self.written = 0
        self._batch: list[dict[str, Any]] = []
        self._last = -float("inf")  # the first record is flushed at once: the journal holds a design early
        self._lock: Any = None
        self._writer: Any = None
        self._sink: Any = None
        self.check()
        self._schema = schema(spec)

    def check(self) -> None:
        """Refuse, before any work, a target holding something else than this sweep's records (unless ``force``)."""
        meta = sweep_metadata(self.target) if self.target.exists() else None
        if meta is not None and meta.get("identity") == self.spec.identity():
            self.force = False  # this sweep's own file: resumed, never replaced by a fresh start
        elif self.target.exists() and not self.force:
            if meta is None:
                raise ConfigurationError(
                    f"--out {str(self.target)!r} exists and is not a pinmob sweep file; choose another file name or "
                    "allow overwriting (--force)"
                )
            if meta.get("identity") != self.spec.identity():
                raise ConfigurationError(
                    f"--out {str(self.target)!r} holds the records of another sweep ({meta.get('name')!r}, "
                    f"{meta.get('written')} of {meta.get('designs')} designs); choose another file name or allow "
                    "overwriting (--force)"
                )

    def __enter__(self) -> Store:
        import pyarrow as pa

        self._lock = open(self.target.with_name(f".{self.target.name}.pinmob-lock"), "a+")  # noqa: SIM115
        try:
            fcntl.flock(self._lock, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            self._lock.close()
            raise ConfigurationError(f"another pinmob sweep is writing {str(self.target)!r} now") from None
        for stale in self.target.parent.glob(f".{self.target.name}.*{TEMP_SUFFIX}"):
            stale.unlink(missing_ok=True)  # a merge cut short by SIGKILL
        if self.journal.exists():
            if _identity(self.journal) == self.spec.identity():
                self._publish(complete=False, recover=True)  # a run killed hard: keep its complete batches
            elif self.force:
                self.journal.unlink()
            else:
                self._lock.close()
                raise ConfigurationError(
                    f"{str(self.journal)!r} holds the unfinished records of another sweep into {str(self.target)!r}; "
                    "run that sweep again to finish it, or allow overwriting (--force)"
                )
        if self.target.exists() and not self.force:
            for record in _records(self.target, ["design"]):
                self.done[record["design"]] = True
        self.resumed = int(self.done.sum())
        self._sink = pa.OSFile(str(self.journal), "wb")
        self._writer = pa.ipc.new_stream(self._sink, self._schema)
        return self

    def write(self, record: dict[str, Any]) -> None:
        """Add one record (in design order); flushed to the journal in batches."""
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

    def __exit__(self, *exc: object) -> None:
        try:
            if self._writer is not None:
                self._flush()
                self._writer.close()
                self._sink.close()
                self._writer = None
                interrupted = False
                while True:  # a Ctrl-C or SIGTERM during the merge: finish it first (it is short and idempotent)
                    try:
                        self._publish(complete=self.complete)
                        break
                    except KeyboardInterrupt:
                        interrupted = True
                if interrupted:
                    raise KeyboardInterrupt
        finally:
            if self._lock is not None:
                with contextlib.suppress(OSError):
                    os.unlink(self._lock.name)
                self._lock.close()
                self._lock = None

    def _publish(self, complete: bool, recover: bool = False) -> None:
        """Merge the target's records with the journal's into a new target (renamed over it), drop the journal."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        keep_old = self.target.exists() and (recover or not self.force)
        present = np.zeros(self.spec.count, bool)  # the designs the new file holds (its metadata says how many)
        for source in (_records(self.target, ["design"]) if keep_old else iter(()), _journal(self.journal)):
            for record in source:
                present[record["design"]] = True
        count = int(present.sum())
        if count == 0 and not self.target.exists():
            self.journal.unlink(missing_ok=True)
            return
        old = _records(self.target) if keep_old else iter(())
        merged = _unique(heapq.merge(old, _journal(self.journal), key=lambda r: r["design"]))
        final = schema(self.spec, complete and count == self.spec.count, count)
        replacing = Replacing(self.target)
        with replacing as tmp:
            with contextlib.closing(pq.ParquetWriter(tmp, final)) as writer:
                for group in _groups(merged, ROW_GROUP):
                    writer.write_table(pa.Table.from_pylist(group, schema=final))
            replacing.commit()
        self.journal.unlink(missing_ok=True)
        self.force = False  # the target now holds this sweep's records


def _records(path: Path, columns: list[str] | None = None) -> Iterator[dict[str, Any]]:
    import pyarrow.parquet as pq

    with pq.ParquetFile(path) as fh:
        for batch in fh.iter_batches(batch_size=ROW_GROUP, columns=columns):
            yield from batch.to_pylist()


def _journal(path: Path) -> Iterator[dict[str, Any]]:
    """The journal's records, up to its last complete batch (a run killed hard may have cut the next one)."""
    import pyarrow as pa

    if not path.exists():
        return
    try:
        reader = pa.ipc.open_stream(pa.memory_map(str(path)))
    except (pa.ArrowInvalid, OSError):
        return
    while True:
        try:
            batch = reader.read_next_batch()
        except (StopIteration, pa.ArrowInvalid, OSError):
            return
        yield from batch.to_pylist()


def _unique(records: Iterator[dict[str, Any]]) -> Iterator[dict[str, Any]]:
    last = -1
    for r in records:
        if r["design"] != last:
            yield r
            last = r["design"]


def _groups(records: Iterator[dict[str, Any]], size: int) -> Iterator[list[dict[str, Any]]]:
    group: list[dict[str, Any]] = []
    for r in records:
        group.append(r)
        if len(group) == size:
            yield group
            group = []
    if group:
        yield group


def _identity(journal: Path) -> str | None:
    """The sweep identity in a journal's schema (None when unreadable)."""
    import pyarrow as pa

    try:
        meta = pa.ipc.open_stream(pa.memory_map(str(journal))).schema.metadata or {}
        return str(json.loads(meta[META])["identity"])
    except Exception:  # noqa: BLE001  (a journal cut before its schema)
        return None


def read_records(path: str | Path, columns: list[str] | None = None) -> Iterator[dict[str, Any]]:
    """The records of a sweep's Parquet file, in design order, a row group at a time."""
    return _records(Path(path), columns)
