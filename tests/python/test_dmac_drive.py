"""DmacDrive through motorbus.open_drive on a served pty in real time: params,
homing, faults, units, status, link loss and the safety words."""
from __future__ import annotations

import pytest

import motorbus
from motorbus.drive import Units, open_drive
from motorbus.drives.dmac import DmacErrorWord, DmacStatus, HomingFailed, make_sim
from motorbus.serial import PtyLineServer


@pytest.fixture()
def rig():
    sim = make_sim("00", reference_switch=3000)  # IN5 turns on at 0.3 rev
    server = PtyLineServer([sim])
    d = open_drive("dmac", line=server.slave_path, address="00", units=Units("mm", 0.01))
    d.params["#ACCEL_TIME"] = 20
    d.params["DECEL_TIME"] = 20
    yield d, sim, server
    d.close()
    server.close()


def test_enable_move_and_status(rig):
    d, sim, _ = rig
    d.enable()
    assert d.status.enabled and not d.status.fault
    d.move_to(50.0, velocity=500.0)           # 5000 increments at 50000 inc/s
    assert d.position == 50.0
    assert d.params["#HIGH_SPEED"] == 60000    # the move's 30000 was for that move only
    d.move_by(-20.0)
    assert d.position == 30.0
    st = d.status
    assert not st.moving and st.at_target and isinstance(st.raw[0], DmacStatus)
    assert "DMAC 00" in st.text


def test_params_describe_and_refusals(rig):
    d, _, _ = rig
    info = d.params.describe("HIGH_SPEED")
    assert (info.name, info.default, info.maximum, info.persists, info.unit) == ("#HIGH_SPEED", 60000, 400000, True, "0.01 rpm")
    assert d.params.describe("#STATUS").writable is False
    assert "#LOW_SPEED" in d.params
    with pytest.raises(KeyError):
        d.params["#NOPE"]
    with pytest.raises(motorbus.InvalidArgument):
        d.params["#TORQUE_RATIO"] = 101
    with pytest.raises(motorbus.InvalidArgument):
        d.params["#SPEED"] = 5
    d.params["TORQUE_RATIO"] = 70
    assert d.params["#TRA"] == 70


def test_home_reference_and_here(rig):
    d, sim, _ = rig
    d.enable()
    d.params["#LOW_SPEED"] = 60000            # search at 600 rpm: the switch is 0.3 rev away
    d.home()
    assert d.status.homed and d.position == 0.0
    assert sim.read("#CAPTURE") == 3000       # where IN5 rose, in the old frame
    d.move_to(10.0)
    d.home("here")
    assert d.position == 0.0
    with pytest.raises(motorbus.InvalidArgument):
        d.home("index")


def test_home_without_a_switch_fails_typed():
    sim = make_sim("00", positive_end_switch=2000)
    with PtyLineServer([sim]) as server:
        with open_drive("dmac", line=server.slave_path, address="00") as d:
            d.enable()
            d.native.hard_ends("ALL")
            d.params["#LOW_SPEED"] = 60000
            with pytest.raises(HomingFailed) as failed:
                d.home(timeout=5)             # the end-stop at 2000 comes before IN5 at 3000
            e = failed.value
            assert isinstance(e, motorbus.LimitReached) and e.side == 1 and "IN5 reference edge" in e.reason
            assert 2000 <= e.position < 3000 and not d.status.homed


def test_fault_then_clear(rig):
    d, sim, _ = rig
    d.enable()
    sim.set_supply_voltage(11000)             # undervoltage on a DMAC34
    st = d.status
    assert st.fault and not st.enabled and DmacErrorWord.UNDERVOLTAGE in st.raw[1]
    with pytest.raises(motorbus.DriveFault, match=r"cause is still present .*SUPPLY_VOLTAGE 11 V.*clear_faults\(\)"):
        d.move_to(1.0)
    with pytest.raises(motorbus.DriveFault, match="latched again at once.*undervoltage.*still present"):
        d.clear_faults()
    sim.set_supply_voltage(32000)
    d.clear_faults()
    assert not d.status.fault
    d.move_to(1.0)
    assert d.position == 1.0


def test_jog_then_stop_and_quick_stop(rig):
    d, _, _ = rig
    d.enable()
    d.jog(100.0)
    assert d.status.moving
    d.stop()
    d.wait_idle(timeout=5)
    d.jog(-100.0)
    d.quick_stop()
    assert not d.status.moving


def test_exception_in_with_stops_and_link_loss_raises_linkdown():
    sim = make_sim("00")
    server = PtyLineServer([sim])
    d = open_drive("dmac", line=server.slave_path, address="00", on_error="quick_stop")
    with pytest.raises(RuntimeError):
        with d:
            d.enable()
            d.jog(1000.0)
            raise RuntimeError("boom")
    assert not sim.state().status & int(DmacStatus.MOVEMENT)   # HALT: at rest at once
    d2 = open_drive("dmac", line=server.slave_path, address="00")
    server.close()
    with pytest.raises(motorbus.LinkDown):
        d2.position
    d2.close()


def test_plugin_fields():
    plugin = motorbus.registry.drive_plugin("dmac")
    assert (plugin.kind, plugin.transport, plugin.default_address, plugin.default_baud) == ("dmac", "serial", "00", 38400)
    assert plugin.check_address("7") == "07"
    with pytest.raises(motorbus.InvalidArgument):
        plugin.check_address("64")
    with pytest.raises(motorbus.InvalidArgument):
        open_drive("dmac", line="/dev/null", address="00", on_error="brake")
