"""python-can's own back-to-back test case (test/back2back_test.py of python-can 4.6.1,
vendored under thirdparty/), subclassed for ``interface="motorbus"``.

Everything passes but CAN FD: motorbus buses are classic CAN, so opening with ``fd=True``
raises ``can.CanInterfaceNotImplementedError`` (as python-can's classic-only interfaces
refuse CAN FD) and sending an FD message raises ``can.CanOperationError``. python-can's
``TEST_CAN_FD`` switch is off here, so the buses open with ``fd=False``, and the two FD
tests check the refusal instead.
"""
import importlib.util
import sys
from pathlib import Path

import can
import pytest

_SUITE = Path(__file__).parent / "thirdparty" / "python-can-4.6.1" / "test"
_PKG = "_pythoncan_upstream_tests"  # not "test": that is also the standard library's package


def _load_back2back():
    if _PKG not in sys.modules:
        spec = importlib.util.spec_from_file_location(_PKG, _SUITE / "__init__.py",
                                                      submodule_search_locations=[str(_SUITE)])
        pkg = importlib.util.module_from_spec(spec)
        sys.modules[_PKG] = pkg
        spec.loader.exec_module(pkg)
    return importlib.import_module(f"{_PKG}.back2back_test")


_b2b = _load_back2back()  # a module attribute, not a global class: pytest collects only ours
_b2b.TEST_CAN_FD = False   # python-can's switch for interfaces without CAN FD


class _Motorbus:
    INTERFACE_1 = "motorbus"
    CHANNEL_1 = "virtual:back2back"
    INTERFACE_2 = "motorbus"
    CHANNEL_2 = "virtual:back2back"

    def test_fd_message(self):
        with pytest.raises(can.CanOperationError, match="CAN FD"):
            super().test_fd_message()

    def test_fd_message_with_brs(self):
        with pytest.raises(can.CanOperationError, match="CAN FD"):
            super().test_fd_message_with_brs()

    def test_fd_bus_is_refused(self):
        with pytest.raises(can.CanInterfaceNotImplementedError, match="CAN FD is not supported"):
            can.Bus(channel=self.CHANNEL_1, interface=self.INTERFACE_1, bitrate=self.BITRATE, fd=True)


class TestBack2BackMotorbus(_Motorbus, _b2b.Back2BackTestCase):
    pass


class TestThreadSafeBack2BackMotorbus(_Motorbus, _b2b.TestThreadSafeBus):
    pass
