"""The UNITEK manual's worked examples (002, examples 1-10-1 and §4.8/§5.2) byte for byte,
with python-can as the client of a socketcand-served simulator (no motorbus code on
the client side), and motorbus's own client's frames captured on the bus by python-can.

Vectors: tests/data/unitek/seed_examples.json (a copy of the shared seed vectors, with
the manual's errata corrected, as docs/drives/unitek.md lists them: ex 6 `35 E8 03`, ex 4 DLC 5,
ex 9 ids 0x201/0x181)."""
from __future__ import annotations

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import can
import pytest

import motorbus
from motorbus.drives.unitek import Reg, Status, Unitek
from motorbus.sim import SimBench

pytestmark = pytest.mark.threaded

VECTORS = json.loads((Path(__file__).parents[1] / "data" / "unitek" / "seed_examples.json").read_text())["unitek_regid"]
RX, TX = int(VECTORS["rx_id_default"], 16), int(VECTORS["tx_id_default"], 16)


def hexbytes(text: str) -> bytes:
    return bytes.fromhex(text)


def recv_from(bus: can.BusABC, arb_id: int, timeout: float = 2.0) -> can.Message:
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        m = bus.recv(0.05)
        if m is not None and m.arbitration_id == arb_id:
            return m
    raise AssertionError(f"no frame on 0x{arb_id:X} within {timeout} s")


def nothing_on(bus: can.BusABC, arb_id: int, wait: float = 0.2) -> bool:
    end = time.monotonic() + wait
    while time.monotonic() < end:
        m = bus.recv(0.02)
        if m is not None and m.arbitration_id == arb_id:
            return False
    return True


def send(bus: can.BusABC, arb_id: int, data: bytes) -> None:
    bus.send(can.Message(arbitration_id=arb_id, data=data, is_extended_id=False))


@pytest.fixture()
def bench():
    with SimBench(["unitek:0x201"], sim_options={"unitek": {"acc_ramp_ms": 20}}) as b:
        yield b, b.sims[("unitek", "0x201")]


def pycan(b) -> can.BusABC:
    srv = b.can.servers[0]
    return can.Bus(interface="socketcand", host=srv.host, port=srv.port, channel="can0")


def settle(sim, frames_in: int, timeout: float = 2.0) -> None:
    """Writes are never acknowledged: wait until the sim has taken `frames_in` frames."""
    end = time.monotonic() + timeout
    while sim.counters.frames_in < frames_in:
        assert time.monotonic() < end, "the sim never received the frames"
        time.sleep(0.002)


def test_every_write_example_is_taken_and_never_acknowledged(bench):
    b, sim = bench
    bus = pycan(b)
    try:
        sent = 0
        for ex in VECTORS["to_drive"]:
            assert int(ex["id"], 16) == RX
            send(bus, RX, hexbytes(ex["data"]))
            sent += 1
            settle(sim, sent)
            if ex["data"].startswith("68"):  # ex 1 moved the receive id: put it back for the next examples
                assert sim.rx_id == 0x210
                send(bus, 0x210, bytes([0x68, 0x01, 0x02]))
                sent += 1
                settle(sim, sent)
                assert sim.rx_id == 0x201
        assert nothing_on(bus, TX), "a write was acknowledged (B-U05)"
        assert sim.value(Reg.ACC_RAMP) == 1000            # ex 6 (corrected bytes)
        assert sim.value(Reg.TORQUE_CMD) == 16380         # ex 5
        assert sim.value(Reg.POS_DEST) == 300010000       # the §4.8 data-field example (last position write)
        assert sim.status & Status.ENA == 0               # ex 2 disabled the drive
        assert sim.counters.refused == 0 and sim.counters.unknown == 0
    finally:
        bus.shutdown()


def test_example_8_read_status_once(bench):
    b, sim = bench
    bus = pycan(b)
    try:
        ex = VECTORS["exchanges"][0]
        send(bus, int(ex["request"]["id"], 16), hexbytes(ex["request"]["data"]))
        m = recv_from(bus, int(ex["reply"]["id"], 16))
        assert m.dlc == ex["reply"]["dlc"] == 4
        assert bytes(m.data[:3]) == hexbytes(ex["reply"]["data_prefix"])     # 40 81 01
        assert int.from_bytes(m.data[1:3], "little") == int(ex["reply"]["value"], 16)
        assert nothing_on(bus, TX)                                           # exactly one reply
    finally:
        bus.shutdown()


def test_example_9_cyclic_speed_every_100ms_then_stop(bench):
    b, sim = bench
    bus = pycan(b)
    try:
        send(bus, RX, bytes([0x35, 0x00, 0x00]))                     # ACC 0 ms
        send(bus, RX, bytes([0x31, 0xFF, 0x7F]))                     # full speed
        settle(sim, 2)
        time.sleep(0.01)
        ex = VECTORS["exchanges"][1]
        send(bus, RX, hexbytes(ex["request"]["data"]))               # 3D 30 64
        frames = [recv_from(bus, TX) for _ in range(4)]
        for m in frames:
            assert m.dlc == ex["reply"]["dlc"]
            assert bytes(m.data[:3]) == hexbytes(ex["reply"]["data_prefix"])   # 30 FF 7F
        assert sim.cyclic == [(0x30, 100)]
        stop = VECTORS["exchanges"][2]
        send(bus, RX, hexbytes(stop["request"]["data"]))             # 3D 30 FF
        settle(sim, 4)
        assert sim.cyclic == []
        sent = sim.sent(0x30)
        time.sleep(0.3)
        assert sim.sent(0x30) == sent                                # the stream ended
    finally:
        bus.shutdown()


def test_examples_10_and_10_1_status_events(bench):
    b, sim = bench
    bus = pycan(b)
    try:
        sim.set_calibrated(True)
        ex10 = VECTORS["exchanges"][3]
        send(bus, RX, hexbytes(ex10["request"]["data"]))             # 51 10 00
        settle(sim, 1)
        assert nothing_on(bus, TX)                                   # no frame at activation (C-U12)
        send(bus, RX, bytes([0x6E, 0x00, 0x00, 0x01, 0x00]))         # POS_DEST one revolution: Tol on arrival
        m = recv_from(bus, TX, 5)
        assert m.dlc == ex10["reply"]["dlc"] == 6
        assert bytes(m.data[:5]) == hexbytes(ex10["reply"]["data_prefix"])    # 40 81 31 00 00
        ex101 = VECTORS["exchanges"][4]
        send(bus, RX, hexbytes(ex101["request"]["data"]))            # 52 12 00
        settle(sim, 3)
        sim.force_limit(+1, True)
        m = recv_from(bus, TX)
        assert m.dlc == ex101["reply_on_limit"]["dlc"]
        assert bytes(m.data[:5]) == hexbytes(ex101["reply_on_limit"]["data_prefix"])   # 40 85 31 00 00
    finally:
        bus.shutdown()


def test_section_5_2_requests_for_a8(bench):
    b, sim = bench
    bus = pycan(b)
    try:
        send(bus, RX, bytes([0x3D, 0xA8, 0x00]))                     # E-U02: once
        assert bytes(recv_from(bus, TX).data) == bytes([0xA8, 0, 0, 0])
        send(bus, RX, bytes([0x3D, 0xA8, 0x0A]))                     # E-U03: every 10 ms
        for _ in range(3):
            assert recv_from(bus, TX).data[0] == 0xA8
        assert sim.cyclic == [(0xA8, 10)]
        send(bus, RX, bytes([0x3D, 0xA8, 0xFF]))
    finally:
        bus.shutdown()


def test_our_client_puts_the_examples_on_the_bus(bench):
    """motorbus's client, captured by python-can on another socketcand connection."""
    b, sim = bench
    spy = pycan(b)
    srv = b.can.servers[0]
    try:
        with motorbus.open_bus(f"socketcand:{srv.host}:{srv.port}/can0") as mbus:
            drive = Unitek(mbus, 0x201)
            assert drive.read(Reg.KERN_STATUS) == 0x0181                  # ex 8
            drive.write(Reg.SPEED_CMD, 3277)                             # ex 3
            drive.write(Reg.POS_DEST, 3_000_000)                         # ex 4
            drive.write(Reg.POS_DEST, 300_010_000)                       # §4.8
            drive.write(Reg.TORQUE_CMD, 16380)                           # ex 5
            drive.write(Reg.ACC_RAMP, 1000)                              # ex 6
            drive.store_eeprom(0)                                        # ex 7
            drive.disable()                                              # ex 2
            drive.enable()
            drive.set_events(True)                                       # ex 10 / §5.2 item 3
            drive.set_events(True, 0x0012)                               # ex 10-1
            s = drive.subscribe(Reg.SPEED_IST, 100)                      # ex 9
            end = time.monotonic() + 2
            while s.count < 1:                                           # the first frame comes at once
                assert time.monotonic() < end
                time.sleep(0.002)
            drive.unsubscribe(Reg.SPEED_IST)
            drive.set_receive_id(0x210)                                  # ex 1
            drive.close()
        expected = [
            "3D 40 00", "31 CD 0C", "6E C0 C6 2D 00", "6E 10 CA E1 11", "90 FC 3F", "35 E8 03", "84 00 00",
            "51 04 00", "51 00 00", "51 10 00", "52 12 00", "51 10 00", "3D 30 64", "3D 30 FF", "68 10 02",
        ]
        got = []
        end = time.monotonic() + 3
        while len(got) < len(expected) and time.monotonic() < end:
            m = spy.recv(0.05)
            if m is not None and m.arbitration_id == RX:
                got.append(bytes(m.data).hex(" ").upper())
        assert got == expected
        seed = {ex["data"] for ex in VECTORS["to_drive"]} | {ex["request"]["data"] for ex in VECTORS["exchanges"]}
        assert seed - {"51 04 00"} <= set(got) | {"51 04 00"}                # every seed frame came out of our client
    finally:
        spy.shutdown()


def test_sim_serve_cli_serves_unitek_to_python_can():
    proc = subprocess.Popen([sys.executable, "-m", "motorbus", "sim", "serve", "--bus", "virtual:bench",
                             "--socketcand", "127.0.0.1:0", "--drive", "unitek:0x201"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        word, hostport, channel = proc.stdout.readline().split()
        assert word == "socketcand" and channel == "can0"
        host, port = hostport.rsplit(":", 1)
        bus = can.Bus(interface="socketcand", host=host, port=int(port), channel="can0")
        try:
            send(bus, RX, bytes([0x3D, 0x40, 0x00]))
            m = recv_from(bus, TX)
            assert m.dlc == 4 and bytes(m.data[:3]) == bytes([0x40, 0x81, 0x01])
        finally:
            bus.shutdown()
    finally:
        proc.send_signal(signal.SIGINT)
        assert proc.wait(10) == 0
