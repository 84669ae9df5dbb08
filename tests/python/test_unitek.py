"""UNITEK client and simulator from Python (in process, on a SimClock where time matters):
register tables from TOML, the Pythonic client, scalings, the 8-register cyclic limit,
EEPROM over a power cycle, the T-Out model."""
from __future__ import annotations

import itertools
import time

import numpy as np
import pytest

import motorbus
from motorbus import _core
from motorbus.drives import unitek
from motorbus.drives.unitek import ModeBit, Reg, Status, Unitek

pytestmark = pytest.mark.threaded
_names = itertools.count()


@pytest.fixture()
def rig():
    name = f"virtual:unitek-py-{next(_names)}"
    clock = _core.runtime.SimClock(1_000_000_000)
    with motorbus.open_bus(name) as sim_bus, motorbus.open_bus(name) as host_bus:
        sim = unitek.make_sim("0x201", clock, bus=sim_bus, acc_ramp_ms=10)
        drive = Unitek(host_bus, 0x201, clock=clock, timeout=0.5)
        yield drive, sim, clock, host_bus
        drive.close()
        sim.close()


def settle(sim, host_bus) -> None:
    want = host_bus.counters.tx_frames
    end = time.monotonic() + 2
    while sim.counters.frames_in + sim.counters.ignored < want:
        assert time.monotonic() < end
        time.sleep(0.0005)


def test_builtin_table_is_the_manual(tmp_path):
    t = unitek.builtin_registers()
    assert sorted(r.regid for r in t.rows()) == [0x30, 0x31, 0x35, 0x40, 0x51, 0x52, 0x68, 0x6E, 0x84, 0x90, 0xA8]
    pos = t["POS_DEST"]
    assert (pos.bits, pos.signed, pos.min, pos.max, pos.unit) == (32, True, -2147483647, 2147483647, "rev")
    assert t[0x31].quantity == _core.unitek.Quantity.SPEED
    assert not t["KERN_STATUS"].writable and not t["MODE"].readable
    with pytest.raises(unitek.UnknownRegister) as e:
        t[0x99]
    assert e.value.regid == 0x99 and isinstance(e.value, KeyError)


def test_toml_register_list_extends_the_table(tmp_path):
    f = tmp_path / "ndrive.toml"
    f.write_text('[[register]]\nregid = 0x34\nname = "SPEED_LIM"\nsigned = true\nquantity = "speed"\n'
                 'unit = "rpm"\nmin = -32767\nmax = 32767\n'
                 '[[register]]\nregid = 0xE0\nname = "TEMP"\naccess = "ro"\nscale = 0.1\nunit = "degC"\n')
    t = unitek.load_registers(f)
    assert t["SPEED_LIM"].regid == 0x34 and t[0xE0].scale == 0.1
    assert unitek.ndrive_registers()["POS_IST"].regid == 0x6D
    bad = tmp_path / "bad.toml"
    for text, word in [('[[register]]\nname = "X"\n', "regid"), ('[[register]]\nregid = 1\nname = "X"\nbits = 24\n', "bits"),
                       ('[[register]]\nregid = 1\nname = "X"\ncolour = 1\n', "colour"),
                       ('[[register]]\nregid = 0x3D\nname = "X"\n', "0x3D"), ("= nope", "TOML"),
                       ('[[register]]\nregid = 1\nname = "X"\nmin = 1\n', "min and max")]:
        bad.write_text(text)
        with pytest.raises(motorbus.InvalidArgument, match=word):
            unitek.load_registers(bad)


def test_scalings_from_section_6():
    s = _core.unitek.Scalings(n_max_rpm=2000)
    t = unitek.builtin_registers()
    assert s.to_num(t["SPEED_CMD"], 1500) == 24575
    assert s.to_num(t["POS_DEST"], 200) == 13_107_200
    assert _core.unitek.continuous_current_num("DS 205/405", 2) == 44
    assert [d["device"] for d in _core.unitek.device_currents()] == ["DS 205/405", "DS 412", "DS 420"]


def test_codec_functions():
    assert _core.unitek.encode_write(0x6E, 3_000_000, 32) == bytes.fromhex("6EC0C62D00")
    assert _core.unitek.encode_request(0x30, 100) == bytes.fromhex("3D3064")
    assert _core.unitek.decode_from_drive(bytes.fromhex("4081315A")) == (0x40, 0x3181, 16)
    assert _core.unitek.decode_to_drive(bytes.fromhex("31CD0C99")) == (0x31, 0x0CCD, 16)
    with pytest.raises(unitek.FrameError) as e:
        _core.unitek.decode_from_drive(b"\x40\x81\x01\x00\x00")
    assert e.value.byte == 5 and e.value.data == b"\x40\x81\x01\x00\x00"
    assert isinstance(e.value, motorbus.ProtocolError)


def test_client_reads_writes_and_typed_errors(rig):
    drive, sim, clock, bus = rig
    assert drive.status == Status.ENA | Status.POSITION_CONTROL | Status.SPEED_CONTROL
    drive.write("ACC_RAMP", 250)
    assert drive.read(Reg.ACC_RAMP) == 250
    drive.speed_rpm = 300
    settle(sim, bus)
    clock.advance(100_000_000)
    assert drive.speed_rpm == pytest.approx(300, abs=0.1)
    with pytest.raises(unitek.UnknownRegister):
        drive.write(0x99, 1)
    with pytest.raises(motorbus.InvalidArgument, match="read-only"):
        drive.write(Reg.SPEED_IST, 1)
    with pytest.raises(motorbus.InvalidArgument, match="outside"):
        drive.write(Reg.SPEED_CMD, 40000)
    with pytest.raises(motorbus.InvalidArgument, match="write-only"):
        drive.read(Reg.MODE)
    drive.disable()
    assert drive.mode == ModeBit.DISABLE and not drive.status & Status.ENA


def test_cyclic_limit_and_period_replacement(rig):
    drive, sim, clock, bus = rig
    regs = [Reg.SPEED_IST, Reg.SPEED_CMD, Reg.ACC_RAMP, Reg.KERN_STATUS, Reg.EVENT_MASK, Reg.POS_DEST,
            Reg.TORQUE_CMD, Reg.POS_IST]
    for r in regs:
        drive.subscribe(r, 10)
    with pytest.raises(unitek.CyclicLimit, match="at most 8"):
        drive.subscribe(Reg.REG_A8, 10)
    drive.subscribe(Reg.SPEED_IST, 20)            # a repeat: new period, no 9th slot
    settle(sim, bus)
    assert dict(sim.cyclic)[0x30] == 20 and len(sim.cyclic) == 8
    for r in regs:
        drive.unsubscribe(r)
    settle(sim, bus)
    assert sim.cyclic == []


def test_stream_callbacks_and_numpy(rig):
    drive, sim, clock, bus = rig
    got = []
    s = drive.subscribe(Reg.POS_DEST, 5, capacity=64, callback=lambda r, t, v: got.append((r, t, v)))
    settle(sim, bus)
    for _ in range(10):
        clock.advance(5_000_000)
        sim.service()
    end = time.monotonic() + 2
    while s.count < 11 or len(got) < 11:   # the callback runs after the sample is stored
        assert time.monotonic() < end
        time.sleep(0.001)
    t, v = s.read()
    assert isinstance(t, np.ndarray) and t.dtype == np.int64 and len(t) == 11
    assert (v == 0).all() and len(got) == 11 and got[0][0] == 0x6E
    assert s.physical(np.array([65536]))[0] == pytest.approx(1.0)
    assert s.read()[0].size == 0 and s.lost == 0


def test_ring_overrun_is_counted_as_lost(rig):
    drive, sim, clock, bus = rig
    s = drive.subscribe(Reg.SPEED_IST, 1, capacity=16)
    settle(sim, bus)
    for _ in range(40):
        clock.advance(1_000_000)
        sim.service()
    end = time.monotonic() + 2
    while s.count < 41:
        assert time.monotonic() < end
        time.sleep(0.001)
    t, v = s.read()
    assert len(t) == 16 and s.lost == 41 - 16


def test_eeprom_survives_power_cycle_and_rx_id_change(rig):
    drive, sim, clock, bus = rig
    drive.write(Reg.ACC_RAMP, 321)
    drive.set_receive_id(0x210)
    assert drive.read(Reg.ACC_RAMP) == 321
    drive.store_eeprom(1)
    drive.write(Reg.ACC_RAMP, 5)
    settle(sim, bus)
    sim.power_cycle()
    assert sim.rx_id == 0x210 and drive.read(Reg.ACC_RAMP) == 321
    assert sim.eeprom()[0x35] == 321


def test_with_block_stops_on_error(rig):
    drive, sim, clock, bus = rig
    with pytest.raises(RuntimeError):
        with Unitek(bus, 0x201, clock=clock, on_error="disable") as d:
            d.speed_rpm = 100
            raise RuntimeError("boom")
    settle(sim, bus)
    assert not sim.status & Status.ENA


def test_a_client_still_open_at_exit_is_stopped_with_on_exit(rig):
    """The native client has the shape of every kind's: a subclass of the C++ client
    (no forwarding layer) whose exit hook applies ``on_exit``, as ArcusClient's and
    DmacClient's do."""
    from motorbus import _stop_at_exit
    drive, sim, clock, bus = rig
    d = Unitek(bus, 0x201, clock=clock, on_exit="disable")
    assert isinstance(d, _core.unitek.Client)
    assert d in _stop_at_exit._live
    d.speed_rpm = 100
    settle(sim, bus)
    assert sim.status & Status.ENA
    d._stop_at_exit()                  # what the atexit hook and SIGTERM do to each live client
    settle(sim, bus)
    assert not sim.status & Status.ENA
    d.close()
    assert d not in _stop_at_exit._live


def test_t_out_model_disables_a_silent_link():
    name = f"virtual:unitek-py-{next(_names)}"
    with motorbus.open_bus(name) as sim_bus, motorbus.open_bus(name) as host_bus:
        sim = unitek.make_sim("0x201", bus=sim_bus, t_out_ms=50)
        try:
            d = Unitek(host_bus, 0x201)
            d.write(Reg.SPEED_CMD, 1000)
            assert d.status & Status.ENA
            end = time.monotonic() + 3
            while sim.status & Status.ENA:
                assert time.monotonic() < end, "T-Out never tripped"
                time.sleep(0.01)
            assert sim.t_out_tripped and sim.speed_num == 0
            d.close()
        finally:
            sim.close()


def test_plugin_and_addresses():
    plugin = motorbus.registry.drive_plugin("unitek")
    assert plugin.transport == "can" and plugin.default_address == "0x201"
    assert plugin.check_address("201") == "0x201" and plugin.check_address(0x27F) == "0x27F"
    for bad in ("0x200", "0x280", "zz", True):
        with pytest.raises(motorbus.InvalidArgument):
            plugin.check_address(bad)
    with pytest.raises(motorbus.InvalidArgument, match="unknown"):
        unitek.make_sim("0x201", colour=1)
    assert not unitek.UnitekDrive.has_watchdog


def test_eeprom_file_survives_a_new_sim(tmp_path):
    path = tmp_path / "unitek.json"
    name = f"virtual:unitek-py-{next(_names)}"
    with motorbus.open_bus(name) as sim_bus, motorbus.open_bus(name) as host_bus:
        sim = unitek.make_sim("0x201", bus=sim_bus, store_path=str(path))
        d = Unitek(host_bus, 0x201)
        d.write(Reg.ACC_RAMP, 777)
        d.set_receive_id(0x222)
        d.store_eeprom(0)
        end = time.monotonic() + 2
        while not path.exists():
            assert time.monotonic() < end
            time.sleep(0.005)
        d.close()
        sim.close()
    again = unitek.make_sim("0x201", store_path=str(path))   # the next power-up reads the file
    assert again.rx_id == 0x222 and again.value(Reg.ACC_RAMP) == 777
    again.close()
    options = motorbus.registry.drive_plugin("unitek").store_options(str(tmp_path), "0x201")
    assert options == {"store_path": str(tmp_path / "unitek-0x201.eeprom.json")}  # sim serve --store-dir
    path.write_text("[1, 2]")
    with pytest.raises(motorbus.InvalidArgument, match="EEPROM"):
        unitek.make_sim("0x201", store_path=str(path))


def test_bad_arguments_are_typed(rig):
    drive, sim, clock, bus = rig
    with pytest.raises(motorbus.InvalidArgument, match="interval"):
        drive.subscribe(Reg.SPEED_IST, 0)
    with pytest.raises(motorbus.InvalidArgument, match="interval"):
        drive.subscribe(Reg.SPEED_IST, 255)
    with pytest.raises(motorbus.InvalidArgument, match="capacity"):
        drive.subscribe(Reg.SPEED_IST, 10, capacity=0)
    with pytest.raises(motorbus.InvalidArgument, match="timeout"):
        drive.read(Reg.SPEED_IST, timeout=-1)
    with pytest.raises(motorbus.InvalidArgument, match="regid"):
        drive.write(300, 1)
    with pytest.raises(motorbus.InvalidArgument, match="EEPROM level"):
        drive.store_eeprom(3)
    with pytest.raises(motorbus.InvalidArgument, match="0x201..0x27F"):
        drive.set_receive_id(0x300)
    with pytest.raises(motorbus.InvalidArgument, match="bus"):
        _core.unitek.Client(None)
    with pytest.raises(motorbus.InvalidArgument, match="clock"):
        _core.unitek.Sim(None)
    with pytest.raises(motorbus.InvalidArgument, match="rx_id"):
        _core.unitek.Sim(clock, rx_id=0x100)
    with pytest.raises(motorbus.InvalidArgument, match="N max"):
        unitek.make_sim("0x201", n_max_rpm=0)
    with pytest.raises(motorbus.InvalidArgument, match="device"):
        Unitek(bus, 0x201, device="DS 999")
    with pytest.raises(motorbus.InvalidArgument, match="on_error"):
        Unitek(bus, 0x201, on_error="explode")
    with pytest.raises(motorbus.InvalidArgument, match="bits 16 or 32"):
        _core.unitek.encode_write(0x31, 1, 24)
