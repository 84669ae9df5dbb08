"""A hardware-in-the-loop test module using motorbus's pytest plugin (docs/pytest-plugin.md).

    pytest examples/11_pytest_bench.py                  # the built-in bench's simulated twin:
                                                        # one axis of every registered kind
    pytest examples/11_pytest_bench.py --bench-sim rig.toml   # rig.toml's simulated twin
    pytest examples/11_pytest_bench.py --bench rig.toml       # the real rig

The same file runs on all three; after every test, whatever happened, every axis is stopped.
"""
import time

import pytest

from motorbus import registry


def test_every_axis_answers(bench):
    for name, drive in bench.axes.items():
        st = drive.status
        assert not st.fault, f"{name}: {st.text}"


# Axes by name (indirect parametrization): a name the bench lacks is skipped with the reason.
# (The built-in twin's unitek starts uncalibrated, as a drive out of the box: it does not run.)
@pytest.mark.parametrize("axis", ["arcus", "dmac", "cia402", "arcus-canopen", "pmc007"], indirect=True)
def test_axis_jogs_forward(axis):
    axis.enable()
    start = axis.position
    axis.jog(2.0)                    # user units per second
    deadline = time.monotonic() + 5
    while axis.position <= start:
        assert time.monotonic() < deadline, f"{axis} does not move"
        time.sleep(0.01)
    # no stop needed: the plugin stops every axis after the test


@pytest.mark.axes("cia402")
def test_a_drive_fault_is_reported(axis, sim_faults):
    axis.enable()
    assert "drive_fault" in sim_faults.offered("cia402")
    sim_faults.inject("cia402", "drive_fault")
    assert axis.status.fault


def test_every_kind_offers_faults(bench, sim_faults):
    for name in bench.axes:
        assert sim_faults.offered(name), registry.drive_plugin(bench.config[name].kind).kind
