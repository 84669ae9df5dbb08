"""The bindings hold no logic of their own: enums are the C++ enums (taking their
names as strings too), and a range is checked once, by the core, whatever
Python int reaches it (no wrap-around on the way to a uint8/uint16)."""
from __future__ import annotations

import pytest

import motorbus
from motorbus import _core


# ---- enums: bound C++ enums, names accepted in any case ------------------------

@pytest.mark.parametrize("enum, name, member", [
    (_core.dmac.PowerMode, "sc", "SC"),
    (_core.dmac.PowerMode, "ON", "ON"),
    (_core.dmac.StopWhat, "MOUV", "MOVEMENT"),       # the manual's word is an alias
    (_core.dmac.StopWhat, "sequence", "SEQUENCE"),
    (_core.dmac.EndStops, "pos", "POS"),
    (_core.dmac.Polarity, "Out", "OUT"),
    (_core.dmac.Keyword, "interpol", "INTERPOL"),
    (_core.dmac.Sensor, "driver", "DRIVER"),
    (_core.dmac.Radix, "h", "HEX"),
    (_core.arcus.HomeMethod, "zh", "ZH"),
    (_core.arcus.HomingMethod, "hl", "HL"),
])
def test_an_enum_takes_its_names(enum, name, member):
    assert enum(name) == getattr(enum, member)


def test_functions_take_the_enum_or_its_name():
    assert _core.dmac.format_value(500, "hex") == _core.dmac.format_value(500, _core.dmac.Radix.HEX) == "h000001F4"
    assert _core.dmac.format_value(5, "") == "+5"          # empty = decimal, as before


@pytest.mark.parametrize("call, words", [
    (lambda: _core.dmac.format_value(1, "octal"), "radix: 'octal' is not DEC, HEX or BIN"),
    (lambda: _core.dmac.format_value(1, 2.5), "radix: expected DEC, HEX or BIN, got float"),
    (lambda: _core.dmac.PowerMode("half"), "POWER: 'half' is not ON, OFF or SC"),
    (lambda: _core.arcus.HomeMethod("Q"), "home method: 'Q' is not H, HL, ZH, Z or L"),
])
def test_a_bad_name_is_an_invalid_argument_listing_the_choices(call, words):
    with pytest.raises(motorbus.InvalidArgument) as e:
        call()
    assert words in str(e.value)


def test_synchro_refuses_a_keyword_that_is_not_synchro_s():
    # DmacKeyword has every keyword of the language; the core's synchro() takes four.
    pair = _core.serial.PtyPair()
    link = _core.serial.LineLink(pair.port)
    with pytest.raises(motorbus.InvalidArgument, match="SYNCHRO: ON, OFF, TOP or INTERPOL"):
        _core.dmac.synchro(link, "SC")


# ---- ranges: checked by the core, once -------------------------------------------

@pytest.mark.parametrize("counter", [0, 241, 256, 257, -1, 1 << 20])
def test_sync_counter_out_of_range_is_refused_not_wrapped(counter):
    with pytest.raises(motorbus.InvalidArgument, match="SYNC counter must be 1-240"):
        _core.canopen.sync_encode(counter)
    assert _core.canopen.sync_encode(240).data == b"\xf0"


@pytest.mark.parametrize("overflow", [1, 241, 256, 258, -1])
def test_sync_overflow_out_of_range_is_refused_not_wrapped(overflow):
    bus = _core.can.open_virtual("bindings-args-sync")
    with pytest.raises(motorbus.InvalidArgument, match="SYNC counter overflow must be 0 or 2-240"):
        _core.canopen.SyncProducer(bus, 0.01, counter_overflow=overflow)


@pytest.mark.parametrize("first, last", [(0, 5), (-1, 127), (1, 128), (1, 256 + 5), (-255, -255), (9, 3)])
def test_scan_range_out_of_range_is_refused_not_wrapped(first, last):
    bus = _core.can.open_virtual("bindings-args-scan")
    with pytest.raises(motorbus.InvalidArgument, match="scan range must be within 1-127"):
        _core.canopen.scan_network(bus, first=first, last=last, sdo_timeout=0.01)


@pytest.mark.parametrize("ms", [60000, 65535, 65536 + 5, 1 << 31])
def test_slcan_timestamp_out_of_range_is_refused_not_wrapped(ms):
    with pytest.raises(motorbus.InvalidArgument, match="slcan timestamp: must be 0-59999 ms"):
        _core.can.slcan_encode(_core.can.Frame(1), timestamp_ms=ms)


def test_pdo_pack_with_a_wrong_count_is_the_core_s_error():
    layout = _core.canopen.PdoLayout([(0x6041, 0, 16), (0x6064, 0, 32)])
    assert layout.pack([0x1234, -1]) == b"\x34\x12\xff\xff\xff\xff"
    for values in ([1], [1, 2, 3], list(range(9)), list(range(65))):
        with pytest.raises(motorbus.InvalidArgument, match=f"PDO pack: {len(values)} values for 2 mapped entries"):
            layout.pack(values)


def test_unitek_device_names_are_the_core_s():
    assert _core.unitek.continuous_current_num("DS 412", 0.0) == 0
    with pytest.raises(motorbus.InvalidArgument, match="unitek device: 'DS 205/405', 'DS 412' or 'DS 420', not 'DS 9'"):
        _core.unitek.continuous_current_num("DS 9", 1.0)
