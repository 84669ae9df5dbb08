"""The PMC007 Python client against the simulator on an in-process virtual bus (SimClock
for the motion): named access to every object, the status IntFlags with write-1-to-clear,
the offline program (assemble, upload, read back, verify, execute on the clock), PDO
configuration with typed callbacks, the units and params of the Drive adapter."""
from __future__ import annotations

import itertools
import threading

import pytest

import motorbus
from motorbus import _core
from motorbus.drives import pmc007
from motorbus.drives.pmc007 import ControllerStatus, ErrorStatus, Pmc007

pytestmark = pytest.mark.threaded
_names = itertools.count()


@pytest.fixture
def rig():
    name = f"virtual:pmc007-py-{next(_names)}"
    clock = _core.runtime.SimClock(1_000_000_000)
    with motorbus.open_bus(name) as sim_bus, motorbus.open_bus(name) as host_bus:
        sim = pmc007.make_sim(5, clock=clock, bus=sim_bus)
        client = Pmc007(host_bus, 5)
        yield sim, client, clock
        client.close()
        sim.close()


def advance(sim, clock, seconds: float) -> None:
    clock.advance(int(seconds * 1e9))
    sim.poll()


def test_every_object_has_a_name_and_resolves_every_way():
    assert len(pmc007.OBJECTS) == 210
    assert len({v.index for v in pmc007.OBJECTS.values()}) == 73
    for form in ("start_speed", "Start speed", "0x6006", "6006h", "0x6006:00", (0x6006, 0), 0x6006):
        assert Pmc007.resolve(form) == "start_speed"
    assert Pmc007.resolve("0x600F:01") == "external_emergency_stop.enable"
    with pytest.raises(motorbus.InvalidArgument, match="no object"):
        Pmc007.resolve("0x6030")


def test_status_intflags_and_write_one_to_clear(rig):
    sim, c, clock = rig
    assert c.error_status == ErrorStatus(0)
    sim.inject_error(int(ErrorStatus.UVLO | ErrorStatus.TSD))
    assert c.error_status == ErrorStatus.UVLO | ErrorStatus.TSD
    assert c.read("error_register") == 0x01 | 0x04 | 0x08          # generic, voltage, temperature
    with pytest.raises(motorbus.canopen.SdoAbortError) as e:
        c.step(100, speed=1000)
    assert e.value.code == 0x08000022
    c.clear_errors(ErrorStatus.UVLO)
    assert c.error_status == ErrorStatus.TSD
    c.clear_errors()
    c.step(1000, speed=1000)
    assert c.controller_status == ControllerStatus.BUSY
    c.clear_status(0xFF)                                               # busy cannot be cleared
    assert c.busy
    assert c.read("manufacturer_status_register") == 0x08


def test_position_speed_and_absolute_moves_on_the_sim_clock(rig):
    sim, c, clock = rig
    c.step(2000, speed=1000)
    advance(sim, clock, 1.0)
    assert c.position == 1000
    advance(sim, clock, 1.5)
    assert c.position == 2000 and not c.busy
    c.move_absolute(-500, speed=500)
    advance(sim, clock, 6)
    assert c.position == -500
    c.run(-800)
    advance(sim, clock, 1)
    assert sim.velocity == pytest.approx(-800)
    c.stop()
    assert not c.busy
    c.position = 42
    assert c.position == 42


def test_microstepping_does_not_rescale_the_counter(rig):
    sim, c, clock = rig
    c.position = 1600
    c.microstepping = 16
    assert c.position == 1600          # B-P15
    with pytest.raises(motorbus.canopen.SdoAbortError):
        c.microstepping = 3


def test_offline_program_upload_read_back_verify_and_run(rig):
    sim, c, clock = rig
    text = "VSET 0,1000\nDIR 0,1\nROT 0,500\nWAIT 1,0\nDIR 0,0\nROT 0,200\nWAIT 1,0\n"
    words = c.upload_program(text)
    assert words == pmc007.assemble(text)
    assert c.read_program() == words and c.verify_program(text)
    assert list(sim.flash_program) == words
    assert pmc007.disassemble(words) == text
    c.start_program()
    advance(sim, clock, 0.25)
    assert c.position == 250
    advance(sim, clock, 0.35)           # 0.5 s: first move done, second one runs back
    assert c.position == 500 - 100
    advance(sim, clock, 1)
    assert c.position == 300 and not sim.program_running
    c.run_instruction(2)                # "try run current command": ROT 0,500 at 6003h
    advance(sim, clock, 1)
    assert c.position == 300 - 500      # direction was left at 0 by the program


def test_tpdo_typed_callback(rig):
    sim, c, clock = rig
    got: list = []
    seen = threading.Event()
    c.write("gpio_parameters.direction", 0x3)
    cob = c.configure_tpdo(1, ["gpio_value", "controller_status"], cob_id=0x187, inhibit_100us=50,
                           event_timer_ms=1000)
    assert cob == 0x187
    c.on_tpdo(cob, lambda values: (got.append(values), seen.set()))
    c.nmt(0x01)
    c.write("gpio_value", 0x3)
    assert seen.wait(2)
    deadline = threading.Event()
    for _ in range(100):
        if any(v == {"gpio_value": 3, "controller_status": 0} for v in got):
            break
        deadline.wait(0.02)
    assert {"gpio_value": 3, "controller_status": 0} in got
    with pytest.raises(motorbus.canopen.SdoAbortError) as e:
        c.configure_tpdo(2, ["step_command"])       # not mappable (Appendix 1)
    assert e.value.code == 0x06040041


def test_drive_adapter_units_params_and_home(rig):
    sim, c, clock = rig
    drive = pmc007.Pmc007Drive(c, units=motorbus.Units("mm", 0.01), on_error=None, on_exit=None)
    assert drive.params.describe("start_speed").persists
    assert not drive.params.describe("motor_position").persists
    drive.params["0x6006"] = 500
    assert drive.params["Start speed"] == 500
    with pytest.raises(motorbus.InvalidArgument, match="outside"):
        drive.params["acceleration_coefficient"] = 9
    assert not drive.has_watchdog
    st = drive.status
    assert st.enabled and not st.moving and st.raw == (0, 0)


def test_make_sim_refuses_unknown_options_and_bad_nodes():
    with pytest.raises(motorbus.InvalidArgument, match="unknown"):
        pmc007.make_sim(5, colour="red")
    with pytest.raises(motorbus.InvalidArgument, match="1..127"):
        pmc007.make_sim(128)
    assert pmc007.Pmc007Drive.check_address(" 7 ") == "7"


def test_rpdo_and_numpy_tpdo_stream(rig):
    sim, c, clock = rig
    rx = c.configure_rpdo(1, ["motor_position"])
    tx = c.configure_tpdo(1, ["motor_position", "controller_status"], transmission_type=255)
    stream = c.tpdo_stream(tx, capacity=8)
    c.nmt(0x01)
    for p in (100, 200, 300):
        c.send_rpdo(rx, {"motor_position": p})
        for _ in range(200):
            if sim.position == p:
                break
            threading.Event().wait(0.005)
        assert sim.position == p
    for _ in range(200):
        if 300 in stream.values()["motor_position"]:
            break
        threading.Event().wait(0.005)
    v = stream.values()
    assert v.dtype.names == ("t", "motor_position", "controller_status")
    assert list(v["motor_position"][-3:]) == [100, 200, 300]
    assert (v["t"][1:] >= v["t"][:-1]).all()
    stream.close()
    with pytest.raises(motorbus.InvalidArgument, match="needs a value"):
        c.send_rpdo(rx, {})


def test_a_client_still_open_at_exit_is_stopped_with_on_exit(rig):
    """The native client has every kind's shape: the exit hook knows it and applies
    ``on_exit`` (it used to apply on_exit when a ``with`` ended normally, and nothing at
    interpreter exit); a closed client is forgotten."""
    from motorbus import _stop_at_exit
    sim, c, clock = rig
    other = Pmc007(c.bus, 5, on_exit="disable")
    assert other in _stop_at_exit._live
    other.enable(True)
    assert c.enabled
    other._stop_at_exit()              # what the atexit hook and SIGTERM do to each live client
    assert not c.enabled
    other.close()
    assert other not in _stop_at_exit._live
    with Pmc007(c.bus, 5, on_exit="disable") as d:   # a normal end of `with` leaves the motor be
        d.enable(True)
    assert c.enabled


def test_sim_serve_store_dir_keeps_the_flash(tmp_path):
    from motorbus.sim import make_sim as make_any_sim
    name = f"virtual:pmc007-py-store-{next(_names)}"
    with motorbus.open_bus(name) as sim_bus, motorbus.open_bus(name) as host_bus:
        sim = make_any_sim("pmc007", "5", store_dir=str(tmp_path))
        sim.attach(sim_bus)
        c = Pmc007(host_bus, 5)
        c["start_speed"] = 321
        c.save()
        c.close()
        sim.close()
    assert (tmp_path / "pmc007-5.flash").exists()
    again = make_any_sim("pmc007", "5", store_dir=str(tmp_path))
    assert int.from_bytes(again.od["Start speed"].raw, "little") == 321
    again.close()
