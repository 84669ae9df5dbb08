import pytest

import motorbus


def test_frame_fields_roundtrip():
    f = motorbus.Frame(0x123, b"\x01\x02")
    assert (f.id, f.data, f.dlc, f.extended, f.rtr) == (0x123, b"\x01\x02", 2, False, False)
    assert str(f) == "123#0102"
    assert motorbus.Frame(0x123, [1, 2]) == f


@pytest.mark.parametrize(
    "kwargs, field",
    [
        (dict(id=0x800), "frame id"),
        (dict(id=0x20000000, extended=True), "frame id"),
        (dict(id=1, data=bytes(9)), "frame data"),
        (dict(id=1, rtr=True, dlc=9), "frame dlc"),
        (dict(id=1, data=[256]), "byte value"),
    ],
)
def test_invalid_frame_is_refused_naming_the_field(kwargs, field):
    with pytest.raises(motorbus.InvalidArgument, match=field) as e:
        motorbus.Frame(**kwargs)
    assert isinstance(e.value, ValueError)
