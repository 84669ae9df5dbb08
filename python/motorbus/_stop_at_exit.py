"""Drive objects stop their motor when an exception leaves ``with``, when the
interpreter exits with them still open, and when the process is ended by
SIGTERM or SIGHUP.

Every drive client (serial or CAN) registers itself with :func:`track`
when it opens and :func:`untrack` when it closes; at exit each one still
tracked has its ``_stop_at_exit()`` called (best effort: a link that is
already gone must not stop the others).  Weak references: a client that was
garbage-collected is simply gone.

Signals (docs/reliability.md, "Signals").  The first :func:`track` made on the
main thread installs :func:`handle_signal` for SIGTERM and SIGHUP where their
handler is still SIG_DFL (a program's own handler, or SIG_IGN under ``nohup``,
is left alone).  The handler does not stop the drives itself: it runs between
two bytecodes of the main thread, or inside a C++ wait's interruption point,
where that thread may hold the very line or SDO channel a stop needs.  It
raises :class:`TerminatedBySignal` (a ``KeyboardInterrupt``), so the process
unwinds exactly as after Ctrl-C — ``with`` blocks stop their drives, the CLI
stops the axis it moves, the pytest plugin stops the bench — and at exit, after
:func:`stop_all`, the process dies by that same signal (SIG_DFL restored, the
signal sent again), so its parent sees -15 / 128+15.  A program that swallows
the interrupt, or a main thread that cannot unwind (it waits for a thread that
keeps moving a motor), does not keep the motors running: ``grace`` seconds
after the signal a watchdog thread stops every drive and ends the process the
same way.  A second signal does that at once.
"""
from __future__ import annotations

import atexit
import os
import signal
import sys
import threading
import time
import weakref
from typing import Any, Optional

__all__ = ["TerminatedBySignal", "handle_signal", "stop_all", "track", "untrack", "SIGNALS"]

_live: "weakref.WeakSet[Any]" = weakref.WeakSet()
# Re-entrant: the signal handler runs in the main thread between two bytecodes, possibly
# inside track() or untrack() of that same thread.
_lock = threading.RLock()

#: The signals that stop the drives before the process ends (SIGINT is Ctrl-C's
#: KeyboardInterrupt, which Python already raises).
SIGNALS: tuple = tuple(getattr(signal, n) for n in ("SIGTERM", "SIGHUP") if hasattr(signal, n))
#: Seconds after a signal before the watchdog stops every drive from its own thread and
#: ends the process, if unwinding the main thread has not ended it by then.
GRACE = 5.0
#: Seconds the watchdog (or a second signal) gives stop_all() before the process dies anyway.
STOP_BUDGET = 5.0

_installed: set = set()             # the signals whose handler is handle_signal (installed here)
_install_tried = False              # done once, from the main thread
_pending: Optional[int] = None      # the signal that is ending the process


class TerminatedBySignal(KeyboardInterrupt):
    """Raised in the main thread by SIGTERM or SIGHUP while drives are open: the
    process unwinds as after Ctrl-C (every ``with`` stops its drives), then dies
    by ``signum``.  A ``KeyboardInterrupt``, so ``except Exception`` does not
    swallow it and code that handles Ctrl-C handles it the same way."""

    def __init__(self, signum: int) -> None:
        self.signum = signum
        super().__init__(f"{_name(signum)}: stopping every drive, then exiting by {_name(signum)}")


def _name(signum: int) -> str:
    try:
        return signal.Signals(signum).name
    except ValueError:
        return f"signal {signum}"


def track(drive: Any) -> None:
    with _lock:
        _live.add(drive)
    if not _install_tried:
        _install_handlers()


def untrack(drive: Any) -> None:
    with _lock:
        _live.discard(drive)


def _install_handlers() -> None:
    """SIGTERM and SIGHUP -> handle_signal, where their handler is still SIG_DFL.
    Python lets only the main thread set handlers: a drive opened on another
    thread leaves it to the next one opened on the main thread."""
    global _install_tried
    if threading.current_thread() is not threading.main_thread():
        return
    _install_tried = True
    for sig in SIGNALS:
        try:
            if signal.getsignal(sig) is signal.SIG_DFL:   # a user's handler, SIG_IGN (nohup), None: theirs
                signal.signal(sig, handle_signal)
                _installed.add(sig)
        except (ValueError, OSError):   # an embedding interpreter may refuse: the atexit stop remains
            pass


def stop_all() -> None:
    """Stops every drive this process has open (each kind's ``_stop_at_exit``:
    the drive's ``on_exit`` way), best effort: one dead link must not spare the
    other motors.  Public as ``motorbus.stop_all_drives``."""
    with _lock:
        drives = list(_live)
    for d in drives:
        try:
            d._stop_at_exit()
        except Exception:  # noqa: BLE001 - one dead link must not spare the other motors
            pass


def handle_signal(signum: int, frame: Any = None) -> None:
    """The SIGTERM/SIGHUP handler (public as ``motorbus.stop_on_signal``: a program
    with its own handler calls it last, from that handler, to get the same).

    No drive open: the process dies by the signal at once, as with SIG_DFL.
    Otherwise it raises :class:`TerminatedBySignal` and arms the watchdog (see
    the module doc); the exit hook stops what is still open and re-raises the
    signal.  A second signal while that goes on: stop from a helper thread,
    at most STOP_BUDGET s, and die."""
    global _pending
    if _pending is not None:
        _stop_then_die(signum)
        return
    with _lock:
        live = len(_live)
    if not live:
        _die(signum)
    _pending = signum
    _wrap_excepthook()
    threading.Thread(target=_watchdog, args=(signum, GRACE), name="motorbus-signal-watchdog", daemon=True).start()
    raise TerminatedBySignal(signum)


def _watchdog(signum: int, grace: float) -> None:
    time.sleep(grace)
    # Still alive: the interrupt was swallowed, or the main thread waits for something
    # that does not end.  Stop from here (another thread: no lock of the main thread's
    # is held by this one) and end the process the way the signal would have.
    _stop_then_die(signum)


def _stop_then_die(signum: int) -> None:
    t = threading.Thread(target=stop_all, name="motorbus-signal-stop", daemon=True)
    t.start()
    t.join(STOP_BUDGET)   # a stop stuck behind a lock the main thread holds must not keep the process
    _die(signum)


def _die(signum: int) -> None:
    """Ends the process by ``signum`` with its default action (the parent sees -signum,
    a shell 128+signum).  atexit handlers still queued and daemon threads do not run."""
    for stream in (sys.stdout, sys.stderr):
        try:
            stream.flush()
        except Exception:  # noqa: BLE001 - a closed stream must not keep the process alive
            pass
    _default_action(signum)
    try:
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signum})
    except (AttributeError, OSError, ValueError):
        pass
    os.kill(os.getpid(), signum)
    time.sleep(1.0)               # delivery is asynchronous; a process that is still here:
    os._exit(128 + signum)        # the shell's convention for "killed by signum"


def _default_action(signum: int) -> None:
    if threading.current_thread() is threading.main_thread():
        try:
            signal.signal(signum, signal.SIG_DFL)
            return
        except (ValueError, OSError):
            pass
    # Python sets handlers from the main thread only; the watchdog resets the C-level one.
    try:
        import ctypes

        libc = ctypes.CDLL(None, use_errno=True)
        libc.signal.argtypes = [ctypes.c_int, ctypes.c_void_p]
        libc.signal.restype = ctypes.c_void_p
        libc.signal(signum, None)   # SIG_DFL is 0
    except Exception:  # noqa: BLE001 - then os._exit(128 + signum) ends it
        pass


def _wrap_excepthook() -> None:
    """An uncaught TerminatedBySignal prints one line, not a traceback: ending by a
    signal is not a program error."""
    previous = sys.excepthook

    def hook(exc_type: Any, exc: Any, tb: Any) -> None:
        if isinstance(exc, TerminatedBySignal):
            print(f"motorbus: {exc}", file=sys.stderr, flush=True)
            return
        previous(exc_type, exc, tb)

    sys.excepthook = hook


def _at_exit() -> None:
    stop_all()
    if _pending is not None:
        _die(_pending)


atexit.register(_at_exit)


def _forked_child() -> None:
    # A forked child (multiprocessing) shares its parent's links: the drives are the
    # parent's to stop, not the child's, at its exit or on its signal.  The handlers stay:
    # with nothing tracked they end the child as SIG_DFL would.
    global _live, _lock, _pending
    _live = weakref.WeakSet()
    _lock = threading.RLock()
    _pending = None


if hasattr(os, "register_at_fork"):
    os.register_at_fork(after_in_child=_forked_child)


def ladder(how, stop, quick_stop, disable) -> tuple:
    """The ways to try, in order, for a safety word: the asked one, then each harder one
    (a failed stop falls back to the quick stop, then to disabling); none for None.  The
    blocking ``halt`` below and motorbus.aio's awaited one both climb it."""
    if how is None:
        return ()
    return {"stop": (stop, quick_stop, disable), "quick_stop": (quick_stop, disable), "disable": (disable,)}[how]


def halt(how, stop, quick_stop, disable) -> None:
    """Applies one of the safety words ("stop", "quick_stop", "disable"; None does
    nothing) with the three ways a drive has; best effort while unwinding: a way
    that fails (the link may be gone) falls back to the next harder one."""
    for step in ladder(how, stop, quick_stop, disable):
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
