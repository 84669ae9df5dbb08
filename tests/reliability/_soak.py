"""The one size knob of tests/reliability (see conftest.py)."""
import itertools
import os

SOAK = os.environ.get("MOTORBUS_SOAK", "") not in ("", "0")

_hub = itertools.count()


def size(bounded, soak):
    """``bounded`` in the default run, ``soak`` with MOTORBUS_SOAK=1."""
    return soak if SOAK else bounded


def hub(prefix="rel"):
    """A fresh virtual hub name (hubs are process-wide)."""
    return f"{prefix}-{os.getpid()}-{next(_hub)}"
