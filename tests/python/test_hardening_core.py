"""Hardening (issue "Hardening"): the C++ core under faults and bad input, seen
from Python.  The checks live in C++; these tests show the typed errors reach
Python through the existing bindings."""
import itertools
import time

import pytest

import motorbus
from motorbus.canopen import LocalNode, ObjectDictionary, SdoAbortError, SdoClient, load_eds

_hub = itertools.count()


def _blob_node(block_transfer):
    name = f"hardening-core-{next(_hub)}"
    dev = motorbus.open_bus(f"virtual:{name}")
    host = motorbus.open_bus(f"virtual:{name}")
    od = ObjectDictionary()
    od.add_variable(0x2201, "Blob", "DOMAIN", "rw", max_size=1 << 16)
    node = LocalNode(dev, 5, od, block_transfer=block_transfer)
    return dev, host, node


# ---- defect 4: block means block -------------------------------------------------------------

def test_block_refused_is_an_abort_not_a_silent_segmented_transfer():
    dev, host, node = _blob_node(block_transfer=False)
    try:
        sdo = SdoClient(host, 5, timeout=0.5)
        sdo.download(0x2201, 0, b"x" * 100)  # segmented: fine
        with pytest.raises(SdoAbortError) as e:
            sdo.upload(0x2201, 0, block=True)
        assert e.value.code == 0x05040001
        with pytest.raises(SdoAbortError) as e:
            sdo.download(0x2201, 0, b"y" * 100, block=True)
        assert e.value.code == 0x05040001
        assert sdo.counters.fallbacks == 0
        # Opting in gives the old behaviour, counted.
        fb = SdoClient(host, 5, timeout=0.5, block_fallback=True)
        assert fb.upload(0x2201, 0, block=True) == b"x" * 100
        assert fb.counters.fallbacks == 1
    finally:
        node.close()
        host.close()
        dev.close()


# ---- defect 9: load_eds is bounded -----------------------------------------------------------

def test_load_eds_refuses_an_endless_file_fast():
    t0 = time.monotonic()
    with pytest.raises(motorbus.InvalidArgument, match=r"/dev/zero.*16 MiB"):
        load_eds("/dev/zero")
    assert time.monotonic() - t0 < 2.0
