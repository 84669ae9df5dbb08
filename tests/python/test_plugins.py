"""Vendors are plugins: the shared files name no vendor, and the registry works as documented."""
import pathlib
import re
import subprocess
import sys

import pytest

import motorbus
from motorbus import registry

ROOT = pathlib.Path(__file__).resolve().parents[2]
SHARED = ["CMakeLists.txt", "bindings/module.cpp", "python/motorbus/cli.py", "python/motorbus/sim.py",
          "python/motorbus/bus.py", "python/motorbus/__init__.py", "python/motorbus/drive.py",
          "python/motorbus/registry.py", "python/motorbus/bus_server.py", "python/motorbus/poller.py",
          "python/motorbus/pytest_plugin.py", "python/motorbus/cli_monitor.py",
          "python/motorbus/canopen/poll.py", "bindings/poll.cpp"] + \
    [str(p.relative_to(ROOT)) for p in sorted((ROOT / "cpp/motorbus/poll").iterdir())]


def vendors() -> list[str]:
    return sorted(p.name for p in (ROOT / "cpp/motorbus/drives").iterdir() if p.is_dir())


def test_no_shared_file_names_a_vendor():
    names = vendors() + [k for k in registry._load(registry.DRIVE_GROUP) if k != "cia402"]
    assert {"arcus", "dmac"} <= set(names)
    pattern = re.compile("|".join(sorted(set(names))), re.IGNORECASE)
    for f in SHARED:
        hits = [line for line in (ROOT / f).read_text().splitlines() if pattern.search(line)]
        assert hits == [], f"{f} names a vendor: {hits}"


def test_every_vendor_folder_has_its_test_executable_and_bindings():
    for v in vendors():
        assert (ROOT / "tests/cpp/drives" / v).is_dir(), v
    for f in (ROOT / "bindings/drives").glob("*.cpp"):
        text = f.read_text()
        assert f"void bind_{f.stem}(py::module_& m)" in text or f"void bind_{f.stem}(pybind11::module_& m)" in text


def test_in_tree_kinds_are_declared_as_entry_points_like_any_plugin():
    text = (ROOT / "pyproject.toml").read_text()
    # A kind may carry a hyphen ("arcus-canopen", the CANopen persona of "arcus");
    # its module is the same name with "_" (a Python identifier).
    # The entry point names the kind's Drive subclass (as python-can's names a bus class).
    declared = re.findall(r'^([\w-]+) = "motorbus\.drives\.(\w+):(\w+Drive)"$', text, re.MULTILINE)
    assert declared and all(k.replace("-", "_") == m for k, m, _ in declared)
    kinds = motorbus.drive_kinds()
    assert set(kinds) == {k for k, _, _ in declared}
    for k, _, cls in declared:
        plugin = registry.drive_plugin(k)
        assert issubclass(plugin, motorbus.Drive) and plugin.__name__ == cls and plugin.kind == k
        assert plugin.transport in ("serial", "can") and plugin.description == kinds[k]
    assert all(isinstance(d, str) and d and "\n" not in d for d in kinds.values())
    schemes = registry.bus_schemes()
    assert {"virtual", "slcan", "socketcand", "socketcan"} <= set(schemes)


def test_unknown_kind_and_scheme_name_what_is_registered():
    with pytest.raises(motorbus.InvalidArgument, match=r"unknown drive kind 'nope' \(registered: .*cia402"):
        motorbus.open_drive("nope", bus="virtual:x", address=1)
    with pytest.raises(motorbus.InvalidArgument, match="a CAN drive takes bus="):
        motorbus.open_drive("cia402", line="/dev/null", address=1)
    with pytest.raises(motorbus.InvalidArgument, match="node-ID 200 is outside"):
        motorbus.open_drive("cia402", bus="virtual:x", address=200)


def test_a_plugin_registered_at_run_time_is_served_by_sim_serve_code():
    """What an out-of-tree package gets: its kind is listed, opened and served with no change here."""
    from motorbus.drives import cia402

    class MyKindDrive(cia402.Cia402Drive):     # a kind is a Drive subclass; it inherits the hooks
        kind = "mykind"
        description = "a test kind"
        default_address = "3"

    registry.register(registry.DRIVE_GROUP, "mykind", MyKindDrive)
    try:
        assert motorbus.drive_kinds()["mykind"] == "a test kind"
        from motorbus.sim import SimBench
        with SimBench(["mykind:3"], bus="virtual:plugin-test") as bench:
            assert bench.announce()[0].startswith("socketcand 127.0.0.1:")
            with motorbus.open_drive("mykind", bus="virtual:plugin-test", address=3) as d:
                d.enable()
                assert d.status.enabled
    finally:
        registry._cache[registry.DRIVE_GROUP].pop("mykind", None)


def test_motorbus_drives_lists_every_kind():
    out = subprocess.run([sys.executable, "-m", "motorbus", "drives"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    for kind in motorbus.drive_kinds():
        assert re.search(rf"^{kind}\s+(serial|can)\s+\S", out.stdout, re.MULTILINE), out.stdout
