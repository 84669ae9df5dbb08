"""One vocabulary for how a drive stops (motorbus.stopping), said once: every entry point
that takes a stop word — open_drive and each kind's Drive, the native clients, a bench
file, Bench.stop_all (the pytest plugin's teardown, ``motorbus stop``), the command line
and a pytest run on a bench file — refuses a wrong one with the same
``InvalidArgument`` and the same message naming the allowed words."""
from __future__ import annotations

import subprocess
import sys
import textwrap
from importlib import metadata

import pytest

import motorbus
from motorbus import Bench, BenchFileError, registry
from motorbus.stopping import STOP_WAYS, check_stop_way, stop_words

pytest_plugins = ["pytester"]

WORDS = "'stop', 'quick_stop', 'disable' or None"
BAD = "brake"


def message(what: str, bad=BAD, words: str = WORDS) -> str:
    return f"{what}: one of {words}, not {bad!r}"


def test_the_words_are_said_once():
    assert STOP_WAYS == ("stop", "quick_stop", "disable", None)
    assert stop_words() == WORDS
    # The Drive layer's and a vendor module's names are the same object, not copies.
    from motorbus.drives import arcus
    assert motorbus.drive.STOP_WAYS is STOP_WAYS and arcus.STOP_WAYS is STOP_WAYS
    for good in STOP_WAYS:
        assert check_stop_way(good) is good
    # Near misses, and values equal to nothing but not words (True == 1, a list is unhashable).
    for bad in ("Stop", "stop ", "", "none", True, 0, b"stop", ["stop"]):
        with pytest.raises(motorbus.InvalidArgument) as e:
            check_stop_way(bad, "on_exit")
        assert str(e.value) == message("on_exit", bad)


@pytest.mark.parametrize("key", ["on_error", "on_exit"])
@pytest.mark.parametrize("kind", sorted(registry.drive_kinds()))
def test_open_drive_refuses_a_bad_word_before_opening_anything(kind, key, tmp_path):
    cls = registry.drive_plugin(kind)
    # A link that cannot be opened: a check after opening would fail another way.
    where = ({"line": str(tmp_path / "no-such-port")} if cls.transport == "serial"
             else {"bus": "socketcand:127.0.0.1:9/can0"})
    with pytest.raises(motorbus.InvalidArgument) as e:
        motorbus.open_drive(kind, address=cls.default_address, **where, **{key: BAD})
    assert str(e.value) == message(key)


@pytest.mark.parametrize("kind", sorted(registry.drive_kinds()))
def test_each_kinds_drive_refuses_a_bad_word(kind):
    """The Drive constructor checks too (a kind opened without open_drive: its own open, a bench)."""
    cls = registry.drive_plugin(kind)
    with pytest.raises(motorbus.InvalidArgument) as e:
        cls(None, on_exit=BAD)
    assert str(e.value) == message("on_exit")


def _native_clients():
    from motorbus.canopen.cia402 import Cia402
    from motorbus.drives.arcus import ArcusClient
    from motorbus.drives.dmac import DmacClient
    from motorbus.drives.pmc007 import Pmc007
    from motorbus.drives.unitek import Unitek
    # The word is checked before the link is touched: None is no link at all.
    return [(lambda **kw: ArcusClient(None, **kw), WORDS, ""), (lambda **kw: DmacClient(None, **kw), WORDS, ""),
            (lambda **kw: Pmc007(None, **kw), WORDS, ""), (lambda **kw: Unitek(None, **kw), WORDS, ""),
            # The CANopen layer's host has no decelerated stop of its own: its subset, named.
            (lambda **kw: Cia402(None, 5, **kw), "'quick_stop', 'disable' or None", "Cia402 ")]


@pytest.mark.parametrize("key", ["on_error", "on_exit"])
def test_native_clients_refuse_a_bad_word(key):
    for make, words, prefix in _native_clients():
        with pytest.raises(motorbus.InvalidArgument) as e:
            make(**{key: BAD})
        assert str(e.value) == message(prefix + key, words=words)


def _bench_file(tmp_path, options: str = "") -> str:
    path = tmp_path / "bench.toml"
    path.write_text(textwrap.dedent(f"""\
        [line.rs485]
        port = "{tmp_path / 'no-such-port'}"

        [axis.x]
        kind = "arcus"
        line = "rs485"
        address = "01"
        {options}
        """))
    return str(path)


@pytest.mark.parametrize("key", ["on_error", "on_exit"])
def test_a_bench_file_with_a_bad_word_is_refused_where_it_says_it(tmp_path, key):
    path = _bench_file(tmp_path, f'options = {{ {key} = "{BAD}" }}')
    # Refused while the file is read: the line's port (absent here) is never opened.
    with pytest.raises(BenchFileError) as e:
        Bench.load(path)
    assert isinstance(e.value, motorbus.InvalidArgument)
    assert message(key) in str(e.value)
    assert f"bench.toml:8: axis.x.options.{key}" in str(e.value)


def test_bench_stop_all_refuses_a_word_that_is_not_a_stop(tmp_path):
    with Bench.load(_bench_file(tmp_path), sim=True) as bench:
        x = bench["x"]
        x.enable()
        # Before the check, "close" reached getattr(drive, how)() and closed every axis.
        for bad in ("close", None, "home"):
            with pytest.raises(motorbus.InvalidArgument) as e:
                bench.stop_all(bad)
            assert str(e.value) == message("Bench.stop_all how", bad, "'stop', 'quick_stop' or 'disable'")
        assert not x.closed and x.status.enabled
        assert bench.stop_all("disable") == []
        assert not x.status.enabled


def test_the_command_line_refuses_a_bench_file_with_a_bad_word(tmp_path):
    path = _bench_file(tmp_path, f'options = {{ on_exit = "{BAD}" }}')
    r = subprocess.run([sys.executable, "-m", "motorbus", "stop", path, "--sim"], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 2, r.stderr          # EXIT_USAGE: the bench file is wrong
    assert message("on_exit") in r.stderr
    assert "axis.x.options.on_exit" in r.stderr


@pytest.mark.subprocess
def test_a_pytest_run_on_a_bench_file_with_a_bad_word_says_why(pytester, tmp_path):
    path = _bench_file(tmp_path, f'options = {{ on_error = "{BAD}" }}')
    pytester.makepyfile(test_uses_bench="def test_x(bench):\n    pass\n")
    eps = metadata.entry_points(group="pytest11")
    plugin = [] if any(ep.value == "motorbus.pytest_plugin" for ep in eps) else ["-p", "motorbus.pytest_plugin"]
    result = pytester.runpytest_subprocess(*plugin, "-p", "no:cacheprovider", "--bench-sim", path, timeout=240)
    assert result.ret != 0
    text = result.stdout.str() + result.stderr.str()
    assert "BenchFileError" in text and message("on_error") in text
