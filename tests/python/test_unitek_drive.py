"""The UNITEK Drive adapter beyond the shared Drive API script: torque, the homing
reading, refused velocity, units from the scalings, and what link loss does."""
from __future__ import annotations

import itertools
import time

import pytest

import motorbus
from motorbus.drives import unitek
from motorbus.drives.unitek import REVOLUTIONS, Status

pytestmark = pytest.mark.threaded
_names = itertools.count()


@pytest.fixture()
def rig():
    name = f"virtual:unitek-drive-{next(_names)}"
    with motorbus.open_bus(name) as sim_bus:
        sim = unitek.make_sim("0x201", bus=sim_bus, acc_ramp_ms=10, torque_continuous_num=10000)
        drive = motorbus.open_drive("unitek", bus=name, address="0x201", units=REVOLUTIONS)
        yield drive, sim
        drive.close()
        sim.close()


def wait(cond, timeout=5.0):
    end = time.monotonic() + timeout
    while not cond():
        assert time.monotonic() < end
        time.sleep(0.005)


def test_move_in_revolutions_and_tol(rig):
    drive, sim = rig
    drive.enable()
    drive.move_to(2.5, timeout=10)
    assert drive.position == pytest.approx(2.5, abs=1 / 65536)
    assert sim.value(0x6E) == 2.5 * 65536
    st = drive.status
    assert st.at_target and st.raw & Status.TOL and not st.moving
    with pytest.raises(motorbus.InvalidArgument, match="NDrive"):
        drive.move_to(1.0, velocity=5)


def test_jog_speed_from_n_max(rig):
    drive, sim = rig
    drive.enable()
    drive.jog(5.0)                           # 5 rev/s = 300 rpm = 10 % of N max 3000
    wait(lambda: drive.velocity == pytest.approx(5.0, rel=1e-3))
    assert sim.value(0x31) == 3277
    drive.stop()
    drive.wait_idle(timeout=5)
    with pytest.raises(motorbus.InvalidArgument, match="N max"):
        drive.jog(60.0)                      # 3600 rpm


def test_torque_is_a_native_feature(rig):
    drive, sim = rig
    assert motorbus.Capability.TORQUE in drive.capabilities
    drive.enable()
    drive.torque(50.0)                       # ex 5: 50 % (the manual rounds to 16380)
    wait(lambda: sim.value(0x90) == 16384)
    wait(lambda: sim.status & Status.ICNS)   # above the continuous limit set for this sim
    drive.torque(0.0)
    drive.stop()
    drive.wait_idle(timeout=5)


def test_home_needs_the_calibrated_bit(rig):
    drive, sim = rig
    drive.enable()
    with pytest.raises(motorbus.DriveFault, match="not calibrated"):
        drive.home()
    sim.set_calibrated(True)
    drive.move_to(1.0, timeout=10)
    drive.home(timeout=10)
    assert drive.position == 0 and drive.status.homed


def test_disable_and_store(rig):
    drive, sim = rig
    values = dict(drive.params)                  # every readable register, read once
    assert values["KERN_STATUS"] == 0x0181 and "MODE" not in values
    drive.params["MODE"] = 0                     # write-only, by name
    drive.params["ACC_RAMP"] = 123
    drive.store()
    wait(lambda: sim.eeprom()[0x35] == 123)
    drive.disable()
    assert not drive.status.enabled and not drive.status.fault
    with pytest.raises(motorbus.DriveFault, match="enable"):
        drive.jog(1.0)


def test_link_loss_the_drive_keeps_its_set_point(rig):
    """No watchdog reachable over CAN: the motor keeps turning, the host gets a typed error."""
    drive, sim = rig
    assert not drive.has_watchdog
    drive.enable()
    drive.jog(2.0)
    wait(lambda: drive.velocity > 1.9)
    sim.close()                              # the link to the drive is gone (it no longer answers)
    with pytest.raises(motorbus.TimeoutError):
        drive.position
    assert sim.speed_num == pytest.approx(2.0 * 65536 / (3000 / 60 * 65536 / 32767), rel=1e-3)
