"""Issue 28, the Python side: typed errors from bench files (item 7), integer addresses
(issue 22), `sim.store_path` that would overwrite a user's file (item 10), the Poller's
bounded retention (item 9), `motion.plan(shape=None)` (item 10).  Each bench-file mistake
must be a BenchFileError reading `file:line: key: ...`; a bus that refuses the connection
is not a mistake in the file."""
from __future__ import annotations

import socket
import time

import numpy as np
import pytest

import motorbus
from motorbus import Bench, BenchFileError, Poller, motion


def _load(tmp_path, text: str, *, sim: bool = True, name: str = "bench.toml") -> Bench:
    path = tmp_path / name
    path.write_text(text)
    return Bench.load(path, sim=sim)


def _refused(tmp_path, text: str, line: int, key: str, says: str, *, sim: bool = True) -> BenchFileError:
    with pytest.raises(BenchFileError) as info:
        _load(tmp_path, text, sim=sim).close()
    e = info.value
    path = str(tmp_path / "bench.toml")
    assert str(e).startswith(f"{path}:{line}: {key}: "), str(e)
    assert says in str(e), str(e)
    assert (e.line, e.key) == (line, key)
    return e


_CAN = '[bus.b]\nspec = "virtual:round2"\n[axis.z]\nkind = "cia402"\nbus = "b"\naddress = 5\n'
_SERIAL = '[line.l]\nport = "/dev/ttyUSB-round2"\n[axis.x]\nkind = "arcus"\nline = "l"\naddress = 1\n'


# ---- item 7: every mistake typed and placed -------------------------------------------------------
def test_an_address_of_thousands_of_digits(tmp_path):
    # 5 000 digits: Python's int conversion limit (ValueError from tomllib before the fix)
    _refused(tmp_path, _CAN.replace("address = 5", "address = " + "9" * 5000), 6, "axis.z.address",
             "a number of 5000 digits: too large")
    # 100 000 digits: a line longer than a bench file's
    _refused(tmp_path, _CAN.replace("address = 5", "address = " + "9" * 100_000), 6, "axis.z.address",
             "longer than a bench file's lines may be")
    # as a string: the kind's parser (int() of it) raised ValueError
    _refused(tmp_path, _CAN.replace("address = 5", 'address = "' + "9" * 5000 + '"'), 6, "axis.z.address",
             "an address of 5000 characters")


def test_two_thousand_nested_arrays(tmp_path):
    _refused(tmp_path, _CAN + "params = { a = " + "[" * 2000 + "]" * 2000 + " }\n", 7, "axis.z.params.a",
             "nested more than 32 deep")


@pytest.mark.parametrize("key, value, says", [
    ("baud", "9223372036854775807", "expected an integer in 0..2e+07"),
    ("baud", "-1", "expected an integer in 0..2e+07"),
    ("timeout", "1e300", "expected a number in 0..3600"),
    ("turnaround", "100", "expected a number in 0..10"),
])
def test_line_numbers_out_of_range(tmp_path, key, value, says):
    text = _SERIAL.replace('port = "/dev/ttyUSB-round2"', f'port = "/dev/ttyUSB-round2"\n{key} = {value}')
    _refused(tmp_path, text, 3, f"line.l.{key}", says)


@pytest.mark.parametrize("sim", [False, True], ids=["hardware", "sim"])
@pytest.mark.parametrize("spec, says", [
    ("socketcand:127.0.0.1:99999/can0", "port 99999: a TCP port 1..65535"),
    ("socketcand:127.0.0.1:0/can0", "port 0: a TCP port 1..65535"),
    ("slcan:/dev/ttyACM0@-5", "bitrate -5: a CAN bit rate"),
    ("nope:x", "unknown bus scheme 'nope'"),
])
def test_a_bad_bus_spec_is_named_with_or_without_sim(tmp_path, spec, says, sim):
    """Under sim=True the bus is replaced by a served one: the file's spec is still checked."""
    _refused(tmp_path, _CAN.replace("virtual:round2", spec), 2, "bus.b.spec", says, sim=sim)


def test_a_bus_that_refuses_the_connection_is_not_a_mistake_in_the_file(tmp_path):
    with socket.socket() as s:      # a port nothing listens on: bound, never listening
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
        with pytest.raises(motorbus.LinkDown) as info:
            _load(tmp_path, _CAN.replace("virtual:round2", f"socketcand:127.0.0.1:{port}/can0"), sim=False)
    assert not isinstance(info.value, BenchFileError)
    assert str(info.value).startswith(f"{tmp_path / 'bench.toml'}:2: bus 'b': "), str(info.value)


@pytest.mark.parametrize("text, line, key, says", [
    (_SERIAL + 'sim = { plus_limit = "x" }\n', 7, "axis.x.sim.plus_limit", "wrong value 'x' for plus_limit (str)"),
    (_CAN + "sim = { heartbeat_ms = -1 }\n", 7, "axis.z.sim.heartbeat_ms", "wrong value -1 for heartbeat_ms"),
    (_CAN.replace("cia402", "pmc007") + "sim = { ext1_switch = 100 }\n", 7, "axis.z.sim.ext1_switch",
     "wrong value 100 for ext1_switch (int)"),
    (_CAN + 'sim = { start_position = 100, plus_limit = [1, 2] }\n', 7, "axis.z.sim.plus_limit", "wrong value [1, 2]"),
])
def test_sim_options_of_the_wrong_type_name_the_option(tmp_path, text, line, key, says):
    _refused(tmp_path, text, line, key, says)


@pytest.mark.parametrize("scale", ["1e-300", "1e300", "-1e-13"])
def test_a_scale_no_drive_can_represent(tmp_path, scale):
    """1e-300 loaded, then a move of 1 mm asked 1e300 counts: an untyped TypeError."""
    _refused(tmp_path, _CAN + f'units = {{ name = "mm", scale = {scale} }}\n', 7, "axis.z.units.scale",
             "its magnitude must be in 1e-12..1e+12")


def test_the_smallest_scale_still_loads(tmp_path):
    with _load(tmp_path, _CAN + 'units = { name = "km", scale = 1e-12 }\n') as bench:
        assert bench["z"].units.scale == 1e-12


# ---- issue 22: an integer address is that integer ----------------------------------------------
def test_an_integer_address_means_that_integer(tmp_path):
    text = ('[bus.b]\nspec = "virtual:round2-unitek"\n[axis.u]\nkind = "unitek"\nbus = "b"\naddress = 0x201\n'
            'sim = { calibrated = true }\n')
    with _load(tmp_path, text) as bench:
        assert bench.config["u"].address == "0x201"     # 513, not "513" read as hex 0x513
        bench["u"].enable()
        assert bench["u"].status.enabled
    with _load(tmp_path, _SERIAL.replace("address = 1", "address = 7")) as bench:
        assert bench.config["x"].address == "07"


# ---- item 10: sim.store_path ----------------------------------------------------------------------
def test_store_path_refuses_a_file_that_is_not_a_store(tmp_path):
    mine = tmp_path / "notes.txt"
    mine.write_text("my notes\nnot a store file\n")
    e = _refused(tmp_path, _SERIAL + f'sim = {{ store_path = "{mine}" }}\n', 7, "axis.x.sim.store_path",
                 "is not a store file written by motorbus")
    assert "a simulator would overwrite it" in str(e)
    assert mine.read_text() == "my notes\nnot a store file\n"
    _refused(tmp_path, _SERIAL + f'sim = {{ store_path = "{tmp_path}" }}\n', 7, "axis.x.sim.store_path",
             "is not a regular file (a directory)")
    json_file = tmp_path / "data.json"
    json_file.write_text('{"name": "not registers"}')
    _refused(tmp_path, _CAN.replace("cia402", "unitek").replace("address = 5", "address = 0x201")
             + f'sim = {{ store_path = "{json_file}" }}\n', 7, "axis.z.sim.store_path", "register -> integer")


@pytest.mark.parametrize("kind, address, transport", [
    ("arcus", "1", "line"), ("arcus-canopen", "1", "bus"), ("pmc007", "5", "bus"), ("unitek", "0x201", "bus")])
def test_store_path_takes_a_free_path_and_the_simulators_own_store_file(tmp_path, kind, address, transport):
    store = tmp_path / f"{kind}.store"
    link = ('[line.l]\nport = "/dev/ttyUSB-round2"\n' if transport == "line"
            else f'[bus.l]\nspec = "virtual:round2-store-{kind}"\n')
    text = (link + f'[axis.a]\nkind = "{kind}"\n{transport} = "l"\naddress = {address}\n'
            + f'sim = {{ store_path = "{store}"'
            + (", calibrated = true" if kind == "unitek" else "") + " }\n")
    with _load(tmp_path, text) as bench:     # free: taken
        bench["a"].store()
    deadline = time.monotonic() + 10
    while not store.exists():
        assert time.monotonic() < deadline, "the simulator wrote no store file"
        time.sleep(0.05)
    written = store.read_bytes()
    assert written.strip()
    with _load(tmp_path, text) as bench:     # its own store file: taken again
        assert bench["a"].kind == kind


# ---- item 9: the Poller retains a bounded number of rows -----------------------------------------
def test_poller_retention_is_bounded_while_read_returns_every_row(tmp_path):
    with _load(tmp_path, _CAN) as bench:
        with Poller(bench.axes, rate_hz=500, keep=0.2, mode="ask") as poller:
            assert poller.keep_rows == 100
            got = 0
            deadline = time.monotonic() + 1.0
            while time.monotonic() < deadline:
                time.sleep(0.05)
                got += len(poller.read()["t"])
            frame = poller.frame()
        rows = len(frame["t"])
        assert 0 < rows <= 100
        assert poller.discarded > 0 and poller.discarded + rows >= got
        # the retained rows are the newest ones, consecutive deadlines
        assert np.all(np.diff(frame["t"]) > 0)
        assert frame["t"][-1] - frame["t"][0] <= 0.2 + 1e-9


def test_poller_keep_none_retains_every_row_and_keep_0_none(tmp_path):
    with _load(tmp_path, _CAN) as bench:
        with Poller(bench.axes, rate_hz=200, keep=None, mode="ask") as everything, \
                Poller(bench.axes, rate_hz=200, keep=0, mode="ask") as nothing:
            total = 0
            for _ in range(6):
                time.sleep(0.05)
                everything.read()
                total += len(nothing.read()["t"])
        assert len(everything.frame()["t"]) >= 40 and everything.discarded == 0
        assert len(nothing.frame()["t"]) == 0 and nothing.discarded >= total > 0


@pytest.mark.parametrize("keep", [-1, float("nan"), float("inf"), "10", True])
def test_poller_keep_must_be_seconds(tmp_path, keep):
    with _load(tmp_path, _CAN) as bench:
        with pytest.raises(motorbus.InvalidArgument, match="Poller keep"):
            Poller(bench.axes, keep=keep, start=False)


def test_poller_default_retention_is_ten_minutes(tmp_path):
    with _load(tmp_path, _CAN) as bench:
        p = Poller(bench.axes, rate_hz=1000, start=False)
        assert p.keep_rows == 600_000


# ---- item 10: motion.plan(shape=None) ----------------------------------------------------------------
@pytest.mark.parametrize("shape", [None, 3, "square"])
def test_plan_with_a_wrong_shape_is_invalid_argument(shape):
    with pytest.raises(motorbus.InvalidArgument, match="motion.plan shape"):
        motion.plan(10, max_velocity=1, max_acceleration=1, shape=shape)


# ---- item 1: a forked child does not stop its parent's drives --------------------------------------
def test_a_forked_child_ended_by_sigterm_leaves_the_parents_drives_alone(tmp_path):
    import os
    import signal

    from motorbus import _stop_at_exit

    with _load(tmp_path, _CAN) as bench:
        z = bench["z"]
        z.enable()
        z.jog(1000)
        r, w = os.pipe()
        pid = os.fork()
        if pid == 0:   # the child: tracks nothing of its own, ends by SIG_DFL at once
            try:
                os.close(r)
                os.write(w, b"%d" % len(_stop_at_exit._live))
                os.close(w)
                time.sleep(30)
            finally:   # whatever happens, the child never returns into pytest
                os._exit(0)
        os.close(w)
        tracked_in_child = os.read(r, 16)
        os.close(r)
        os.kill(pid, signal.SIGTERM)
        _, status = os.waitpid(pid, 0)
        assert tracked_in_child == b"0"
        assert os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGTERM
        time.sleep(0.1)
        assert z.status.moving           # the parent's jog goes on
        z.stop()


# ---- item 6: the linear locator places what the regular expressions placed ----------------------
def test_the_locator_places_headers_keys_and_inline_keys():
    from motorbus.bench import _Locator

    text = ('# a bench\n'
            '[ bus . "can 0" ]   # spaces and a quoted part\n'
            'spec = "virtual:x"\n'
            '[axis.z]\n'
            'params = { "0x6081" = 20000, \'0x6083\' = 1, plain = "a = b, c = {" }\n'
            'units = { name = "mm", scale = 0.01 }  # scale = 2 in a comment\n'
            'see [the docs](x.md)\n')
    lines = _Locator(text).lines
    assert lines[("bus", "can 0")] == 2 and lines[("bus", "can 0", "spec")] == 3
    assert lines[("axis", "z", "params", "0x6081")] == 5 and lines[("axis", "z", "params", "0x6083")] == 5
    assert lines[("axis", "z", "params", "plain")] == 5
    assert ("axis", "z", "params", "c") not in lines      # inside a string
    assert lines[("axis", "z", "units", "scale")] == 6
    assert ("the docs",) not in lines                       # not a header: text after "]"


def test_a_quoted_parameter_the_drive_lacks_is_placed(tmp_path):
    _refused(tmp_path, _CAN + 'params = { "0x6081" = 20000, "0x7FFF" = 1 }\n', 7, "axis.z.params.0x7FFF",
             "has no parameter '0x7FFF'")
