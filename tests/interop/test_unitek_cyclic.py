"""The cyclic scenario over a real transport: 8 registers every 1 ms for 10 s of simulated
time, from the simulator served over socketcand into motorbus's numpy rings; a 9th
register refused by our client and ignored by the sim when python-can sends it anyway;
stop requests end every stream.  Time is a SimClock: the periods measured are exact,
nothing here depends on the machine's speed."""
from __future__ import annotations

import time

import can
import numpy as np
import pytest

import motorbus
from motorbus import _core
from motorbus.drives import unitek
from motorbus.drives.unitek import Reg, Unitek
from motorbus.sim import SimBench

pytestmark = pytest.mark.threaded

REGS = [Reg.SPEED_IST, Reg.SPEED_CMD, Reg.ACC_RAMP, Reg.KERN_STATUS, Reg.EVENT_MASK, Reg.POS_DEST,
        Reg.TORQUE_CMD, Reg.POS_IST]
STEPS = 10_000  # 10 s at 1 ms


def wait(cond, what: str, timeout: float = 5.0) -> None:
    end = time.monotonic() + timeout
    while not cond():
        assert time.monotonic() < end, what
        time.sleep(0.0002)


def test_eight_registers_every_ms_for_10_s_into_numpy():
    clock = _core.runtime.SimClock(1_000_000_000)
    with SimBench(["unitek:0x201"], clock=clock) as bench:
        sim = bench.sims[("unitek", "0x201")]
        srv = bench.can.servers[0]
        peer = can.Bus(interface="socketcand", host=srv.host, port=srv.port, channel="can0")
        try:
            with motorbus.open_bus(f"socketcand:{srv.host}:{srv.port}/can0") as bus:
                drive = Unitek(bus, 0x201, clock=clock, timeout=2.0)
                streams = [drive.subscribe(r, 1, capacity=STEPS + 16) for r in REGS]
                with pytest.raises(unitek.CyclicLimit, match="at most 8"):
                    drive.subscribe(Reg.REG_A8, 1)
                wait(lambda: len(sim.cyclic) == 8, "the sim never started 8 streams")
                # The same 9th request from another host (python-can): ignored by the drive.
                peer.send(can.Message(arbitration_id=0x201, data=[0x3D, 0xA8, 0x01], is_extended_id=False))
                wait(lambda: sim.counters.cyclic_refused == 1, "the 9th request never reached the sim")
                assert len(sim.cyclic) == 8 and 0xA8 not in dict(sim.cyclic)
                wait(lambda: all(s.count >= 1 for s in streams), "first frames missing")
                for k in range(1, STEPS + 1):
                    clock.advance(1_000_000)
                    sim.service()
                    while not all(s.count > k for s in streams):
                        time.sleep(0)
                for r in REGS:
                    drive.unsubscribe(r)
                wait(lambda: sim.cyclic == [], "stop requests did not end the streams")
                before = [sim.sent(r) for r in REGS]
                clock.advance(100_000_000)
                sim.service()
                assert [sim.sent(r) for r in REGS] == before      # nothing after the stops
                assert sim.sent(0xA8) == 0
                for s in streams:
                    t, v = s.read()
                    assert len(t) == STEPS + 1 and s.lost == 0      # 0 samples lost
                    periods = np.diff(t)
                    assert periods.min() == periods.max() == 1_000_000   # every period exactly 1 ms
                assert drive.counters.rejected == 0
                drive.close()
        finally:
            peer.shutdown()
