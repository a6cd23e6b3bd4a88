"""Reusable ``pin.Data``: a small pool per model.

Creating a ``pin.Data`` costs about as much as a whole analysis of a large
mechanism (it grows with nv^3: 13 to 24 us at nv 15, 0.24 to 0.5 ms at nv 36), so the
configurations, the closure solver, the assembly functions, the batched predictor's problems (where Pinocchio's
kinematics run), a scan's platform poses and the model's motion subspaces borrow one from
the model's pool and give it back when they are done with it. The pool holds at
most ``POOL_SIZE`` spare ones per model and goes with the model.

The pools are found by the model object's identity: a ``weakref.WeakKeyDictionary`` finds its key by equality, and
``pin.Model.__eq__`` compares two models' every joint, frame and inertia (1.4 us for a 3-PUU, 3.6 us for a
6-UPS: two a borrowing, one to lend and one to give back, before any work was done).
"""

from __future__ import annotations

import functools
import threading
import weakref
from collections.abc import Iterator
from contextlib import contextmanager

import pinocchio as pin

#: Spare ``pin.Data`` kept per model (each can weigh megabytes for a large model).
POOL_SIZE = 2

#: Per live model, by ``id``: a weak reference to it (whose callback removes the entry) and its spare Data.
_POOL: dict[int, tuple[weakref.ref[pin.Model], list[pin.Data]]] = {}
_LOCK = threading.Lock()


def spares(model: pin.Model, create: bool = False) -> list[pin.Data] | None:
    """The spare Data of ``model`` (the object, not an equal copy), or None; with ``create`` an empty list made.

    The caller holds ``_LOCK``.
    """
    key = id(model)
    entry = _POOL.get(key)
    if entry is not None and entry[0]() is model:
        return entry[1]
    if not create:
        return None
    spare: list[pin.Data] = []
    _POOL[key] = (weakref.ref(model, functools.partial(_forget, key)), spare)
    return spare


def _forget(key: int, ref: weakref.ref[pin.Model]) -> None:
    """A model's pool removed as the model goes (its id free for another model only after this has run).

    No lock: it runs inside any allocation that frees a model, possibly while this thread holds ``_LOCK``;
    the dictionary's own operations are atomic.
    """
    entry = _POOL.get(key)
    if entry is not None and entry[0] is ref:
        _POOL.pop(key, None)


def acquire(model: pin.Model) -> pin.Data:
    """A spare ``pin.Data`` of ``model``, or a new one; its contents are whatever the last user left.

    A spare made before joints or frames were added to the model (a reader borrows one while it builds the model:
    :func:`pinmob.model.joints.motion_subspaces`) is dropped: Pinocchio's algorithms do not check a Data's sizes
    against its model, and one frame short they read and write past its end.
    """
    with _LOCK:
        spare = spares(model)
        while spare:
            data = spare.pop()
            if _fits(model, data):
                return data
    return pin.Data(model)  # as model.createData(), which returns a copy of the one it builds (twice the time)


def _fits(model: pin.Model, data: pin.Data) -> bool:
    """``data`` has one placement per joint and frame of ``model`` as it is now."""
    return len(data.oMi) == model.njoints and len(data.oMf) == model.nframes


def release(model_ref: weakref.ref[pin.Model], data: pin.Data) -> None:
    """Give ``data`` back to the pool of the model ``model_ref`` refers to (dropped when the model is gone).

    Dropped too when the pool is busy: ``release`` runs as a finalizer, which the garbage collector may call in the
    middle of any allocation, including one made while this very thread holds the pool's lock (a blocking
    acquisition there waited forever: a finite analysis hung in ``bench_finite.py``). A dropped Data only costs a
    new one later.
    """
    model = model_ref()
    if model is None or not _LOCK.acquire(blocking=False):
        return
    try:
        spare = spares(model, create=True)
        assert spare is not None
        if len(spare) < POOL_SIZE:
            spare.append(data)
    finally:
        _LOCK.release()


def release_with(owner: object, model: pin.Model, data: pin.Data) -> weakref.finalize:
    """Give ``data`` back to the pool when ``owner`` (an object that uses it) is collected.

    Returns the finalizer: calling it gives ``data`` back at once (and not again when ``owner`` is collected).
    """
    return weakref.finalize(owner, release, weakref.ref(model), data)


@contextmanager
def borrowed(model: pin.Model) -> Iterator[pin.Data]:
    """A pooled ``pin.Data`` of ``model`` for the duration of the block."""
    data = acquire(model)
    try:
        yield data
    finally:
        release(weakref.ref(model), data)
