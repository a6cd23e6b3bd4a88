"""Reading a sweep's records back: the Parquet file, a row group at a time, and the journal's complete batches."""

from __future__ import annotations

import json
from collections.abc import Iterator
from pathlib import Path
from typing import Any

#: Metadata key of the sweep's description in the Parquet schema.
META = b"pinmob.sweep"
#: Records per Parquet row group (and per batch read).
ROW_GROUP = 1024


def records_of(path: Path, columns: list[str] | None = None) -> Iterator[dict[str, Any]]:
    """The records of a Parquet file (only ``columns``, if given), a row group at a time."""
    import pyarrow.parquet as pq

    with pq.ParquetFile(path) as fh:
        for batch in fh.iter_batches(batch_size=ROW_GROUP, columns=columns):
            yield from batch.to_pylist()


def journal_records(path: Path) -> Iterator[dict[str, Any]]:
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


def unique(records: Iterator[dict[str, Any]]) -> Iterator[dict[str, Any]]:
    """Records sorted by design, each design once (the first of a run of equal ones)."""
    last = -1
    for r in records:
        if r["design"] != last:
            yield r
            last = r["design"]


def groups(records: Iterator[dict[str, Any]], size: int) -> Iterator[list[dict[str, Any]]]:
    """The records in lists of ``size`` (the last one shorter)."""
    group: list[dict[str, Any]] = []
    for r in records:
        group.append(r)
        if len(group) == size:
            yield group
            group = []
    if group:
        yield group


def journal_identity(journal: Path) -> str | None:
    """The sweep identity in a journal's schema (None when unreadable)."""
    import pyarrow as pa

    try:
        meta = pa.ipc.open_stream(pa.memory_map(str(journal))).schema.metadata or {}
        return str(json.loads(meta[META])["identity"])
    except Exception:  # noqa: BLE001  (a journal cut before its schema)
        return None


def read_records(path: str | Path, columns: list[str] | None = None) -> Iterator[dict[str, Any]]:
    """The records of a sweep's Parquet file, in design order, a row group at a time."""
    return records_of(Path(path), columns)
