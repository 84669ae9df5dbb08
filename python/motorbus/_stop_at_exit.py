"""Drive objects stop their motor when an exception leaves ``with`` and when
the interpreter exits with them still open.

Every drive client (Arcus, DMAC, CiA 402) registers itself with :func:`track`
when it opens and :func:`untrack` when it closes; at exit each one still
tracked has its ``_stop_at_exit()`` called (best effort: a link that is
already gone must not stop the others).  Weak references: a client that was
garbage-collected is simply gone.
"""
from __future__ import annotations

import atexit
import threading
import weakref
from typing import Any

_live: "weakref.WeakSet[Any]" = weakref.WeakSet()
_lock = threading.Lock()


def track(drive: Any) -> None:
    with _lock:
        _live.add(drive)


def untrack(drive: Any) -> None:
    with _lock:
        _live.discard(drive)


def stop_all() -> None:
    with _lock:
        drives = list(_live)
    for d in drives:
        try:
            d._stop_at_exit()
        except Exception:  # noqa: BLE001 - one dead link must not spare the other motors
            pass


atexit.register(stop_all)


def halt(how, stop, quick_stop, disable) -> None:
    """Applies one of the safety words ("stop", "quick_stop", "disable"; None does
    nothing) with the three ways a drive has; best effort while unwinding: a way
    that fails (the link may be gone) falls back to the next harder one."""
    if how is None:
        return
    ladder = {"stop": (stop, quick_stop, disable), "quick_stop": (quick_stop, disable), "disable": (disable,)}[how]
    for step in ladder:
        try:
            step()
            return
        except Exception:  # noqa: BLE001 - try the next way
            continue


class StopsMotor:
    """Mixin for drive objects: ``with`` support that calls ``_stop_on_error()``
    when an exception leaves the block and ``close()`` in every case.  The
    class also calls :func:`track` when it opens and :func:`untrack` in
    ``close()``, and defines ``_stop_at_exit()`` for the exit hook."""

    def __enter__(self):
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        try:
            if exc_type is not None:
                self._stop_on_error()
        finally:
            self.close()
