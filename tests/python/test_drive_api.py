"""One Drive API over every kind: the same script against each simulated drive.

Each kind runs twice:
* ``transport``: its simulator served the way a bench is wired — serial kinds on a
  pty (the client opens the pty path), CAN kinds behind a socketcand server on
  127.0.0.1 (the client opens ``socketcand:HOST:PORT/can0``);
* ``in_process``: the simulator on the most direct link this process has (CAN:
  the same virtual bus; serial: its pty, the only link a serial device has).

The kinds and the rig are in drive_kinds.py (test_aio_drive.py runs the same cases
awaited); the script itself is the same for every kind.
"""
from __future__ import annotations

import time

import pytest

import motorbus
from motorbus import Capability, DriveStatus, Units

from drive_kinds import KINDS, OUT_OF_TREE, kind, rig  # noqa: F401  (fixtures; KINDS, OUT_OF_TREE: re-exported)

pytestmark = pytest.mark.threaded


def test_enable_move_to_in_user_units_and_read_back(rig, kind):
    drive = rig.drive
    assert drive.kind == kind.kind and drive.units == Units("mm", kind.scale)
    kind.setup(drive)
    drive.enable()
    assert drive.status.enabled
    drive.move_to(12.34, timeout=10)
    assert drive.position == pytest.approx(12.34, abs=kind.scale)
    st = drive.status
    assert not st.moving and st.at_target and not st.fault
    drive.move_by(-2.34, timeout=10)
    assert drive.position == pytest.approx(10.0, abs=kind.scale)


def test_jog_then_stop(rig, kind):
    drive = rig.drive
    kind.setup(drive)
    drive.enable()
    start = drive.position
    drive.jog(kind.jog)
    deadline = time.monotonic() + 5
    while drive.velocity < kind.jog * 0.9:
        assert time.monotonic() < deadline, "never reached the jog speed"
        time.sleep(0.01)
    assert drive.status.moving
    drive.stop()
    drive.wait_idle(timeout=10)
    assert drive.velocity == 0
    assert not drive.status.moving
    assert drive.position > start


def test_home(rig, kind):
    drive = rig.drive
    kind.setup(drive)
    drive.enable()
    drive.home(kind.home, timeout=20)
    st = drive.status
    assert st.homed and not st.fault
    assert drive.position == pytest.approx(0.0, abs=kind.scale)


def test_an_exception_inside_with_stops_the_motor(rig, kind):
    drive = rig.drive
    kind.setup(drive)
    drive.enable()
    with pytest.raises(RuntimeError, match="script failed"):
        with drive:
            drive.jog(kind.jog)
            time.sleep(0.05)
            raise RuntimeError("script failed")
    assert drive.closed
    # Look again through another Drive object: the motor was stopped, so it comes to
    # rest (a jog left running would never be idle).
    other = rig.reopen()
    other.wait_idle(timeout=5)
    assert other.velocity == 0
    assert not other.status.moving


def test_fault_then_clear_faults(rig, kind):
    drive, sim = rig.drive, rig.sim
    kind.setup(drive)
    drive.enable()
    kind.fault(sim, drive)
    deadline = time.monotonic() + 5
    while not drive.status.fault:
        assert time.monotonic() < deadline, "the drive never reported the fault"
        time.sleep(0.01)
    assert drive.status.text
    with pytest.raises(motorbus.DriveFault):   # a faulted drive refuses motion, typed
        drive.move_to(2.0, timeout=5)
    kind.unfault(sim)
    drive.clear_faults()
    assert not drive.status.fault
    drive.enable()
    drive.move_to(1.0, timeout=10)
    assert drive.position == pytest.approx(1.0, abs=kind.scale)


def test_params_read_write_describe(rig, kind):
    drive = rig.drive
    info = drive.params.describe(kind.param)
    assert info.writable and info.type in ("int", "float")
    drive.params[kind.param] = kind.value
    assert drive.params[kind.param] == kind.value
    assert kind.param in drive.params and len(drive.params) > 3
    with pytest.raises(KeyError):
        drive.params["NO_SUCH_PARAMETER"]
    with pytest.raises(motorbus.InvalidArgument):
        drive.params.describe("NO_SUCH_PARAMETER")
    if info.maximum is not None:
        with pytest.raises(motorbus.InvalidArgument, match=r"outside"):
            drive.params[kind.param] = info.maximum + 1
        assert drive.params[kind.param] == kind.value  # the refused write changed nothing


def test_status_fields_and_capabilities(rig, kind):
    drive = rig.drive
    st = drive.status
    assert isinstance(st, DriveStatus)
    assert st.raw is not None and isinstance(st.text, str) and st.text
    assert not st.limit_positive and not st.limit_negative
    assert {Capability.POSITION, Capability.VELOCITY, Capability.HOMING} <= drive.capabilities
    assert kind.kind in motorbus.drive_kinds()


def test_closed_drive_refuses_and_bad_arguments_are_typed(rig, kind):
    drive = rig.drive
    with pytest.raises(motorbus.InvalidArgument, match="finite"):
        drive.move_to(float("nan"))
    with pytest.raises(motorbus.InvalidArgument, match="velocity"):
        drive.move_to(1.0, velocity=0)
    drive.close()
    with pytest.raises(motorbus.ClosedError):
        drive.position
