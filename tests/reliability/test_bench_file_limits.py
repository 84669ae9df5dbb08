"""Issue 28 item 6: the bench-file loader is bounded in time and memory whatever the file.

Before: the line locator's regular expressions backtracked cubically on a long line (4 KB:
16.6 s, 8 KB: never ends), `Bench.load` read without a cap (/dev/zero: 2 GB RSS in 2 s, a
200 MB file: 653 MB) and hung on a FIFO.  Each case runs `Bench.load` in a child process of
its own, under a deadline, and reports the child's peak RSS growth over its state after the
import; every case must end in a BenchFileError (an InvalidArgument) naming the file.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import time

import pytest

from motorbus.bench import MAX_FILE_BYTES, MAX_LINE_CHARS, _Locator

from _soak import size

pytestmark = pytest.mark.subprocess

#: Seconds one load may take, child start included: a hang or a cubic scan becomes a failure.
DEADLINE = 30.0
#: Peak RSS the load may add (MB): the 1 MiB cap and a linear parse keep it to a few times that.
MEMORY_MB = 120

_CHILD = r"""
import json, resource, sys, time
import motorbus
from motorbus.bench import Bench, BenchFileError
before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
t0 = time.perf_counter()
try:
    Bench.load(sys.argv[1])
    outcome, message = "loaded", ""
except BenchFileError as e:
    outcome, message = "BenchFileError", str(e)
except BaseException as e:
    outcome, message = type(e).__name__, str(e)[:300]
took = time.perf_counter() - t0
grew = (resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before) / 1024
print(json.dumps({"outcome": outcome, "message": message[:400], "seconds": took, "rss_mb": grew}))
"""


def _load_in_child(path: str) -> dict:
    t0 = time.monotonic()
    try:
        out = subprocess.run([sys.executable, "-c", _CHILD, path], capture_output=True, text=True, timeout=DEADLINE)
    except subprocess.TimeoutExpired:
        pytest.fail(f"Bench.load({path}) did not end in {DEADLINE} s")
    assert out.returncode == 0, out.stderr
    result = json.loads(out.stdout.strip().splitlines()[-1])
    result["wall"] = time.monotonic() - t0
    return result


def _check(result: dict, path: str, says: str) -> None:
    assert result["outcome"] == "BenchFileError", result
    assert result["message"].startswith(path), result
    assert says in result["message"], result
    assert result["rss_mb"] < MEMORY_MB, result


# Lines that made the old locator backtrack (cubic: "[" then spaces, a key of word characters
# then no "=", an inline table of unterminated keys), and the dotted keys and headers that
# make tomllib itself quadratic; each at the length that used to take 16 s, twice that, and
# the longest line a bench file may have.
_LONG_LINES = {
    "header_spaces": lambda n: "[" + " " * n,
    "header_words": lambda n: "[" + "a " * (n // 2),
    "key_no_equals": lambda n: "a" * n,
    "inline_words": lambda n: "x = {" + "a " * (n // 2),
    "inline_quotes": lambda n: "x = {" + '"a' * (n // 2),
    "dotted_header": lambda n: "[" + '"a".' * (n // 4) + "b]",
    "dotted_key": lambda n: "a." * (n // 2) + "b = 1",
}


@pytest.mark.parametrize("pattern", sorted(_LONG_LINES))
@pytest.mark.parametrize("length", [4096, 8192, MAX_LINE_CHARS - 16])
def test_long_lines_are_located_in_linear_time(tmp_path, pattern, length):
    text = "[axis.x]\nkind = \"cia402\"\n" + _LONG_LINES[pattern](length) + "\n"
    t0 = time.perf_counter()
    _Locator(text)
    assert time.perf_counter() - t0 < 5.0, "the locator is not linear"   # cubic: 16 s at 4 KB
    path = str(tmp_path / f"{pattern}.toml")
    with open(path, "w") as f:
        f.write(text)
    result = _load_in_child(path)
    assert result["outcome"] == "BenchFileError" and result["message"].startswith(path), result
    assert result["rss_mb"] < MEMORY_MB, result


def test_a_line_longer_than_the_cap_is_refused_naming_it(tmp_path):
    path = str(tmp_path / "long.toml")
    with open(path, "w") as f:
        f.write('[axis.x]\nkind = "cia402"\naddress = "' + "5" * (MAX_LINE_CHARS * 4) + '"\n')
    _check(_load_in_child(path), f"{path}:3: axis.x.address", "longer than a bench file's lines may be")


def test_dev_zero_is_refused_before_it_is_read():
    _check(_load_in_child("/dev/zero"), "/dev/zero", "not a regular file (a character device)")


def test_a_fifo_is_refused_without_waiting_for_a_writer(tmp_path):
    path = str(tmp_path / "bench.fifo")
    os.mkfifo(path)
    _check(_load_in_child(path), path, "not a regular file (a FIFO)")


def test_a_directory_is_refused(tmp_path):
    _check(_load_in_child(str(tmp_path)), str(tmp_path), "not a regular file (a directory)")


@pytest.mark.parametrize("megabytes", [2, size(200, 2000)])
def test_a_file_over_the_cap_is_refused_without_reading_it(tmp_path, megabytes):
    path = str(tmp_path / "huge.toml")
    with open(path, "wb") as f:      # sparse: the size is there, the disk is not used
        f.truncate(megabytes << 20)
    _check(_load_in_child(path), path, f"larger than a bench file may be ({MAX_FILE_BYTES} bytes)")


def test_a_file_at_the_cap_loads_in_bounded_time_and_memory(tmp_path):
    """Just under 1 MiB of valid TOML: many short tables and keys, then the checker's error."""
    path = str(tmp_path / "big.toml")
    lines, total, i = [], 0, 0
    while True:
        line = f"[axis.a{i}]\nkind = \"cia402\"\nbus = \"b\"\naddress = {i % 127 + 1}\n"
        if total + len(line) > MAX_FILE_BYTES:
            break
        lines.append(line)
        total += len(line)
        i += 1
    with open(path, "w") as f:
        f.write("".join(lines))
    _check(_load_in_child(path), f"{path}:3: axis.a0.bus", "no [bus.b] in this file")


def test_nesting_is_refused_before_tomllib_recurses(tmp_path):
    path = str(tmp_path / "nested.toml")
    with open(path, "w") as f:
        f.write('[axis.x]\nkind = "cia402"\nparams = { a = ' + "[" * 2000 + "]" * 2000 + " }\n")
    _check(_load_in_child(path), f"{path}:3: axis.x.params", "nested more than")


def test_many_long_dotted_keys_stay_bounded(tmp_path):
    """64 lines of 4 000-part table names: 75 s and 16 GB inside tomllib before the key limit."""
    path = str(tmp_path / "dotted.toml")
    n = MAX_LINE_CHARS // 4
    with open(path, "w") as f:
        f.write("\n".join(f"[k{i}." + "a." * n + "b]" for i in range(MAX_FILE_BYTES // (2 * n + 16))))
    _check(_load_in_child(path), f"{path}:1: k0.a", "a dotted key of more than")
