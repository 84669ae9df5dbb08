"""Reliability tests: load, faults, link loss, floods and bad input (docs/reliability.md).

One knob sizes every test: ``MOTORBUS_SOAK=1`` (or ``pytest --soak``) scales the counts and
durations up (``make soak``, long); unset, the whole directory is a bounded run (≤ 90 s on the
project's 2-core VM).  Every test is marked ``soak``.  Tests assert exact counts, never timings:
the only clocks here are deadlines that turn a hang into a failure.
"""
import os

import pytest


def pytest_addoption(parser):
    parser.addoption("--soak", action="store_true", default=False,
                     help="scale the reliability tests up (same as MOTORBUS_SOAK=1)")


def pytest_configure(config):
    if config.getoption("--soak", default=False):
        os.environ["MOTORBUS_SOAK"] = "1"


def pytest_collection_modifyitems(config, items):
    here = os.path.dirname(__file__)
    for item in items:
        if str(item.fspath).startswith(here):
            item.add_marker(pytest.mark.soak)
