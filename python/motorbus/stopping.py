"""The stop words, said once: how a drive is stopped.

Every place that takes one — ``Drive(on_error=, on_exit=)`` and each kind's
``open``, the native clients' ``on_error``/``on_exit``, a bench file's
``[axis.X.options]``, ``Bench.stop_all(how)`` (the pytest plugin's teardown and
``motorbus stop``) — checks it here, so a wrong word is the same
:class:`motorbus.InvalidArgument` with the same message everywhere:

* ``"stop"``: decelerate with the drive's own ramp;
* ``"quick_stop"``: the fastest stop the drive has;
* ``"disable"``: power stage off (the motor no longer holds position);
* ``None``: leave the motor as it is (``on_error``/``on_exit`` only).

A native client whose protocol lacks a way (the CANopen layer's ``Cia402`` host
has no decelerated stop of its own) passes the subset it has as ``allowed``;
the message then names that subset.
"""
from __future__ import annotations

from typing import Any, Optional

from . import _core

__all__ = ["STOP_WAYS", "StopHow", "check_stop_way", "stop_words"]

#: The one safety vocabulary (``on_error``, ``on_exit``; ``Bench.stop_all`` takes
#: the three words but not None: stopping nothing is not a stop).
STOP_WAYS: tuple = ("stop", "quick_stop", "disable", None)
#: The type of an ``on_error``/``on_exit`` value.
StopHow = Optional[str]


def stop_words(allowed: tuple = STOP_WAYS) -> str:
    """``"'stop', 'quick_stop', 'disable' or None"``: the words of ``allowed`` as an error names them."""
    names = [repr(w) for w in allowed]
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " or " + names[-1]


def check_stop_way(how: Any, what: str = "on_error", allowed: tuple = STOP_WAYS) -> StopHow:
    """Returns ``how`` when it is one of ``allowed``; otherwise raises
    :class:`motorbus.InvalidArgument` ``"<what>: one of <allowed>, not <how>"``.
    ``what`` names the argument (``"on_error"``, ``"Bench.stop_all how"``...)."""
    # Compared by type too: True == 1 and a str subclass must not slip through a
    # tuple's ==; an unhashable value (a list) is simply not a word.
    if not any(how is w or (type(how) is str and how == w) for w in allowed):
        raise _core.InvalidArgument(f"{what}: one of {stop_words(allowed)}, not {how!r}")
    return how
