"""canopen's and python-can's own test suites, run over the motorbus python-can interface.

Both projects test themselves on python-can's ``virtual`` bus.  Their test directories
(not in the PyPI wheels) are vendored at the versions pinned in requirements-dev.txt
under ``thirdparty/<project>-<version>/`` (see ``thirdparty/README.md``).  Each suite
runs twice in a child ``pytest``: once as published, on python-can's ``virtual`` bus,
and once with the ``virtual`` interface replaced by motorbus, i.e.
``can.Bus(interface="virtual", channel=X)`` opens
``can.Bus(interface="motorbus", channel=f"virtual:{X}")``.  The two runs must give
every test the same outcome, except:

* CAN FD (python-can's back-to-back ``test_fd_*``): motorbus is classic CAN; on the
  motorbus run python-can's ``TEST_CAN_FD`` switch is off (``fd=True`` is refused with
  ``can.CanInterfaceNotImplementedError``, see test_pythoncan_back2back.py) and sending
  an FD message must fail with motorbus's ``CanOperationError``.
* RACY: tests that read with ``bus.recv()`` a bus that canopen's ``Network`` is
  reading at the same time through its ``Notifier`` thread.  Which reader gets a
  frame is a race; on python-can's virtual bus the test's own ``recv`` wins in
  practice (the sender's thread queues the frame and keeps the GIL while the Notifier
  thread still has to wake up), on motorbus the Notifier's ``recv``, already waiting in
  C++ without the GIL, often takes it.  Either outcome is accepted on motorbus.

Tests that need something the virtual bus does not model are deselected in both runs,
each with its reason in ``DESELECT``.
"""
from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

pytestmark = [pytest.mark.slow, pytest.mark.subprocess]

THIRDPARTY = Path(__file__).parent / "thirdparty"

# The child process: optionally swap the ``virtual`` interface for motorbus, then pytest.
_BOOTSTRAP = r'''
import os, sys, types
import can, can.interfaces

if os.environ["MOTORBUS_SUITE_BUS"] == "motorbus":
    from motorbus.pycan import MotorbusCanBus

    class VirtualOverMotorbus(MotorbusCanBus):
        """can.Bus(interface="virtual", channel=X) -> motorbus channel "virtual:X"."""

        def __init__(self, channel="channel-0", rx_queue_size=0, preserve_timestamps=False,
                     protocol=None, **kwargs):
            super().__init__(f"virtual:{channel}", **kwargs)
            self._virtual_channel = channel

        def _recv_internal(self, timeout):
            msg, filtered = super()._recv_internal(timeout)
            if msg is not None:
                msg.channel = self._virtual_channel  # what python-can's virtual bus reports
            return msg, filtered

    shim = types.ModuleType("_motorbus_as_virtual")
    shim.VirtualOverMotorbus = VirtualOverMotorbus
    sys.modules[shim.__name__] = shim
    can.interfaces.BACKENDS["virtual"] = (shim.__name__, "VirtualOverMotorbus")
    if os.path.exists(os.path.join("test", "config.py")):  # python-can's suite: classic CAN
        sys.path.insert(0, os.getcwd())
        import test.config
        test.config.TEST_CAN_FD = False

import pytest
sys.exit(pytest.main(sys.argv[1:]))
'''

SUITES = {
    "canopen": {
        "dir": "canopen-2.4.1",
        "paths": ["test"],
        "min_tests": 150,
    },
    "python-can": {
        "dir": "python-can-4.6.1",
        # the files of python-can's test/ that run a bus through can.Bus(interface="virtual");
        # the others test log formats, hardware interfaces with mocks, the CLI, or
        # python-can's VirtualBus class itself (test_interface_virtual.py, test_bridge.py)
        "paths": ["test/back2back_test.py", "test/contextmanager_test.py", "test/network_test.py",
                  "test/notifier_test.py", "test/simplecyclic_test.py", "test/test_bus.py",
                  "test/test_message_filtering.py", "test/zero_dlc_test.py"],
        "min_tests": 40,
    },
}

DESELECT = {
    # they read ``bus.queue``, an attribute of python-can's VirtualBus class
    "test/simplecyclic_test.py::SimpleCyclicSendTaskTest::test_cycle_time": "VirtualBus.queue",
    "test/simplecyclic_test.py::SimpleCyclicSendTaskTest::test_restart_perodic_tasks": "VirtualBus.queue",
    # UDP multicast on the host's network, not the virtual bus (skipped anyway without msgpack)
    "test/back2back_test.py::BasicTestUdpMulticastBusIPv4": "network (UDP multicast)",
    "test/back2back_test.py::BasicTestUdpMulticastBusIPv6": "network (UDP multicast)",
}

FD = {f"test.back2back_test.{cls}::{name}"
      for cls in ("Back2BackTestCase", "TestThreadSafeBus")
      for name in ("test_fd_message", "test_fd_message_with_brs")}

RACY = {
    "test.test_time.TestTime::test_time_producer",
    "test.test_network.TestScanner::test_scanner_search_limit",
}


def _run(suite: dict, bus: str, tmp_path: Path) -> tuple[dict[str, tuple[str, str]], str]:
    """Outcome ('passed'/'failed'/'error'/'skipped', message) per test id of one run."""
    cwd = THIRDPARTY / suite["dir"]
    xml = tmp_path / f"{suite['dir']}-{bus}.xml"
    args = ["-q", "-p", "no:cacheprovider", "-c", os.devnull, "--rootdir", str(cwd),
            "--confcutdir", str(cwd), "-o", "timeout=60", f"--junitxml={xml}", "-W", "ignore"]
    args += [f"--deselect={d}" for d in DESELECT if d.split("::")[0] in suite["paths"]]
    env = dict(os.environ, MOTORBUS_SUITE_BUS=bus, PYTHONDONTWRITEBYTECODE="1")
    env.pop("CI", None)  # the same tests in both runs, whatever the caller's environment
    r = subprocess.run([sys.executable, "-c", _BOOTSTRAP, *args, *suite["paths"]], cwd=cwd, env=env,
                       capture_output=True, text=True, timeout=300)
    out = r.stdout + r.stderr
    # 0 = all passed, 1 = some failed; anything else (an abort, a collection error) is ours
    assert r.returncode in (0, 1), f"{bus} run of {suite['dir']} ended with {r.returncode}:\n{out[-4000:]}"
    assert "terminate called" not in out, out[-4000:]
    outcomes = {}
    for case in ET.parse(xml).getroot().iter("testcase"):
        tid = f"{case.get('classname')}::{case.get('name')}"
        outcome, message = "passed", ""
        for tag in ("failure", "error", "skipped"):
            el = case.find(tag)
            if el is not None:
                outcome = {"failure": "failed"}.get(tag, tag)
                message = (el.get("message") or "") + "\n" + (el.text or "")
                break
        outcomes[tid] = (outcome, message)
    return outcomes, out


@pytest.mark.parametrize("name", sorted(SUITES))
def test_suite_same_outcomes_on_virtual_and_motorbus(name, tmp_path):
    suite = SUITES[name]
    virtual, vout = _run(suite, "virtual", tmp_path)
    motorbus, mout = _run(suite, "motorbus", tmp_path)
    assert len(virtual) >= suite["min_tests"], vout[-3000:]
    assert virtual.keys() == motorbus.keys()

    def summary(outcomes):
        counts = {}
        for outcome, _ in outcomes.values():
            counts[outcome] = counts.get(outcome, 0) + 1
        return counts

    print(f"\n{name}: virtual {summary(virtual)}, motorbus {summary(motorbus)}")
    different = {}
    for tid, (vo, _) in sorted(virtual.items()):
        mo, msg = motorbus[tid]
        if tid in FD:
            assert vo == "passed", (tid, virtual[tid])
            assert mo == "failed" and "CanOperationError" in msg and "CAN FD" in msg, (tid, mo, msg[-1500:])
        elif tid in RACY:
            assert vo == "passed", (tid, virtual[tid])
            assert mo in ("passed", "failed"), (tid, mo, msg[-1500:])
            print(f"  racy {tid}: {mo} on motorbus")
        elif vo != mo:
            different[tid] = f"virtual {vo}, motorbus {mo}: {msg[-1500:]}"
    assert not different, "\n\n".join(f"{k}: {v}" for k, v in different.items())
