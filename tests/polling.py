"""Waiting helpers shared by the Python and interop tests.

Frames and callbacks arrive on other threads (bus receive threads, servers,
child processes), so a test waits for a condition with a generous bound and
then asserts on the state it sees; the bound only limits a broken run.
(tests/ is on sys.path because tests/conftest.py lives here.)
"""
from __future__ import annotations

import time
from typing import Any, Callable, Optional


def wait_for(predicate: Callable[[], Any], timeout: float = 3.0, interval: float = 0.001) -> bool:
    """Polls ``predicate`` until it is true or ``timeout`` seconds passed;
    returns its last value as a bool."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        if predicate():
            return True
        time.sleep(interval)
    return bool(predicate())


def recv_id(bus: Any, can_id: int, timeout: float = 1.0, poll: float = 0.05) -> Optional[Any]:
    """The next frame with ``can_id`` from a motorbus bus (``.id``) or a
    python-can bus (``.arbitration_id``), skipping others; None after ``timeout``."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        f = bus.recv(poll)
        if f is not None and getattr(f, "id", getattr(f, "arbitration_id", None)) == can_id:
            return f
    return None
