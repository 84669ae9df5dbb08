"""Discovery, awaited: ``result = await aio.discover(lines=[...], buses=[...])``.

The same sweep as :func:`motorbus.discovery.discover` (same arguments, same
:class:`~motorbus.discovery.Discovery` result), without blocking the loop.

How: the kinds' probes (``probe``, the CANopen scan) are blocking calls of each
kind's native client -- there is no awaitable transaction for an arbitrary
kind's identity query -- so the whole sweep runs on **one** worker thread
(motorbus.faces' link worker, shared by every awaited discovery: two run one
after the other, never a thread per probe), and the task sleeps until the
result comes back through the loop's completion queue.  Each line and bus is
probed in the order given, exactly as the blocking call does.

``progress``: a callable is called on the loop's thread with each line (never
on the worker); ``True`` prints plain lines to stderr (no bar: the loop's
terminal is not the worker's).  Cancelling the awaiting task raises
``CancelledError`` at once; the worker abandons the sweep at its next step
(a line's next kind or baud rate, a bus's next node report), closing what it
opened, so a cancelled discovery does not keep probing in the background.
"""
from __future__ import annotations

import asyncio
import functools
import sys
import threading
from typing import Any, Callable, Optional, Sequence, Union

from .. import _core, faces
from .. import discovery as _discovery

__all__ = ["discover"]


class _Abandoned(Exception):
    """Raised inside the worker's sweep once its awaiting task was cancelled."""


# The one worker every awaited discovery runs on (faces' workers are keyed by this object).
_WORKER = object()


async def discover(lines: Sequence[str] = (), buses: Sequence[Any] = (), *, kinds: Optional[Sequence[str]] = None,
                   timeout: float = 120.0, reply_timeout: float = 0.05, sdo_timeout: float = 0.1,
                   progress: Union[bool, Callable[[str], None]] = False) -> _discovery.Discovery:
    """Probes ``lines`` (port paths) and ``buses`` (``open_bus`` specs or open Buses)
    for drives of every registered kind (or of ``kinds``): see the module doc."""
    if not isinstance(progress, bool) and not callable(progress):
        raise _core.InvalidArgument(f"discover progress: True, False or a callable taking one line, "
                                    f"not {type(progress).__name__}")
    loop = asyncio.get_running_loop()
    abandoned = threading.Event()

    def say(line: str) -> None:            # on the worker, at each step of the sweep
        if abandoned.is_set():
            raise _Abandoned(line)
        if callable(progress):
            loop.call_soon_threadsafe(progress, line)
        elif progress:
            print(line, file=sys.stderr, flush=True)

    sweep = functools.partial(_discovery.discover, lines, buses, kinds=kinds, timeout=timeout,
                              reply_timeout=reply_timeout, sdo_timeout=sdo_timeout, progress=say)
    try:
        return await faces.NativeIo(None, link=_WORKER).do(_sweep, sweep)
    except asyncio.CancelledError:
        abandoned.set()
        raise


def _sweep(sweep: Callable[[], _discovery.Discovery]) -> Optional[_discovery.Discovery]:
    try:
        return sweep()
    except _Abandoned:
        return None                        # nobody awaits it any more
