"""A line-oriented SDO console for any CANopen node (``motorbus terminal`` on a CANopen axis).

    r INDEX[:SUB] [TYPE]          read:  r 0x6041   r 0x1018:1 u32   r 0x1008 str
    w INDEX[:SUB] VALUE [TYPE]    write: w 0x6040 0x0F u16   w 0x607A -1000 i32

TYPE: u8 u16 u32 u64 i8 i16 i32 i64 str hex (default: read shows the bytes in hex and,
up to 8 bytes, the little-endian unsigned value; write is u32).  An SDO abort comes
back as the error with its CiA 301 code and text."""
from __future__ import annotations

from typing import Any

from .. import _core

__all__ = ["sdo_console", "CONSOLE_HELP"]

CONSOLE_HELP = __doc__.split("\n\n")[1]

_INT_TYPES = {"u8": (1, False), "u16": (2, False), "u32": (4, False), "u64": (8, False),
              "i8": (1, True), "i16": (2, True), "i32": (4, True), "i64": (8, True)}


def _where(text: str) -> tuple[int, int]:
    index, _, sub = text.partition(":")
    try:
        i, s = int(index, 0), int(sub, 0) if sub else 0
    except ValueError:
        raise _core.InvalidArgument(f"console: {text!r} is not INDEX[:SUB] (e.g. 0x6041 or 0x1018:1)") from None
    if not (0 <= i <= 0xFFFF and 0 <= s <= 0xFF):
        raise _core.InvalidArgument(f"console: {text!r}: index 0-0xFFFF, subindex 0-0xFF")
    return i, s


def _type(text: str) -> str:
    if text not in _INT_TYPES and text not in ("str", "hex"):
        raise _core.InvalidArgument(f"console: type {text!r}: one of {' '.join(_INT_TYPES)} str hex")
    return text


def sdo_console(sdo: Any, line: str) -> str:
    """Runs one console line on ``sdo`` (a motorbus SdoClient); returns the answer as text."""
    words = line.split()
    if not words:
        return ""
    op = words[0].lower()
    if op in ("r", "read") and len(words) in (2, 3):
        index, sub = _where(words[1])
        data = sdo.upload(index, sub)
        kind = _type(words[2]) if len(words) == 3 else None
        if kind == "str":
            return data.decode("latin-1")
        if kind in _INT_TYPES:
            size, signed = _INT_TYPES[kind]
            return str(int.from_bytes(data[:size], "little", signed=signed))
        shown = data.hex(" ")
        if kind is None and 0 < len(data) <= 8:
            value = int.from_bytes(data, "little")
            shown += f"  = {value} (0x{value:X})"
        return shown
    if op in ("w", "write") and len(words) in (3, 4):
        index, sub = _where(words[1])
        kind = _type(words[3]) if len(words) == 4 else "u32"
        if kind == "str":
            data = words[2].encode("latin-1")
        elif kind == "hex":
            try:
                data = bytes.fromhex(words[2])
            except ValueError:
                raise _core.InvalidArgument(f"console: {words[2]!r} is not hex bytes") from None
        else:
            size, signed = _INT_TYPES[kind]
            try:
                data = int(words[2], 0).to_bytes(size, "little", signed=signed)
            except (ValueError, OverflowError):
                raise _core.InvalidArgument(f"console: {words[2]!r} does not fit {kind}") from None
        sdo.download(index, sub, data)
        return "OK"
    raise _core.InvalidArgument(f"console: {line!r}: {CONSOLE_HELP.strip()}")
