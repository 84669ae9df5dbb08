"""can::SimulatedDevice from Python: every CAN simulator is a ``_core.can.SimulatedDevice`` with
one ``attach(bus)`` / ``close()`` / ``attached`` / ``describe()``, and keeps the bus it was
given alive (the holder structs that used to do it in the bindings are gone)."""
import gc
import itertools
import time

import pytest

import motorbus
from motorbus import _core

_hubs = itertools.count()


def _wait(pred, timeout=2.0):
    end = time.monotonic() + timeout
    while not pred() and time.monotonic() < end:
        time.sleep(0.002)
    return pred()


def _pmc007():
    return _core.pmc007.Sim(node_id=5), _core.can.Frame(0x605, bytes([0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0])), 0x585


def _unitek():
    return _core.unitek.Sim(_core.runtime.RealClock()), _core.can.Frame(0x201, bytes([0x3D, 0x40, 0x00])), 0x181


def _arcus():
    sim = _core.arcus.Sim(None, node_id=3, comm_type=2)  # a unit stored as CAN
    return sim, _core.can.Frame(0x603, bytes([0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0])), 0x583


def _cia402():
    return _core.cia402.Sim(7), _core.can.Frame(0x607, bytes([0x40, 0x00, 0x10, 0x00, 0, 0, 0, 0])), 0x587


@pytest.mark.parametrize("make", [_pmc007, _unitek, _arcus, _cia402], ids=["pmc007", "unitek", "arcus", "cia402"])
def test_every_can_sim_is_one_simulated_device(make):
    sim, request, reply_id = make()
    assert isinstance(sim, _core.can.SimulatedDevice)
    kind = type(sim).__name__
    hub = f"simdev-py-{kind}-{next(_hubs)}"
    host = motorbus.open_bus("virtual:" + hub)
    got = []
    host.subscribe(lambda f: got.append(bytes(f.data)), id=reply_id)
    try:
        sim.attach(motorbus.open_bus("virtual:" + hub))  # nobody else keeps this endpoint
        gc.collect()
        assert sim.attached
        host.send(request)
        assert _wait(lambda: len(got) == 1), f"{sim.describe()} did not answer"
        with pytest.raises(motorbus.InvalidArgument, match=sim.describe()):
            sim.attach(motorbus.open_bus("virtual:" + hub))
        sim.close()
        sim.close()  # idempotent
        assert not sim.attached
        host.send(request)
        time.sleep(0.1)
        assert len(got) == 1  # silent once closed
        with sim:  # attach again; the with block closes it
            sim.attach(motorbus.open_bus("virtual:" + hub))
            host.send(request)
            assert _wait(lambda: len(got) == 2)
        assert not sim.attached
        with pytest.raises(motorbus.InvalidArgument):
            sim.attach(None)
    finally:
        sim.close()
        host.close()
