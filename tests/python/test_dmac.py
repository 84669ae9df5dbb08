"""motorbus.drives.dmac from Python: the simulator line by line, the client on a
pty with simulated time, the sequencer, interpolation streaming, the context
manager and the exit-time STOP, and the hostile rows of HOSTILE_INPUTS 2.9."""
from __future__ import annotations

import os
import pathlib
import subprocess
import sys
import textwrap

import pytest

import motorbus
from motorbus._core.runtime import SimClock
from motorbus.drives import dmac
from motorbus.drives.dmac import (CommandRejected, DmacClient, DmacStatus, UnknownCommand, make_sim, open_line,
                                  stream_interpolation, synchro)
from motorbus.serial import LineDevice, PtyLineServer

MS = 1_000_000


@pytest.fixture()
def bus():
    """Modules 00, 01 and 02 on one pty; a client per module running on the SimClock."""
    clock = SimClock()
    sims = [make_sim(f"{a:02d}", clock=clock) for a in range(3)]
    with PtyLineServer(sims) as server:
        link = open_line(server.slave_path, timeout=0.5)
        sleep = lambda s: clock.advance(int(s * 1e9))  # noqa: E731
        clients = [DmacClient(link, address=a, sleep=sleep) for a in range(3)]
        for c in clients:
            c.brake(False)  # DMAC34: factory BRAKE ON (annex 7.1)
        yield clock, sims, link, clients
        for c in clients:
            c.close()


def test_make_sim_factory_and_line_settings():
    sim = make_sim("07", model="DMAC23-1", supply_voltage=24000)
    assert sim.address == 7
    assert sim.on_line(b"07READ #SVO") == b"07#SVO=+24000\r\n"
    assert sim.on_line(b"00READ #SVO") == b""
    assert sim.request_terminator() == b"\r"
    assert sim.reply_terminator == b"\r\n"
    assert dmac.LINE_SETTINGS["reply_terminators"] == [b"\r\n"]
    with pytest.raises(motorbus.InvalidArgument):
        make_sim("64")
    with pytest.raises(motorbus.InvalidArgument):
        make_sim("00", colour="red")
    crlf = make_sim(0, request_terminator="\r\n", reply_terminator="\n")
    assert crlf.request_terminator() == b"\r\n"
    assert crlf.on_line(b"00READ #POS") == b"00#POS=+0\n"


def test_sim_profile_times_on_sim_clock():
    clock = SimClock()
    sim = make_sim("00", clock=clock)
    sim.on_line(b"00BRAKE OFF")
    sim.on_line(b"00MOVE_SPEED 30000")  # ATI 1000 ms, HSP 60000: 0.5 s to 30000
    clock.advance(250 * MS)
    assert abs(sim.state().speed - 15000) <= 100
    clock.advance(250 * MS)
    assert sim.on_line(b"00READ #SPEED") == b"00#SPE=+30000\r\n"
    sim.on_line(b"00HALT")
    assert sim.state().speed == 0


def test_sim_end_stop_switches_stop_the_axis_on_the_switch():
    # The simulated axis is a MotorModel: the switch sits at a machine position
    # and stops the move exactly there (1/10000 rev = one model step).
    clock = SimClock()
    sim = make_sim("00", clock=clock, positive_end_switch=2500, negative_end_switch=-2500)
    sim.on_line(b"00BRAKE OFF, HARD_ENDS ALL, MOVE_SPEED 6000")
    clock.advance(2000 * MS)
    assert sim.on_line(b"00READ #POSITION") == b"00#POS=+2500\r\n"
    status = sim.state().status
    assert status & (1 << 16)          # bit 17: hard positive end-stop
    assert status & (1 << 31)          # bit 32: abnormal stop
    assert sim.on_line(b"00READ #SPEED") == b"00#SPE=+0\r\n"
    assert sim.on_line(b"00READ #INPUT.9") == b"00#INP.9=+1\r\n"
    sim.on_line(b"00MOVE_ON 10")       # further CW is refused (#ERROR bit 7)
    assert sim.on_line(b"00READ #ERROR") == b"00#ERR=+64\r\n"
    nc = make_sim("00", positive_end_switch=1000, end_switch_active_low=True)
    assert nc.on_line(b"00READ #INPUT.9") == b"00#INP.9=+1\r\n"   # away from an active-low switch


def test_client_typed_moves_status_and_errors(bus):
    clock, sims, link, (c0, c1, c2) = bus
    c1.set_profile(high_speed=30000, accel_ms=200, decel_ms=200)
    t0 = clock.now()
    c1.move_to(50000)
    st = c1.status
    assert isinstance(st, DmacStatus)
    assert DmacStatus.BUSY | DmacStatus.MOVEMENT | DmacStatus.POWER_ON in st
    assert c1.wait_idle(timeout=30.0, poll=0.001) == 50000
    assert 1.5 < (clock.now() - t0) / 1e9 < 3.0
    assert c1.position == 50000
    c1.position = 0
    assert c1.position == 0
    assert c0.position == 0
    c2.move_speed(-20000)
    clock.advance(2000 * MS)
    assert c2.speed == -20000
    c2.halt()
    assert c2.speed == 0
    with pytest.raises(UnknownCommand):
        c0.command("FROB 1")
    with pytest.raises(CommandRejected) as e:
        c0.command("#TORQUE_RATIO:=101")
    assert e.value.error == 1 << 6  # bit 7 (1-based)
    assert isinstance(e.value, motorbus.DriveFault)
    sims[0].inject_error(5)
    err = c0.error
    assert err.bit(5) and err.names == ["overvoltage"] and err == dmac.DmacErrorWord.OVERVOLTAGE
    c0.clear_error()
    assert not c0.error
    assert dmac.status_names(0x13000800) == ["s_curve", "power_on", "movement", "busy"]
    v = c0.request_version()
    assert (v.code, v.product, v.version, v.release) == ("H142", "DMAC34-1", 1, 7)


def test_client_variables_and_bits(bus):
    clock, sims, link, (c0, _, _) = bus
    c0.write("#V5", -40)
    assert c0.read("#V5", "hex") == -40
    assert c0.read("V5") == -40
    c0.write_bit("#OUTPUT", 2, True)
    assert c0.read_bit("#OUTPUT", 2) is True
    assert c0.outputs == 2
    c0.set_memorized_var(3, 11)
    c0.set_user_var(3, 12)
    c0.module_reset()
    assert (c0.memorized_var(3), c0.user_var(3)) == (11, 0)
    c0.set_timer(2, 300)
    clock.advance(100 * MS)
    assert c0.timer(2) == 200
    sims[0].set_input(3, True)
    assert c0.inputs == 4
    c0.set_soft_limits(-80000, 100000)
    assert c0.soft_limits() == (-80000, 100000)
    c0.set_interpolation(time_ms=50, fifo_size=16)
    assert (c0.read("#ITI"), c0.read("#IFI"), c0.read("#IMO")) == (50, 16, 0)
    sims[0].set_analog(2, 1500)
    assert c0.analog_input(2) == 1500
    assert (c0.motor_temperature, c0.cpu_temperature) == (650, 520)
    c0.torque_ratio = 70
    assert c0.torque_ratio == 70 and c0.high_speed == 60000
    with pytest.raises(motorbus.InvalidArgument):
        c0.write("#STATUS", 1)
    with pytest.raises(motorbus.InvalidArgument):
        c0.read("#NOPE")


def test_sequencer_upload_read_back_run(bus):
    clock, sims, link, (c0, _, _) = bus
    c0.upload_sequence(["MOVE_ON 10000", "WAIT 2000", "JUMP 1"])
    assert c0.read_sequence(1, 3) == ["MON +10000", "WAI +2000", "JUM +1"]
    c0.start_sequence(1)
    assert DmacStatus.SEQUENCER_RUN in c0.status
    clock.advance(2001 * MS)
    assert c0.position == 10000
    clock.advance(2002 * MS)
    assert c0.position == 20000
    c0.stop()
    assert not DmacStatus.SEQUENCER_RUN in c0.status
    # OPEN_SEQ erases the whole program: one upload holds the main part and the subroutine.
    c0.upload_sequence(["#V1:=#V1 + 1", "CALL 14", "JUMP 0", "NOP", "#V2:=#V1 * 100", "RETURN"], first=10)
    assert c0.read_sequence_line(1) == ""
    c0.on_reset = 10
    c0.module_reset()
    clock.advance(10 * MS)
    assert (c0.user_var(1), c0.user_var(2)) == (1, 100)
    with pytest.raises(motorbus.InvalidArgument):
        c0.upload_sequence(["NOT A COMMAND"])


def test_interpolation_streaming_three_axes(bus):
    clock, sims, link, clients = bus
    segments = [[300, -100, 50]] * 80
    stats = stream_interpolation(clients, segments, interpol_time_ms=10, fifo_size=8,
                                 sleep=lambda s: clock.advance(int(s * 1e9)))
    assert stats.segments == 80
    assert stats.xon_errors > 0
    assert stats.underruns == 0
    clock.advance(2000 * MS)
    assert [s.state().position for s in sims] == [24000, -8000, 4000]


def test_synchro_on_top(bus):
    clock, sims, link, (c0, c1, _) = bus
    synchro(link, "ON")
    c0.move_to(1000)
    c1.move_to(-1000)
    clock.advance(100 * MS)
    assert c0.position == 0
    synchro(link, "TOP")
    synchro(link, "OFF")
    c0.status  # globals have no reply: a query tells us the line got that far
    clock.advance(3000 * MS)
    assert (c0.position, c1.position) == (1000, -1000)


def test_context_manager_stops_on_exception(bus):
    clock, sims, link, (c0, _, _) = bus
    with pytest.raises(RuntimeError):
        with DmacClient(link, address=0) as ax:
            ax.move_speed(60000)
            clock.advance(2000 * MS)
            raise RuntimeError("operator error")
    clock.advance(50 * MS)
    st = sims[0].state()
    assert 0 < st.speed < 60000  # decelerating after STOP
    clock.advance(2000 * MS)
    assert sims[0].state().speed == 0


def test_exit_time_stop_from_another_process():
    """A script that starts a move and exits without stopping: atexit sends STOP."""
    clock = SimClock()
    sim = make_sim("05", clock=clock)
    sim.on_line(b"05BRAKE OFF")
    with PtyLineServer([sim]) as server:
        script = textwrap.dedent(f"""
            from motorbus.drives.dmac import DmacClient, open_line
            ax = DmacClient(open_line({server.slave_path!r}), address=5)
            ax.move_speed(30000)
        """)
        env = dict(os.environ, PYTHONPATH=str(pathlib.Path(motorbus.__file__).parents[1]))
        subprocess.run([sys.executable, "-c", script], env=env, check=True, timeout=30)
        clock.advance(100 * MS)
        st = sim.state()
        assert st.speed < 30000 * 0.25  # STOP arrived: it ramps down instead of up
        clock.advance(2000 * MS)
        assert sim.state().speed == 0


# ---- HOSTILE_INPUTS 2.9 (A-rows) from Python --------------------------------------------
class Tamper(LineDevice):
    """Wraps the simulator and rewrites its replies: a hostile or broken module."""

    def __init__(self, inner, fn):
        super().__init__()
        self.inner, self.fn = inner, fn

    def on_line(self, line):
        return self.fn(line, self.inner.on_line(line))


@pytest.mark.parametrize("row,reply,exc", [
    ("A1", lambda r: r[:-2], motorbus.TimeoutError),
    ("A2", lambda r: b"00#POS=+1\x0023\r\n", motorbus.ProtocolError),
    ("A3", lambda r: b"00#POS=+" + b"1" * 400 + b"\r\n", motorbus.ProtocolError),
    ("A5", lambda r: b"?\r\n", UnknownCommand),
    ("A6", lambda r: b"00#VEL=+5\r\n", motorbus.ProtocolError),
    ("A7", lambda r: b"00#POS=1e3\r\n", motorbus.ProtocolError),
    ("A11", lambda r: r[:-2] + b"\x00", motorbus.TimeoutError),
])
def test_hostile_replies_raise_typed_and_next_call_works(row, reply, exc):
    sim = make_sim("00")
    state = {"on": True}
    dev = Tamper(sim, lambda line, r: reply(r) if state["on"] and b"READ #POS" in line else r)
    with PtyLineServer([dev]) as server:
        c = DmacClient(open_line(server.slave_path, timeout=0.2), address=0)
        with pytest.raises(exc):
            c.position
        state["on"] = False
        assert c.position == 0
        c.close()


def test_a8_a10_a13_stray_lines_are_skipped_and_counted():
    sim = make_sim("00")
    banner = b'00EV v1.7 H142 "MIDI-INGENIERIE_DMAC34-1_H142-10145_25/01/05_12/04/06" PHASE:6A BOOT:v1.1\r\n'
    dev = Tamper(sim, lambda line, r: (b"\xff\x00\xff\r\n" + banner + r) if b"READ #POS" in line else r)
    with PtyLineServer([dev]) as server:
        c = DmacClient(open_line(server.slave_path, timeout=0.2), address=0)
        assert c.position == 0
        k = c.counters
        assert k.stray_lines == 2 and k.device_resets == 1
        c.close()


def test_a14_motion_timeout_is_not_retried():
    sim = make_sim("00")
    sim.on_line(b"00BRAKE OFF")
    dev = Tamper(sim, lambda line, r: b"" if b"MOVE_TO" in line else r)
    with PtyLineServer([dev]) as server:
        c = DmacClient(open_line(server.slave_path, timeout=0.1), address=0)
        with pytest.raises(motorbus.TimeoutError):
            c.move_to(1000)
        assert sim.lines_handled == 2  # BRAKE OFF, then the MOVE_TO
        assert DmacStatus.MOVEMENT in c.status  # query the state instead of resending
        c.close()


def test_a15_sim_resyncs_after_overlong_and_binary():
    sim = make_sim("00")
    assert sim.on_line(bytes(range(256))) == b""
    assert sim.on_line(b"00READ #POS" + b"X" * 300) == b""
    assert sim.on_overlong() == b""
    assert sim.on_line(b"00#ERROR:=0, READ #POS") == b"00#POS=+0\r\n"
    assert sim.lines_rejected >= 3


def test_codec_records_and_radix_enum():
    r = dmac.parse_read_reply(b"05#ATI=h000001F4")
    assert isinstance(r, dmac.DmacReadReply)
    assert (r.address, r.mnemonic, r.bit, r.value, r.radix) == (5, "#ATI", 0, 500, dmac.DmacRadix.HEX)
    assert dmac.parse_read_reply(b"5#ATI=+1") is None          # one address digit: not the grammar
    with pytest.raises(AttributeError):
        r.value = 1                                            # read-only
    assert dmac.format_value(500, r.radix) == dmac.format_value(500, "hex") == "h000001F4"
    v = dmac.variable_info("HSP")
    assert isinstance(v, dmac.DmacVariableInfo) and (v.name, v.mnemonic) == ("#HIGH_SPEED", "#HSP")
    assert "VariableInfo(name='#HIGH_SPEED'" in repr(v)
    with pytest.raises(motorbus.InvalidArgument):
        dmac.format_value(1, "octal")


class _TimePasses(LineDevice):
    """A device between two modules on the line whose turn takes a millisecond: the
    line server hands a line to its devices one after the other, and a real clock moves
    on meanwhile."""

    def __init__(self, clock):
        super().__init__()
        self.clock = clock

    def on_line(self, line):
        self.clock.advance(1 * MS)
        return b""


def test_one_synchro_top_starts_every_module_at_the_same_millisecond():
    # On the wire the broadcast SYNCHRO TOP reaches both modules at once; each module
    # takes the instant the line ended, not the instant its own turn came.
    clock = SimClock()
    a, b = make_sim("01", clock=clock), make_sim("02", clock=clock)
    with PtyLineServer([a, _TimePasses(clock), b]) as server:
        link = open_line(server.slave_path, timeout=0.5)
        sleep = lambda s: clock.advance(int(s * 1e9))  # noqa: E731
        clients = [DmacClient(link, address=n, sleep=sleep) for n in (1, 2)]
        for c in clients:
            c.brake(False)
        synchro(link, "ON")
        for c in clients:
            c.move_to(200000)                 # held until the TOP
        clock.advance(50 * MS)
        assert a.state().position == b.state().position == 0
        synchro(link, "TOP")
        synchro(link, "OFF")
        assert clients[1].position == 0       # an answer: the server has handled the TOP
        clock.advance(300 * MS)
        sa, sb = a.state(), b.state()
        assert sa.now_ms == sb.now_ms
        assert 0 < sa.position < 200000       # mid-move, where a 1 ms skew would show
        assert sa.position == sb.position and sa.speed == sb.speed
        for c in clients:
            c.close()
