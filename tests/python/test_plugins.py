"""Vendors are plugins: the shared files name no vendor, and the registry works as documented."""
import pathlib
import re
import subprocess
import sys

import pytest

import motorbus
from motorbus import registry

ROOT = pathlib.Path(__file__).resolve().parents[2]


# ---- vendor names stay in vendor folders (deny by default): the rule is the next test's docstring ----
SCOPE = ["python", "cpp", "bindings", "CMakeLists.txt", "Makefile"]
STANDARD = {"cia402"}
ALIASES = {"arcus": ["dmx-can", "dmxcan"], "dmac": ["midi ing"], "pmc007": ["cqpusi"],
           "unitek": ["bamocar", "bamobil", "ndrive"]}
DEMO_DATA = {
    "python/motorbus/demo_bench.toml": "the shipped demo bench: one axis of every in-tree kind, by kind name",
}
EXCEPTIONS = {
    "python/motorbus/_core/__init__.pyi": "generated stub of _core's top level: the one error table (the vendors' "
                                          "error classes among them) and a `from . import <vendor>` per vendor",
}


def vendors() -> list[str]:
    return sorted(p.name for p in (ROOT / "cpp/motorbus/drives").iterdir() if p.is_dir())


def vendor_names() -> dict[str, list[str]]:
    """Every vendor with the names that name it (lower case)."""
    from importlib import metadata

    kinds = {ep.name.split("-")[0] for ep in metadata.entry_points(group=registry.DRIVE_GROUP)}
    return {v: [v] + ALIASES.get(v, []) for v in sorted((set(vendors()) | kinds) - STANDARD)}


def vendor_of(path: str) -> str | None:
    """The vendor whose folder holds `path` (None: a shared file)."""
    m = re.match(r"cpp/motorbus/drives/([^/]+)/|bindings/drives/([^/]+)\.cpp$|"
                 r"python/motorbus/drives/([a-z0-9]+)(?:_[a-z0-9_]+)?(?:\.py$|/)|"
                 r"python/motorbus/_core/([a-z0-9]+)\.pyi$", path)  # the generated stub of _core.<vendor>
    v = next((g for g in m.groups() if g), None) if m else None
    if m and m.group(4) and not (ROOT / "cpp/motorbus/drives" / v).is_dir():
        return None                     # the stub of an area's submodule (_core.can), not a vendor's
    return None if v in STANDARD else v


def tracked_product_files() -> list[str]:
    out = subprocess.run(["git", "ls-files", "-z", "--", *SCOPE], cwd=ROOT, capture_output=True, check=True)
    return [f for f in out.stdout.decode().split("\0") if f and (ROOT / f).is_file()]  # not a deletion under way


def names_in(text: str, names: dict[str, list[str]]) -> list[str]:
    pattern = re.compile("|".join(re.escape(n) for ns in names.values() for n in ns), re.IGNORECASE)
    return [f"{i}: {line.strip()[:120]}" for i, line in enumerate(text.splitlines(), 1) if pattern.search(line)]


def test_no_file_outside_a_vendor_folder_names_a_vendor():
    """Vendor names stay in vendor folders, denied by default.

    The rule, checked on every file git tracks in the product code — python/, cpp/, bindings/ and the
    top-level CMakeLists.txt and Makefile: a file's path and text may name a vendor only when the file
    is one of that vendor's own:

      cpp/motorbus/drives/<v>/**         its C++ (codec, client, simulator, profile, data files)
      bindings/drives/<v>.cpp            its bindings
      python/motorbus/drives/<v>.py,     its Python module, or package folder, and its personas'
      python/motorbus/drives/<v>/**,     (arcus_canopen.py is the arcus vendor's CANopen persona)
      python/motorbus/drives/<v>_*.py
      python/motorbus/_core/<v>.pyi      the generated stub of its _core submodule

    Everything else is denied, but for two named lists above: DEMO_DATA (data that must name kinds to show
    them) and EXCEPTIONS (each with its reason).  pyproject.toml names every in-tree kind in its entry
    points, as an out-of-tree package names its own: it is outside the scanned scope by design.
    Out of scope too, on purpose: docs/, tests/, examples/, notebooks/, bench/, fuzz/ and README.md.  They
    are where a reader looks a vendor up (docs/drives/<v>.md, numbered examples per drive, a test file
    per vendor, the README's table of drives) and nothing in the product imports them, so a vendor
    named there couples no shared code to it.

    A vendor is a folder of cpp/motorbus/drives/ or a kind declared as a motorbus.drive entry point
    (up to its first "-": "arcus-canopen" is arcus), except STANDARD kinds, named after a profile that
    the shared CANopen layer implements by right; ALIASES adds the makers' and products' names the
    manuals use.  A name matches anywhere in a line, in any case ("ArcusMotion", "bind_arcus", "DMX-CAN").
    """
    names = vendor_names()
    assert {"arcus", "dmac", "pmc007", "unitek"} <= set(names)
    files = tracked_product_files()
    assert "python/motorbus/motion.py" in files and "CMakeLists.txt" in files  # the scope is not empty
    for listed in {**DEMO_DATA, **EXCEPTIONS}:          # a stale entry is a bug of the list
        assert listed in files, f"{listed} is listed but not tracked"
    offenders = {}
    for f in files:
        if vendor_of(f) is not None or f in DEMO_DATA or f in EXCEPTIONS:
            continue
        hits = names_in(f, names) + names_in((ROOT / f).read_text(errors="replace"), names)
        if hits:
            offenders[f] = hits
    assert not offenders, "shared files that name a vendor (move the code to the vendor's folder, or say " \
        "the point without the name):\n" + "\n".join(f"{f}:\n    " + "\n    ".join(h) for f, h in offenders.items())


def test_the_vendor_check_denies_what_it_should():
    """The rule on made-up paths and lines: a check that passes everything would pass the tree too."""
    names = vendor_names()
    assert vendor_of("cpp/motorbus/drives/arcus/sim.cpp") == "arcus"
    assert vendor_of("python/motorbus/drives/arcus_canopen.py") == "arcus"
    assert vendor_of("python/motorbus/drives/pmc007/pmc007.eds") == "pmc007"
    assert vendor_of("cpp/motorbus/drives/unitek/ndrive.toml") == "unitek"
    assert vendor_of("python/motorbus/_core/dmac.pyi") == "dmac"
    assert vendor_of("bindings/drives/unitek.cpp") == "unitek"
    for shared in ("python/motorbus/drives/cia402.py", "cpp/motorbus/drives/cia402/sim.cpp", "python/motorbus/_core/can.pyi",
                   "python/motorbus/motion.py", "cpp/motorbus/canopen/od.hpp", "bindings/module.cpp",
                   "python/motorbus/drives/__init__.py"):
        assert vendor_of(shared) is None, shared
    for line in ("from ._core import ArcusMotion", "void bind_dmac(py::module_& m);", "a DMX-CAN default",
                 "CQPUSI manual", "BAMOCAR", "kind = \"pmc007\"", "unitek_ndrive.toml"):
        assert names_in(line, names), line
    assert names_in("CiA 402 profile position, a CANopen node, an arc of a circle", names) == []


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


def test_a_kind_whose_exchanging_hooks_are_plain_functions_is_refused_naming_them():
    """Hooks that talk to the drive are coroutines (one implementation serves the blocking
    and the awaitable face); a plain one would block every task of an event loop."""
    from motorbus.drives import cia402

    class BlockingKindDrive(cia402.Cia402Drive):
        kind = "blockingkind"

        def _position(self):                  # a plain function: the old contract
            return 0.0

        def _stop(self):
            pass

    registry.register(registry.DRIVE_GROUP, "blockingkind", BlockingKindDrive)
    try:
        with pytest.raises(motorbus.InvalidArgument, match=r"'blockingkind'.*_stop, _position must be coroutine"):
            registry.drive_plugin("blockingkind")
    finally:
        registry._cache[registry.DRIVE_GROUP].pop("blockingkind", None)


def test_motorbus_drives_lists_every_kind():
    out = subprocess.run([sys.executable, "-m", "motorbus", "drives"], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    for kind in motorbus.drive_kinds():
        assert re.search(rf"^{kind}\s+(serial|can)\s+\S", out.stdout, re.MULTILINE), out.stdout
