"""The numbered examples run as documented (the notebooks: test_notebooks.py)."""
import pathlib
import subprocess
import sys

import motorbus

ROOT = pathlib.Path(__file__).resolve().parents[2]


def test_example_01_virtual_bus_python():
    out = run_example("01_virtual_bus.py")
    assert "callback: 181#010203" in out
    assert "logged: ['181#010203', '1ABCDEF0#FF']" in out


def run_cpp_example(name):
    """Output of build/dev/<name> (built with MOTORBUS_EXAMPLES=ON, as `make test` does)."""
    exe = ROOT / "build" / "dev" / name
    if not exe.exists():
        import pytest
        pytest.skip("C++ examples not built (MOTORBUS_EXAMPLES=OFF)")
    out = subprocess.run([str(exe)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    return out.stdout


def run_example(name):
    out = subprocess.run([sys.executable, str(ROOT / "examples" / name)], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    return out.stdout


def test_example_02_sdo_python():
    out = run_example("02_sdo.py")
    assert "name: example drive" in out
    assert "vendor: 0x12e" in out
    assert "offset: -300 served: -300" in out
    assert "refused: 0x06090031" in out


def test_example_05_cia402_python():
    out = run_example("05_cia402.py")
    assert out.splitlines() == ["state: OPERATION ENABLED", "position: 10000", "state: SWITCH ON DISABLED"]


def test_example_03_arcus_python():
    out = run_example("03_arcus.py")
    assert "position 12.50 mm, EX=1250" in out
    assert "homed True, SLS IDLE" in out
    assert "SLT=10 SLR=0.800 ID=DriveMax-CAN" in out


def test_example_03_arcus_cpp():
    out = run_cpp_example("example_03_arcus")
    assert "EX=1250 PX=1250 SLS=0" in out
    assert "SLR=0.800 ID=DriveMax-CAN" in out


def test_example_04_dmac_interpolation_python():
    out = run_example("04_dmac_interpolation.py")
    assert "segments 40," in out and "underruns 0" in out
    assert "x -10000 y 10000" in out   # a quarter circle ends exactly where it should


def test_example_04_dmac_interpolation_cpp():
    out = run_cpp_example("example_04_dmac_interpolation")
    assert "x -10000 y 10000" in out


def test_example_06_drive_api_python():
    out = run_example("06_drive_api.py")
    # The example lists the registry: every in-tree kind, and whatever else is installed.
    assert "kinds: " + ", ".join(sorted(motorbus.drive_kinds())) in out
    assert {"arcus", "arcus-canopen", "cia402", "dmac", "pmc007", "unitek"} <= set(motorbus.drive_kinds())
    for kind in ("arcus", "dmac", "cia402"):
        assert f"{kind}: at 3.50 mm, enabled=True moving=False fault=False" in out, out


def test_example_08_arcus_canopen_python():
    out = run_example("08_arcus_canopen.py")
    assert "serial: 0 (0 = RS-232), protocol 0" in out
    assert "after store + power cycle: protocol 2 serial reply b''" in out
    assert "run current over CANopen (2004h:02): 1200 mA" in out
    assert "moved to 1000.0 counts, state OPERATION ENABLED" in out
    assert "homed at 0.0 StepNLoop IDLE" in out


def test_example_09_unitek_python():
    out = run_example("09_unitek.py")
    assert "KERN_STATUS 0x0181" in out and "ACC_RAMP 1000 ms" in out
    assert "stream 0x30: 21 samples, periods 10.0..10.0 ms, lost 0" in out
    assert "speed 300.0 rpm after 200 ms" in out
    assert "position 1.000 rev, Tol True" in out


def test_example_09_unitek_cpp():
    out = run_cpp_example("example_09_unitek")
    assert "KERN_STATUS 0x0181" in out and "ACC_RAMP 1000 ms" in out
    assert "stream 0x30: 21 samples, last period 10.0 ms, lost 0, speed 3277 num" in out
    assert "position 65536 num, Tol 1" in out
def test_example_07_pmc007_python():
    out = run_example("07_pmc007.py")
    assert "status: <ControllerStatus.BUSY: 8>" in out
    assert "position 3200 busy False" in out
    assert "program: 080003E8 03000000 010001F4 10100000 0B000000 12100003 0E000002 verified True" in out
    assert "after the program: position 1700 counter 3 running False" in out


def test_example_07_pmc007_cpp():
    out = run_cpp_example("example_07_pmc007")
    assert "6001h=0x08" in out
    assert "position 3200 busy 0" in out
    assert "after the program: position 1700 counter 3" in out


def test_example_10_bluesky_scan_python():
    import pytest
    pytest.importorskip("ophyd_async")
    pytest.importorskip("bluesky")
    out = run_example("10_bluesky_scan.py")
    assert out.splitlines() == [f"event {i + 1}: x={i:.2f} z=2.50" for i in range(5)] + \
        ["run: success", "x stands at 4.00 mm"]


def test_example_12_asyncio_python():
    out = run_example("12_asyncio.py")
    for kind in ("arcus", "dmac", "cia402"):
        assert f"{kind}: at 4.00 mm" in out, out
    assert "moving=False, last move interrupted" in out, out


def test_example_14_epics_bluesky_python():
    import pytest
    for module in ("caproto", "epics", "ophyd", "bluesky"):
        pytest.importorskip(module)
    out = run_example("14_epics_bluesky.py")
    assert "pyepics: z at 2.50 mm, DMOV=1" in out
    assert "pyepics: move to 20 refused by the soft limit: True (LVIO=1), z still at 2.50" in out
    assert [line for line in out.splitlines() if line.startswith("event")] == \
        [f"event {i + 1}: x={i:.2f} z=2.50" for i in range(5)]
    assert "run: success" in out and "ophyd: x stands at 4.00 mm" in out
    # a STOP from elsewhere mid-move: ophyd's status fails (the record's STATE/MINOR at DMOV=1)
    assert "ophyd: the stopped move failed (" in out and "x at rest short of 40: True" in out
    assert "service ended: 0" in out
