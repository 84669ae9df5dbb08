"""A bench: buses, serial lines and named axes, described once in a TOML file.

.. code-block:: toml

    [bus.can0]
    spec = "socketcand:10.0.0.5:29536/can0"     # any open_bus spec
    [line.rs485]
    port = "/dev/ttyUSB0"
    baud = 9600
    [axis.x]
    kind = "..."                                 # a serial kind (`motorbus drives` lists them)
    line = "rs485"
    address = 1
    units = { name = "mm", scale = 0.0025 }
    params = { ... }                             # the kind's own parameter names (docs/drives/)
    [axis.z]
    kind = "cia402"
    bus = "can0"
    address = 5

``Bench.load(path)`` opens every bus and line once and every axis on them
(``bench["x"]`` is a :class:`motorbus.Drive`).  ``sim=True`` replaces each axis
by its plugin's simulator behind the same kind of transport: a serial line
becomes a pty served by a line server, a bus a virtual bus served over
socketcand on 127.0.0.1 — so a file written for hardware runs unchanged
without it.  Nothing here names a vendor: every registered kind works.

Errors in a file are :class:`BenchFileError` (an ``InvalidArgument``) reading
``file:line: key: what was expected``.  ``Bench.load`` reads a regular file of at
most :data:`MAX_FILE_BYTES`, with the line, key and nesting limits below, so that
any file ends in a Bench or an error within about a second (docs/bench-files.md).
"""
from __future__ import annotations

import itertools
import math
import os
import re
import stat
import time
import tomllib
from dataclasses import dataclass, field
from typing import Any, Iterator, Mapping, Optional, Sequence

from . import _core, faces, registry
from .bus import open_bus, parse_spec
from .drive import Drive, DriveStatus, MoveFailed, Units
from .stopping import STOP_WAYS, check_stop_way

__all__ = ["Bench", "BenchFileError", "AxisConfig", "ParamDiff", "StartReport"]

_SECTIONS = ("bus", "line", "axis", "epics")
#: [epics]: read by `motorbus serve` (docs/serve.md, docs/epics.md); the bench itself ignores it.
_EPICS_KEYS = {"prefix"}
_BUS_KEYS = {"spec"}
_LINE_KEYS = {"port", "baud", "timeout", "turnaround"}
_AXIS_KEYS = {"kind", "line", "bus", "address", "units", "params", "options", "sim"}
_sim_names = itertools.count(1)
#: Ranges a bench file's numbers are held to (docs/bench-files.md): beyond them a value is a
#: typing mistake, and the transports below would refuse it with an untyped error.
MAX_BAUD = 20_000_000            # serial line rate, baud (0 = keep the port's)
MAX_TIMEOUT_S = 3600.0           # reply timeout of a line
MAX_TURNAROUND_S = 10.0          # RS-485 quiet time before a request
#: units.scale: user units per native unit, in magnitude.  Outside, a move of one user unit is
#: more than 1e12 native units (or less than 1e-12), which no drive's position register holds.
SCALE_RANGE = (1e-12, 1e12)
#: Bus spec arguments every scheme shares: (lowest, highest, what).
_SPEC_RANGES = {"port": (1, 65535, "a TCP port"), "bitrate": (0, 10_000_000, "a CAN bit rate (bit/s, 0 = keep)")}


class BenchFileError(_core.InvalidArgument):
    """A mistake in a bench file: ``file:line: key: what was expected``."""

    def __init__(self, message: str, *, source: str = "<bench>", line: Optional[int] = None,
                 key: str = "") -> None:
        self.source, self.line, self.key, self.reason = source, line, key, message
        where = source if line is None else f"{source}:{line}"
        # A hostile file can make a key or a quoted value a megabyte long: the message stays readable.
        key, message = _clip(key, 80), _clip(message, 400)
        super().__init__(f"{where}: {key}: {message}" if key else f"{where}: {message}")


def _clip(text: str, most: int) -> str:
    return text if len(text) <= most else f"{text[:most // 2]}...({len(text)} characters)...{text[-most // 4:]}"


class _Locator:
    """Line numbers of tables and keys in TOML text (tomllib gives none).

    Understands what bench files use: ``[a.b]`` headers (bare or quoted parts),
    ``key = value`` lines and inline tables (``units = { name = "mm" }``: the
    inner keys are on the key's line).  A key it cannot place gets its table's
    line, or none.

    One pass over each line, no regular expression: every character is looked at
    a bounded number of times (the regular expressions this replaced backtracked
    cubically on a long line: 16.6 s for 4 KB)."""

    _DEPTH = 8    # inline tables nested deeper than this are not located (a bench file has 2)

    def __init__(self, text: Optional[str]) -> None:
        self.lines: dict[tuple, int] = {}
        if not text:
            return
        table: tuple = ()
        for n, raw in enumerate(text.splitlines(), start=1):
            i = _skip_space(raw, 0)
            if i < len(raw) and raw[i] == "[":
                if raw.startswith("[[", i):
                    continue   # an array of tables: not bench syntax (the checker says so by key)
                parts, j = _parse_key(raw, i + 1)
                j = _skip_space(raw, j)
                end = _skip_space(raw, j + 1)
                if parts and j < len(raw) and raw[j] == "]" and (end == len(raw) or raw[end] == "#"):
                    # Beyond MAX_KEY_PARTS the file is refused anyway: only its line is needed,
                    # and every prefix of a 4 000-part name would cost the square of it.
                    table = tuple(parts[:MAX_KEY_PARTS])
                    for k in range(1, len(table) + 1):  # [axis.x] is also where "axis" first appears
                        self.lines.setdefault(table[:k], n)
                continue
            parts, j = _parse_key(raw, i)
            j = _skip_space(raw, j)
            if not parts or j >= len(raw) or raw[j] != "=":
                continue
            path = (table + tuple(parts))[:MAX_KEY_PARTS]
            self.lines.setdefault(path, n)
            j = _skip_space(raw, j + 1)
            if j < len(raw) and raw[j] == "{":
                self._inline(raw, j, path, n)

    def _inline(self, raw: str, i: int, path: tuple, n: int) -> None:
        """Registers the keys of the inline table opening at raw[i] ("{") on line n."""
        stack = [path]          # the table each open "{" stands for; None: inside an array
        expect_key = True
        i += 1
        while i < len(raw) and stack:
            c = raw[i]
            if c in " \t":
                i += 1
            elif c == "#":
                return
            elif expect_key and stack[-1] is not None and (c in _BARE or c in "\"'"):
                parts, j = _parse_key(raw, i)
                k = _skip_space(raw, j)
                if parts and k < len(raw) and raw[k] == "=":
                    key = (stack[-1] + tuple(parts))[:MAX_KEY_PARTS]
                    self.lines.setdefault(key, n)
                    k = _skip_space(raw, k + 1)
                    if k < len(raw) and raw[k] == "{":   # this key's value is a table: its keys nest under it
                        stack.append(key if len(stack) <= self._DEPTH else None)
                        k += 1
                        expect_key = True
                    else:
                        expect_key = False
                    i = k
                else:
                    expect_key = False
                    i = max(j, _skip_string(raw, i) if c in "\"'" else i + 1)
            elif c in "\"'":
                i = _skip_string(raw, i)
                expect_key = False
            elif c == "{":
                stack.append(stack[-1] if stack[-1] is not None and len(stack) <= self._DEPTH else None)
                expect_key = True
                i += 1
            elif c == "[":
                stack.append(None)
                i += 1
            elif c in "}]":
                stack.pop()
                expect_key = False
                i += 1
            elif c == ",":
                expect_key = stack[-1] is not None
                i += 1
            else:
                i += 1

    def line(self, *path: str) -> Optional[int]:
        for k in range(len(path), 0, -1):
            if path[:k] in self.lines:
                return self.lines[path[:k]]
        return None

    def key_on(self, line: int) -> str:
        """The longest dotted key the file places on ``line`` ("" if none)."""
        best: tuple = ()
        for path, n in self.lines.items():
            if n == line and len(path) > len(best):
                best = path
        return ".".join(best)


_BARE = frozenset("ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789_-")


def _skip_space(s: str, i: int) -> int:
    while i < len(s) and s[i] in " \t":
        i += 1
    return i


def _skip_string(s: str, i: int) -> int:
    """The index after the string that opens at s[i] (a quote); the line's end if it does not close."""
    q = s[i]
    i += 1
    while i < len(s):
        c = s[i]
        if c == "\\" and q == '"':
            i += 2
            continue
        if c == q:
            return i + 1
        i += 1
    return i


def _parse_key(s: str, i: int) -> tuple[list[str], int]:
    """A dotted TOML key at s[i] (bare, "basic" or 'literal' parts): (parts, index after it).
    No key there: ([], i)."""
    parts: list[str] = []
    start = i
    while True:
        i = _skip_space(s, i)
        if i < len(s) and s[i] in "\"'":
            end = _skip_string(s, i)
            if end > len(s) or s[end - 1] != s[i] or end - i < 2:
                return [], start
            parts.append(s[i + 1:end - 1])
            i = end
        else:
            j = i
            while j < len(s) and s[j] in _BARE:
                j += 1
            if j == i:
                return [], start
            parts.append(s[i:j])
            i = j
        k = _skip_space(s, i)
        if k < len(s) and s[k] == ".":
            i = k + 1
            continue
        return parts, i


@dataclass
class AxisConfig:
    """One ``[axis.NAME]`` table, checked."""

    name: str
    kind: str
    address: str
    line: Optional[str] = None
    bus: Optional[str] = None
    units: Optional[Units] = None
    params: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)
    sim: dict = field(default_factory=dict)


@dataclass(frozen=True)
class ParamDiff:
    """A parameter whose value on the drive differs from the bench file's."""

    axis: str
    name: str
    file_value: Any
    drive_value: Any


@dataclass(frozen=True)
class StartReport:
    """How closely ``Bench.move_together`` started its axes.

    ``offsets[axis]``: seconds from the first axis's command being accepted to this
    axis's (0 for the first; axes started by their drives' own trigger share one
    offset); ``skew`` = the largest offset.  ``method``: "software" (commands sent
    back to back, each axis starting when its own command arrives), the drives'
    own method (as their kind names it: a broadcast trigger), or both joined by " + "."""

    method: str
    offsets: dict
    skew: float


class _Checker:
    """Validates the parsed document; every error carries file:line: key."""

    def __init__(self, data: Mapping[str, Any], source: str, text: Optional[str]) -> None:
        self.data, self.source, self.where = data, source, _Locator(text)

    def fail(self, message: str, *path: str) -> BenchFileError:
        return BenchFileError(message, source=self.source, line=self.where.line(*path), key=".".join(path))

    def tables(self, section: str, allowed: set) -> dict[str, dict]:
        raw = self.data.get(section, {})
        if not isinstance(raw, Mapping):
            raise self.fail(f"expected tables [{section}.NAME], not a {type(raw).__name__}", section)
        out = {}
        for name, table in raw.items():
            if not isinstance(table, Mapping):
                raise self.fail(f"expected a table [{section}.{name}]", section, name)
            unknown = sorted(set(table) - allowed)
            if unknown:
                raise self.fail(f"unknown key ([{section}.{name}] takes: {', '.join(sorted(allowed))})",
                                section, name, unknown[0])
            out[name] = dict(table)
        return out

    def text(self, table: Mapping, key: str, *path: str, required: bool = True) -> Optional[str]:
        if key not in table:
            if required:
                raise self.fail(f"missing (required: {key} = \"...\")", *path, key)
            return None
        v = table[key]
        if not isinstance(v, str) or not v.strip():
            raise self.fail(f"expected a non-empty string, not {v!r}", *path, key)
        return v.strip()

    def number(self, table: Mapping, key: str, *path: str, default: float, integer: bool = False,
               minimum: float = 0.0, maximum: float = math.inf) -> float:
        v = table.get(key, default)
        ok = isinstance(v, int) if integer else isinstance(v, (int, float))
        if isinstance(v, bool) or not ok or not math.isfinite(v) or not minimum <= v <= maximum:
            kind = "an integer" if integer else "a number"
            within = f">= {minimum:g}" if maximum == math.inf else f"in {minimum:g}..{maximum:g}"
            raise self.fail(f"expected {kind} {within}, not {v!r}", *path, key)
        return v

    def bus_spec(self, spec: str, *path: str) -> None:
        """The spec's syntax and the ranges every scheme shares, checked without opening it
        (under sim=True the bus is replaced, and a wrong spec must still be reported)."""
        try:
            _scheme, args = parse_spec(spec)
        except _core.InvalidArgument as e:
            raise self.fail(str(e), *path) from None
        for arg, (low, high, what) in _SPEC_RANGES.items():
            v = args.get(arg)
            if v is None:
                continue
            if isinstance(v, bool) or not isinstance(v, int) or not low <= v <= high:
                raise self.fail(f"bus spec {spec!r}: {arg} {v!r}: {what} {low}..{high}", *path)

    def table(self, parent: Mapping, key: str, *path: str) -> dict:
        v = parent.get(key, {})
        if not isinstance(v, Mapping):
            raise self.fail(f"expected a table ({key} = {{ ... }}), not {v!r}", *path, key)
        return dict(v)

    def check(self) -> tuple[dict, dict, dict[str, AxisConfig]]:
        unknown = sorted(set(self.data) - set(_SECTIONS))
        if unknown:
            raise self.fail("unknown section (a bench file has [bus.NAME], [line.NAME], [axis.NAME] and "
                            "[epics])", unknown[0])
        epics = self.data.get("epics", {})
        if not isinstance(epics, Mapping) or set(epics) - _EPICS_KEYS:
            bad = sorted(set(epics) - _EPICS_KEYS)[0] if isinstance(epics, Mapping) else None
            raise self.fail(f"unknown key ([epics] takes: {', '.join(sorted(_EPICS_KEYS))})" if bad else
                            f"expected a table [epics], not a {type(epics).__name__}", "epics", *([bad] if bad else []))
        if "prefix" in epics:
            self.text(epics, "prefix", "epics")
        buses = self.tables("bus", _BUS_KEYS)
        for name, t in buses.items():
            t["spec"] = self.text(t, "spec", "bus", name)
            self.bus_spec(t["spec"], "bus", name, "spec")
        lines = self.tables("line", _LINE_KEYS)
        for name, t in lines.items():
            t["port"] = self.text(t, "port", "line", name)
            if "baud" in t:
                t["baud"] = int(self.number(t, "baud", "line", name, default=0, integer=True, maximum=MAX_BAUD))
            t["timeout"] = self.number(t, "timeout", "line", name, default=0.5, maximum=MAX_TIMEOUT_S)
            t["turnaround"] = self.number(t, "turnaround", "line", name, default=0.0, maximum=MAX_TURNAROUND_S)
        axes = {}
        for name, t in self.tables("axis", _AXIS_KEYS).items():
            axes[name] = self.axis(name, t, buses, lines)
        if not axes:
            raise self.fail("no [axis.NAME] table: a bench needs at least one axis", "axis")
        self.one_kind_per_line(axes, lines)
        return buses, lines, axes

    def axis(self, name: str, t: dict, buses: dict, lines: dict) -> AxisConfig:
        path = ("axis", name)
        kind = self.text(t, "kind", *path)
        kinds = sorted(registry.drive_kinds())
        if kind not in kinds:
            raise self.fail(f"unknown kind {kind!r} (registered: {', '.join(kinds)})", *path, "kind")
        plugin = registry.drive_plugin(kind)
        if "address" not in t:
            raise self.fail(f"missing (e.g. address = {plugin.default_address!r})", *path, "address")
        address = t["address"]
        if isinstance(address, bool) or not isinstance(address, (int, str)):
            raise self.fail(f"expected an integer or a string, not {address!r}", *path, "address")
        if isinstance(address, str) and len(address) > 64:
            raise self.fail(f"an address of {len(address)} characters: no kind has such addresses", *path, "address")
        try:
            # An integer stays an integer: `address = 0x201` is 513, which each kind's
            # check_address reads as that number (str() would make it "513", read as hex by some).
            address = plugin.check_address(address.strip() if isinstance(address, str) else address)
        except (_core.InvalidArgument, ValueError, TypeError, OverflowError) as e:
            raise self.fail(f"{e}", *path, "address") from None
        link_key = "line" if plugin.transport == "serial" else "bus"
        other = "bus" if link_key == "line" else "line"
        if other in t:
            raise self.fail(f"a {kind} axis is on a {'serial line' if link_key == 'line' else 'CAN bus'}: "
                            f"use {link_key} = \"NAME\", not {other}", *path, other)
        link = self.text(t, link_key, *path)
        known = lines if link_key == "line" else buses
        if link not in known:
            names = ", ".join(sorted(known)) or "none defined"
            plural = "lines" if link_key == "line" else "buses"
            raise self.fail(f"no [{link_key}.{link}] in this file ({plural}: {names})", *path, link_key)
        units = None
        if "units" in t:
            u = t["units"]
            if not isinstance(u, Mapping) or set(u) - {"name", "scale"} or "scale" not in u:
                raise self.fail("expected { name = \"mm\", scale = <user units per native unit> }", *path, "units")
            scale = u["scale"]
            if isinstance(scale, bool) or not isinstance(scale, (int, float)) or not math.isfinite(scale) \
                    or scale == 0:
                raise self.fail(f"scale must be a finite non-zero number, not {scale!r}", *path, "units", "scale")
            if not SCALE_RANGE[0] <= abs(scale) <= SCALE_RANGE[1]:
                raise self.fail(f"scale {scale!r}: its magnitude must be in {SCALE_RANGE[0]:g}..{SCALE_RANGE[1]:g} "
                                f"(user units per native unit)", *path, "units", "scale")
            try:
                units = Units(str(u.get("name", "native")), float(scale))
            except _core.InvalidArgument as e:
                raise self.fail(str(e), *path, "units") from None
        options = self.table(t, "options", *path)
        for key in ("on_error", "on_exit"):
            # Checked with the file, before any line or bus is opened (stopping.py's words and message).
            if key in options:
                try:
                    check_stop_way(options[key], key)
                except _core.InvalidArgument as e:
                    raise self.fail(str(e), *path, "options", key) from None
        return AxisConfig(name=name, kind=kind, address=address,
                          line=link if link_key == "line" else None, bus=link if link_key == "bus" else None,
                          units=units, params=self.table(t, "params", *path),
                          options=options, sim=self.table(t, "sim", *path))

    def one_kind_per_line(self, axes: dict[str, AxisConfig], lines: dict) -> None:
        # Two axes answering to one address on one bus would both answer every request.
        on_bus: dict[tuple, AxisConfig] = {}
        for a in axes.values():
            if a.bus is not None:
                first = on_bus.setdefault((a.bus, a.address), a)
                if first is not a:
                    raise self.fail(f"address {a.address} is also axis {first.name!r} ({first.kind}) "
                                    f"on bus {a.bus!r}", "axis", a.name, "address")
        # One RS-485 line speaks one protocol: the framing is the kind's.
        seen: dict[str, AxisConfig] = {}
        for a in axes.values():
            if a.line is None:
                continue
            first = seen.setdefault(a.line, a)
            if first.kind != a.kind:
                raise self.fail(f"line {a.line!r} already carries {first.kind} axis {first.name!r}: "
                                f"one protocol per line", "axis", a.name, "line")
            if first is not a and first.address == a.address:
                raise self.fail(f"address {a.address} is also axis {first.name!r} on line {a.line!r}",
                                "axis", a.name, "address")


#: The largest bench file read (bytes).  A bench of 127 CAN nodes and 99 axes on each of a
#: dozen serial lines is well under 100 KB; a larger file is a mistake (or /dev/zero), not a bench.
MAX_FILE_BYTES = 1 << 20
#: The longest line read (characters).
MAX_LINE_CHARS = 16384
#: The most parts a dotted key may have (axis.x.units.scale has 4).
MAX_KEY_PARTS = 16
#: Arrays and inline tables nested deeper than this are refused before tomllib recurses into them.
MAX_NESTING = 32


def read_text(source: str) -> str:
    """The text of a bench file, checked to be a bench-sized regular file before it is
    read (a FIFO would block the open, a device or /dev/zero would never end)."""
    try:
        st = os.stat(source)
    except OSError as e:
        raise BenchFileError(f"cannot read: {e.strerror}", source=source) from None
    if not stat.S_ISREG(st.st_mode):
        raise BenchFileError(f"not a regular file (a {_file_type(st.st_mode)}): a bench file is a TOML file",
                             source=source)
    if st.st_size > MAX_FILE_BYTES:
        raise BenchFileError(f"{st.st_size} bytes: larger than a bench file may be ({MAX_FILE_BYTES} bytes)",
                             source=source)
    try:
        # O_NONBLOCK: should the path have been replaced by a FIFO since the stat, the open
        # must not wait for a writer; the fstat below then refuses it.
        fd = os.open(source, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_CLOEXEC", 0))
    except OSError as e:
        raise BenchFileError(f"cannot read: {e.strerror}", source=source) from None
    try:
        st = os.fstat(fd)
        if not stat.S_ISREG(st.st_mode):
            raise BenchFileError(f"not a regular file (a {_file_type(st.st_mode)})", source=source)
        chunks, size = [], 0
        while size <= MAX_FILE_BYTES:   # a file that grows while it is read is still capped
            chunk = os.read(fd, MAX_FILE_BYTES + 1 - size)
            if not chunk:
                break
            chunks.append(chunk)
            size += len(chunk)
    except OSError as e:
        raise BenchFileError(f"cannot read: {e.strerror}", source=source) from None
    finally:
        os.close(fd)
    if size > MAX_FILE_BYTES:
        raise BenchFileError(f"larger than a bench file may be ({MAX_FILE_BYTES} bytes)", source=source)
    raw = b"".join(chunks)
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as e:
        raise BenchFileError(f"not UTF-8 text ({e.reason} at byte {e.start})", source=source) from None


def parse_file(source: str) -> tuple[str, dict]:
    """(text, document) of a bench file; every mistake a BenchFileError with its line."""
    text = read_text(source)
    return text, parse_text(text, source)


def parse_text(text: str, source: str = "<bench>") -> dict:
    lines = text.splitlines()
    if lines and max(map(len, lines)) > MAX_LINE_CHARS:
        n = next(i for i, line in enumerate(lines, start=1) if len(line) > MAX_LINE_CHARS)
        # tomllib takes quadratic time in the parts of a dotted key: a 1 MB line of "a".
        # parts takes minutes.  No bench line comes near this.
        raise BenchFileError(f"a line of {len(lines[n - 1])} characters: longer than a bench file's lines may be "
                             f"({MAX_LINE_CHARS})", source=source, line=n, key=_Locator(text).key_on(n))
    bad = _prescan(text)
    if bad is not None:
        raise BenchFileError(bad[1], source=source, line=bad[0], key=_Locator(text).key_on(bad[0]))
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as e:
        m = re.search(r"\(at line (\d+), column (\d+)\)", str(e))
        line = int(m.group(1)) if m else None
        raise BenchFileError(f"bad TOML: {str(e).split(' (at line')[0]}", source=source, line=line) from None
    except ValueError as e:
        # Python refuses to convert an integer of more than sys.get_int_max_str_digits() digits.
        line, digits = _longest_number(text)
        raise BenchFileError(f"a number of {digits} digits: too large ({e})", source=source, line=line,
                             key=_Locator(text).key_on(line) if line else "") from None
    except RecursionError:
        raise BenchFileError("nested too deeply", source=source) from None


def _file_type(mode: int) -> str:
    for test, name in ((stat.S_ISDIR, "directory"), (stat.S_ISFIFO, "FIFO"), (stat.S_ISCHR, "character device"),
                       (stat.S_ISBLK, "block device"), (stat.S_ISSOCK, "socket")):
        if test(mode):
            return name
    return "special file"


def _prescan(text: str) -> Optional[tuple[int, str]]:
    """What tomllib must not be given: "[" / "{" outside strings and comments nested
    deeper than MAX_NESTING (tomllib recurses once per level: RecursionError), or a
    dotted key of more than MAX_KEY_PARTS parts (tomllib's time and memory grow with
    the square of the parts: 64 lines of 4 000-part table names took 75 s and 16 GB).
    (line, what) of the first, or None.  One pass, linear."""
    depth, dots, line, i, n = 0, 0, 1, 0, len(text)
    at_line_start = True
    while i < n:
        c = text[i]
        if c == "\n":
            line += 1
            at_line_start = True
            dots = 0
            i += 1
            continue
        if c in "\"'":
            triple = text.startswith(c * 3, i)
            if triple:
                end = text.find(c * 3, i + 3)
                stop = n if end < 0 else end + 3
                line += text.count("\n", i, stop)
                i = stop
            else:
                j = i + 1
                while j < n and text[j] not in (c, "\n"):
                    j += 2 if (text[j] == "\\" and c == '"') else 1
                i = j + 1 if j < n and text[j] == c else j
            at_line_start = False
            continue
        if c == "#":
            j = text.find("\n", i)
            i = n if j < 0 else j
            continue
        if c == ".":
            dots += 1
            if dots >= MAX_KEY_PARTS:
                return line, f"a dotted key of more than {MAX_KEY_PARTS} parts"
        elif c in "=,":
            dots = 0
        elif c in "[{":
            dots = 0
            # A table header ([a] or [[a]] at the start of a line) is not nesting.
            if not (at_line_start and c == "["):
                depth += 1
                if depth > MAX_NESTING:
                    return line, f"arrays or tables nested more than {MAX_NESTING} deep"
        elif c in "]}":
            dots = 0
            depth = max(0, depth - 1)
        if c not in " \t":
            at_line_start = False
        i += 1
    return None


def _longest_number(text: str) -> tuple[Optional[int], int]:
    """(line, digits) of the longest run of digits in the text."""
    best_line, best = None, 0
    for n, raw in enumerate(text.splitlines(), start=1):
        run = 0
        for c in raw:
            if c.isdigit() or c == "_":
                run += 1
                if run > best:
                    best, best_line = run, n
            else:
                run = 0
    return best_line, best


class Bench:
    """Buses, lines and named axes opened from a bench description (see the module doc)."""

    def __init__(self, data: Mapping[str, Any], *, sim: bool = False, source: str = "<dict>",
                 text: Optional[str] = None, clock: Any = None) -> None:
        self._checker = _Checker(data, source, text)
        self.source = source
        self.simulated = sim
        self._bus_cfg, self._line_cfg, self.config = self._checker.check()
        self.buses: dict[str, Any] = {}
        self.lines: dict[str, Any] = {}
        self.sims: dict[str, Any] = {}          # axis name -> its simulator (sim=True)
        self._servers: list[Any] = []           # what serves the simulated transports
        # sim=True: the pty server of each simulated line and the BusServers of each
        # simulated bus, by name (fault injection cuts a line or spoils frames there)
        self.served_lines: dict[str, Any] = {}
        self.served_buses: dict[str, Any] = {}
        self._axes: dict[str, Drive] = {}
        self._closed = False
        try:
            if sim:
                self._serve_simulators(clock)
            self._open_links()
            for name, cfg in self.config.items():
                self._axes[name] = self._open_axis(cfg)
        except BaseException:
            self.close()
            raise

    # ---- construction ----------------------------------------------------------------------
    @classmethod
    def load(cls, path: "str | os.PathLike[str]", *, sim: bool = False, clock: Any = None) -> "Bench":
        """Reads a TOML bench file (a regular file of at most :data:`MAX_FILE_BYTES`)
        and opens everything in it."""
        source = os.fspath(path)
        text, data = parse_file(source)
        return cls(data, sim=sim, source=source, text=text, clock=clock)

    @classmethod
    def from_dict(cls, data: Mapping[str, Any], *, sim: bool = False, clock: Any = None) -> "Bench":
        """The same from an already-parsed description (``{"axis": {"x": {...}}, ...}``)."""
        return cls(data, sim=sim, source="<dict>", clock=clock)

    @classmethod
    def connect(cls, address: Any, *, timeout: float = 5.0) -> Any:
        """The bench a running ``motorbus serve`` owns, from this program: a
        ``motorbus.serve.client.RemoteBench`` whose axes are Drives that talk to the service
        (``address``: the bench file, a socket path or ``"unix:/path.sock"``; docs/serve-protocol.md)."""
        from .serve.client import connect

        return connect(address, timeout=timeout)

    def _fail(self, message: str, *path: str) -> BenchFileError:
        return self._checker.fail(message, *path)

    def _where(self, *path: str) -> str:
        line = self._checker.where.line(*path)
        return self.source if line is None else f"{self.source}:{line}"

    def _serve_simulators(self, clock: Any) -> None:
        """Replaces every line by a pty and every bus by a served virtual bus,
        with each axis's simulator behind it; the links then open those."""
        from .bus_server import BusServers

        for line_name, cfg in self._line_cfg.items():
            axes = [a for a in self.config.values() if a.line == line_name]
            if not axes:
                continue
            devices = []
            for a in axes:
                devices.append(self._make_sim(a, clock))
                self.sims[a.name] = devices[-1]
            server = _core.serial.PtyLineServer(devices=devices, baud=0)
            self._servers.append(server)
            self.served_lines[line_name] = server
            cfg["port"] = server.slave_path
        for bus_name, cfg in self._bus_cfg.items():
            axes = [a for a in self.config.values() if a.bus == bus_name]
            served = BusServers(f"virtual:bench-sim-{os.getpid()}-{next(_sim_names)}",
                                socketcand=["127.0.0.1:0"], channel="can0")
            self._servers.append(served)
            self.served_buses[bus_name] = served
            for a in axes:
                sim = self._make_sim(a, clock, attach=served.endpoint)
                self._servers.insert(0, sim)   # closed before the bus they sit on
                self.sims[a.name] = sim
            srv = served.servers[0]
            cfg["spec"] = f"socketcand:{srv.host}:{srv.port}/can0"

    def _make_sim(self, a: AxisConfig, clock: Any, attach: Any = None) -> Any:
        """The axis's simulator from its ``sim`` table (attached to ``attach()`` for a CAN
        kind); a wrong option is a BenchFileError naming that option (the simulators'
        constructors, and a CAN simulator's services built when it attaches, say only
        "incompatible arguments")."""
        from .sim import make_sim

        if "store_path" in a.sim:
            self._check_store_path(a, a.sim["store_path"])
        untyped = (TypeError, ValueError, OverflowError)
        sim = None
        try:
            sim = make_sim(a.kind, a.address, clock=clock, **a.sim)
            if attach is not None:
                sim.attach(attach())
            return sim
        except _core.InvalidArgument as e:
            if sim is not None:
                _close_quietly(sim)
            raise self._fail(str(e), "axis", a.name, "sim") from None
        except untyped as e:
            if sim is not None:
                _close_quietly(sim)
            error = e
        for key, value in a.sim.items():   # which option: each alone, until one fails the same way
            probe, scratch = None, None
            try:
                probe = make_sim(a.kind, a.address, clock=clock, **{key: value})
                if attach is not None:
                    scratch = open_bus(f"virtual:bench-probe-{os.getpid()}-{next(_sim_names)}")
                    probe.attach(scratch)
            except (_core.InvalidArgument, *untyped) as e:
                why = _first_line(e)
                why = "" if "incompatible" in why else f": {why}"   # pybind's overload list says nothing more
                raise self._fail(f"{a.kind} simulator: wrong value {value!r} for {key} ({type(value).__name__}){why}",
                                 "axis", a.name, "sim", key) from None
            finally:
                if probe is not None:
                    _close_quietly(probe)
                if scratch is not None:
                    _close_quietly(scratch)
        raise self._fail(f"{a.kind} simulator refuses these options together: {_first_line(error)}",
                         "axis", a.name, "sim")

    def _check_store_path(self, a: AxisConfig, path: Any) -> None:
        """A simulator writes its stored settings to ``store_path`` (replacing the file):
        only a path that is free, or holds a store file a motorbus simulator wrote, is
        taken — not a file of the user's that the bench file happens to name."""
        where = ("axis", a.name, "sim", "store_path")
        if not isinstance(path, str) or not path.strip():
            raise self._fail(f"expected a file path, not {path!r}", *where)
        try:
            st = os.stat(path)
        except FileNotFoundError:
            return
        except OSError as e:
            raise self._fail(f"{path}: {e.strerror}", *where) from None
        verdict = _store_file_verdict(path, st)
        if verdict:
            raise self._fail(f"{path} {verdict}: a simulator would overwrite it (name a new file, or "
                             f"remove this one)", *where)

    def _open_links(self) -> None:
        for name, cfg in self._bus_cfg.items():
            try:
                self.buses[name] = open_bus(cfg["spec"])
            except _core.InvalidArgument as e:
                raise self._fail(str(e), "bus", name, "spec") from None
            except (TypeError, ValueError, OverflowError) as e:   # a value the scheme's parser let through
                raise self._fail(f"bus spec {cfg['spec']!r}: {str(e).splitlines()[0]}", "bus", name, "spec") from None
            except _core.MotorbusError as e:
                # The file may be right and the bus away (refused, unplugged): not a BenchFileError,
                # the same error, saying which bus of which file.
                raise _with_context(e, f"{self._where('bus', name, 'spec')}: bus {name!r}") from e
        for name, cfg in self._line_cfg.items():
            axes = [a for a in self.config.values() if a.line == name]
            if not axes:
                continue  # a described but unused line is not opened (it may not exist here)
            plugin = registry.drive_plugin(axes[0].kind)
            baud = cfg.get("baud", plugin.default_baud)
            try:
                port = _core.serial.open_port(cfg["port"], baud)
            except _core.InvalidArgument as e:
                raise self._fail(str(e), "line", name, "port") from None
            except (TypeError, ValueError, OverflowError) as e:
                raise self._fail(f"{str(e).splitlines()[0]}", "line", name) from None
            except _core.MotorbusError as e:
                raise _with_context(e, f"{self._where('line', name, 'port')}: line {name!r}") from e
            settings = dict(plugin.line_settings or {})
            self.lines[name] = _core.serial.LineLink(port, reply_timeout=cfg["timeout"], turnaround=cfg["turnaround"],
                                                     **settings)

    def _open_axis(self, cfg: AxisConfig) -> Drive:
        plugin = registry.drive_plugin(cfg.kind)
        where = {"line": self.lines[cfg.line]} if cfg.line else {"bus": self.buses[cfg.bus]}
        try:
            drive = plugin.open(address=cfg.address, units=cfg.units, line=where.get("line"),
                                bus=where.get("bus"), **cfg.options)
        except TypeError as e:  # an option the plugin does not take
            raise self._fail(f"{cfg.kind} does not take this option set: {e}", "axis", cfg.name, "options") from None
        except _core.InvalidArgument as e:
            raise self._fail(str(e), "axis", cfg.name, "options") from None
        drive.name = cfg.name      # errors (MoveFailed...) name the bench's axis
        for pname in cfg.params:
            if pname not in drive.params:
                drive.close()
                known = ", ".join(sorted(drive.params))
                raise self._fail(f"{cfg.kind} has no parameter {pname!r} (it has: {known})",
                                 "axis", cfg.name, "params", pname)
        return drive

    # ---- use -----------------------------------------------------------------------------------
    @property
    def axes(self) -> dict[str, Drive]:
        """``{name: Drive}`` in file order."""
        return dict(self._axes)

    def __getitem__(self, name: str) -> Drive:
        try:
            return self._axes[name]
        except KeyError:
            raise _core.InvalidArgument(f"bench {self.source}: no axis {name!r} "
                                        f"(axes: {', '.join(self._axes)})") from None

    def __iter__(self) -> Iterator[str]:
        return iter(self._axes)

    def __len__(self) -> int:
        return len(self._axes)

    def select(self, names: Optional[Sequence[str]] = None) -> dict[str, Drive]:
        """The named axes (all when ``names`` is empty), each name checked."""
        return {n: self[n] for n in names} if names else self.axes

    def move_together(self, targets: Mapping[str, float], *, relative: bool = False,
                      velocity: Optional[float] = None, wait: bool = True,
                      timeout: Optional[float] = None) -> StartReport:
        """Starts moves on several axes together and reports how closely.

        Axes of one kind sharing a line or bus whose Drive class offers a drive-level
        synchronised start (``Drive.synchronised_start``, e.g. a broadcast trigger)
        start on the drives' own trigger: their offsets are 0 by construction (one
        broadcast).  The others get a software start: commands back to back, each
        axis starting when its own command arrives; their offsets are measured
        (seconds from the first command accepted to this axis's).  A group started
        by its drives counts as one command in that sequence."""
        return faces.run(self._co_move_together(targets, relative=relative, velocity=velocity, wait=wait,
                                                timeout=timeout))

    async def _co_move_together(self, targets: Mapping[str, float], *, relative: bool = False,
                                velocity: Optional[float] = None, wait: bool = True,
                                timeout: Optional[float] = None) -> StartReport:
        """The logic of ``move_together``, run blocking there and awaited by motorbus.aio."""
        drives = {name: self[name] for name in targets}
        if not drives:
            raise _core.InvalidArgument("move_together: no axis given")
        groups: dict[tuple, list[str]] = {}
        for name in drives:
            cfg = self.config[name]
            groups.setdefault((cfg.kind, cfg.line, cfg.bus), []).append(name)
        offsets: dict[str, float] = {}
        methods: list[str] = []
        t0: Optional[float] = None

        async def command(name: str) -> None:
            d = drives[name]
            await (d._co_move_by if relative else d._co_move_to)(targets[name], velocity=velocity, wait=False)

        for (kind, line, bus), names in groups.items():
            cls = registry.drive_plugin(kind)
            if cls.provides("synchronised_start") and len(names) > 1:
                link = self.lines[line] if line else self.buses[bus]
                # The kind's trigger is a short blocking exchange (a broadcast) on entry and exit.
                with cls.synchronised_start(link, [drives[n] for n in names]) as how:
                    for n in names:
                        await command(n)
                now = time.perf_counter()
                t0 = now if t0 is None else t0
                offsets.update({n: now - t0 for n in names})
                methods.append(how)
                continue
            for n in names:
                await command(n)
                now = time.perf_counter()
                t0 = now if t0 is None else t0
                offsets[n] = now - t0
            methods.append("software")
        if wait:
            await self._co_wait_all(drives, timeout)
        method = methods[0] if len(set(methods)) == 1 else " + ".join(dict.fromkeys(methods))
        return StartReport(method, offsets, max(offsets.values()))

    @staticmethod
    async def _co_wait_all(drives: Mapping[str, Drive], timeout: Optional[float]) -> None:
        """Waits for every axis, even after one failed (each outcome is judged and kept in
        its ``status.last_move``); then raises the first axis's :class:`MoveFailed`, with
        ``failures`` = every failed axis's error by name."""
        failures: dict[str, MoveFailed] = {}
        for name, d in drives.items():
            try:
                await d._co_wait_idle(timeout)
            except MoveFailed as e:
                failures[name] = e
        if failures:
            first = next(iter(failures.values()))
            first.failures = failures
            if len(failures) > 1:
                first.add_note("also: " + "; ".join(str(e) for e in list(failures.values())[1:]))
            raise first

    def status(self) -> dict[str, DriveStatus]:
        return {name: d.status for name, d in self._axes.items()}

    def stop_all(self, how: str = "stop") -> list[tuple[str, BaseException]]:
        """Stops every axis (``how``: "stop", "quick_stop" or "disable"); an axis that
        fails does not keep the others from stopping.  Returns the failures."""
        # Checked before the getattr: any other word would call whatever method it names.
        check_stop_way(how, "Bench.stop_all how", tuple(w for w in STOP_WAYS if w is not None))
        return faces.run(self._co_stop_all(how))

    async def _co_stop_all(self, how: str) -> list[tuple[str, BaseException]]:
        failures = []
        for name, d in self._axes.items():
            if d.closed:
                continue
            try:
                await getattr(d, f"_co_{how}")()
            except Exception as e:  # noqa: BLE001 - the others must still stop
                failures.append((name, e))
        return failures

    # ---- configuration ---------------------------------------------------------------------
    def read_params(self, names: Optional[Sequence[str]] = None, *, all_params: bool = False) -> dict[str, dict]:
        """``{axis: {param: value}}`` read from the drives: the file's parameters,
        or every parameter the drive has with ``all_params``."""
        return faces.run(self._co_read_params(names, all_params=all_params))

    async def _co_read_params(self, names: Optional[Sequence[str]] = None, *,
                              all_params: bool = False) -> dict[str, dict]:
        out = {}
        for axis, d in self.select(names).items():
            wanted = list(d.params) if all_params else list(self.config[axis].params)
            out[axis] = {p: await d.params._co_get(p) for p in wanted}
        return out

    def diff(self, names: Optional[Sequence[str]] = None) -> list[ParamDiff]:
        """The file's parameters whose drive value differs."""
        return faces.run(self._co_diff(names))

    async def _co_diff(self, names: Optional[Sequence[str]] = None) -> list[ParamDiff]:
        out = []
        for axis, d in self.select(names).items():
            for p, want in self.config[axis].params.items():
                have = await d.params._co_get(p)
                if not _same(have, want):
                    out.append(ParamDiff(axis, p, want, have))
        return out

    def apply(self, names: Optional[Sequence[str]] = None) -> list[ParamDiff]:
        """Writes the file's parameters that differ; returns what it changed."""
        return faces.run(self._co_apply(names))

    async def _co_apply(self, names: Optional[Sequence[str]] = None) -> list[ParamDiff]:
        changed = await self._co_diff(names)
        for c in changed:
            try:
                await self[c.axis].params._co_set(c.name, c.file_value)
            except _core.InvalidArgument as e:
                raise self._fail(str(e), "axis", c.axis, "params", c.name) from None
        return changed

    def store(self, names: Optional[Sequence[str]] = None) -> None:
        """Persists the parameters on each drive (its own STORE/save)."""
        faces.run(self._co_store(names))

    async def _co_store(self, names: Optional[Sequence[str]] = None) -> None:
        for d in self.select(names).values():
            await d._co_store()

    # ---- lifetime --------------------------------------------------------------------------
    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        for d in self._axes.values():
            try:
                d.close()
            except Exception:  # noqa: BLE001 - close the rest
                pass
        # A LineLink has no close of its own: its port holds the line (and its lock).
        for link in [ln.port for ln in self.lines.values()] + list(self.buses.values()):
            try:
                link.close()
            except Exception:  # noqa: BLE001
                pass
        for s in self._servers:
            try:
                s.close()
            except Exception:  # noqa: BLE001
                pass
        self._servers = []
        self.served_lines, self.served_buses = {}, {}

    @property
    def closed(self) -> bool:
        return self._closed

    def __enter__(self) -> "Bench":
        return self

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        # Every axis stops on the way out, exception or not: a bench script that
        # ends mid-move must not leave a motor running.
        try:
            self.stop_all("quick_stop" if exc_type is not None else "stop")
        finally:
            self.close()

    def __repr__(self) -> str:
        sim = " simulated" if self.simulated else ""
        return f"<Bench {self.source}{sim}: {', '.join(self._axes)}>"


def _with_context(e: BaseException, where: str) -> BaseException:
    """The same kind of motorbus error, its message prefixed with where it comes from."""
    try:
        return type(e)(f"{where}: {e}")
    except Exception:  # noqa: BLE001 - a type whose constructor takes other arguments: keep it as is
        return e


def _first_line(e: BaseException) -> str:
    text = str(e)
    return _clip(text.splitlines()[0], 160) if text else type(e).__name__


def _close_quietly(sim: Any) -> None:
    try:
        sim.close()
    except Exception:  # noqa: BLE001 - a probe that was never attached
        pass


#: The largest store file a simulator writes (a few hundred lines at most).
_MAX_STORE_BYTES = 1 << 20


def _store_file_verdict(path: str, st: os.stat_result) -> str:
    """"" when ``path`` is a store file written by a motorbus simulator (or empty), else
    what it is.  The formats the in-tree simulators write: lines ``NAME=INTEGER`` (a
    flash), lines ``rom IIII SS HEX`` / ``program ...`` / ``position N`` (a CANopen
    object store), a JSON object of register -> integer (an EEPROM)."""
    if not stat.S_ISREG(st.st_mode):
        return f"is not a regular file (a {_file_type(st.st_mode)})"
    if st.st_size > _MAX_STORE_BYTES:
        return f"is {st.st_size} bytes, larger than any store file"
    try:
        with open(path, "rb") as f:
            text = f.read(_MAX_STORE_BYTES + 1).decode("utf-8")
    except UnicodeDecodeError:
        return "is not text"
    except OSError as e:
        return f"cannot be read ({e.strerror})"
    if not text.strip():
        return ""
    if text.lstrip().startswith("{"):
        import json

        try:
            doc = json.loads(text)
        except (ValueError, RecursionError):
            return "is not a store file written by motorbus (JSON that does not parse)"
        if isinstance(doc, dict) and all(isinstance(v, int) and not isinstance(v, bool) for v in doc.values()):
            return ""
        return "is not a store file written by motorbus (a JSON object of register -> integer)"
    for line in text.splitlines():
        line = line.strip()
        if not line:
            continue
        name, eq, value = line.partition("=")
        if eq and name and all(c.isalnum() or c == "_" for c in name) and _is_int(value):
            continue
        words = line.split()
        if words[0] == "rom" and len(words) == 4 and all(_is_hex(w) for w in words[1:]):
            continue
        if words[0] == "program" and all(w.isdigit() for w in words[1:]):
            continue
        if words[0] == "position" and len(words) == 2 and _is_int(words[1]):
            continue
        return f"is not a store file written by motorbus (line {_clip(line, 60)!r})"
    return ""


def _is_int(text: str) -> bool:
    text = text.strip()
    return text[1:].isdigit() if text[:1] in "+-" else text.isdigit()


def _is_hex(text: str) -> bool:
    return bool(text) and all(c in "0123456789abcdefABCDEF" for c in text)


def _same(a: Any, b: Any) -> bool:
    if isinstance(a, float) or isinstance(b, float):
        try:
            return math.isclose(float(a), float(b), rel_tol=1e-9, abs_tol=1e-12)
        except (TypeError, ValueError):
            return False
    return a == b
