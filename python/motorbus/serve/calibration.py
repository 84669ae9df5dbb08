"""The CA face's calibration, kept next to the bench file (``<bench>.epics.json``).

A motor record's user coordinates are its own: ``VAL = DVAL * DIR + OFF`` with the
soft limits, speeds and the freeze switch set by whoever operates it (an IOC keeps
them with autosave).  ``motorbus serve`` keeps them in one small JSON file per bench,
written on every change (a temporary file renamed over the old one: a crash leaves the
old file or the new one, never half of either) and read when the service starts.

The file::

    {"version": 1,
     "axes": {"x": {"off": 1.5, "dir": 1, "foff": 0, "dhlm": 50.0, "dllm": -50.0,
                    "velo": 10.0, "accl": 0.2, "jvel": 5.0, "twv": 1.0}}}

Positions and limits are in the axis's user units (the bench file's ``units``) as the
drive reads them (the record's *dial* coordinates); an axis the bench no longer has is
kept in the file untouched.  A file that cannot be read is a ``CalibrationError``
naming the file and what is wrong with it: the service refuses to start rather than
serve a bench whose offsets were silently lost.
"""
from __future__ import annotations

import json
import math
import os
import tempfile
from typing import Any, Optional

from .. import _core

__all__ = ["CalibrationError", "KEYS", "load", "save", "CalibrationStore"]

VERSION = 1
#: What is kept per axis, and the checks a value read back must pass.
KEYS = {
    "off": "a finite number (OFF, user units)",
    "dir": "1 or -1 (DIR Pos / Neg)",
    "foff": "0 or 1 (FOFF Variable / Frozen)",
    "dhlm": "a finite number (DHLM, dial units)",
    "dllm": "a finite number (DLLM, dial units)",
    "velo": "a finite number > 0 (VELO, units/s)",
    "accl": "a finite number > 0 (ACCL, s)",
    "jvel": "a finite number > 0 (JVEL, units/s)",
    "twv": "a finite number (TWV, user units)",
}
#: A calibration file is a few hundred bytes per axis: anything far larger is not one.
MAX_BYTES = 4 * 1024 * 1024


class CalibrationError(_core.InvalidArgument):
    """A calibration file that cannot be used: ``<path>: <what is wrong>``."""


def _check(path: str, axis: str, key: str, value: Any) -> Any:
    ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
    if ok and key == "dir":
        ok = value in (1, -1)
    elif ok and key == "foff":
        ok = value in (0, 1)
    elif ok and key in ("velo", "accl", "jvel"):
        ok = value > 0
    if not ok:
        raise CalibrationError(f"{path}: axes.{axis}.{key}: {KEYS[key]}, not {value!r}")
    return int(value) if key in ("dir", "foff") else float(value)


def load(path: Optional[str]) -> dict[str, dict[str, Any]]:
    """``{axis: {key: value}}`` from ``path``; ``{}`` when there is no path or no file yet."""
    if not path:
        return {}
    try:
        with open(path, "rb") as f:
            raw = f.read(MAX_BYTES + 1)
    except FileNotFoundError:
        return {}
    except OSError as e:
        raise CalibrationError(f"{path}: cannot be read: {e.strerror or e}") from None
    if len(raw) > MAX_BYTES:
        raise CalibrationError(f"{path}: larger than {MAX_BYTES} bytes: not a calibration file")
    try:
        data = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, ValueError) as e:
        raise CalibrationError(f"{path}: not JSON: {e}") from None
    if not isinstance(data, dict) or data.get("version") != VERSION or not isinstance(data.get("axes"), dict):
        raise CalibrationError(f"{path}: expected {{\"version\": {VERSION}, \"axes\": {{...}}}}")
    out: dict[str, dict[str, Any]] = {}
    for axis, entry in data["axes"].items():
        if not isinstance(entry, dict):
            raise CalibrationError(f"{path}: axes.{axis}: a table of {', '.join(KEYS)}, not {entry!r}")
        out[axis] = {}
        for key, value in entry.items():
            if key not in KEYS:
                raise CalibrationError(f"{path}: axes.{axis}.{key}: unknown key (known: {', '.join(KEYS)})")
            out[axis][key] = _check(path, axis, key, value)
    return out


def save(path: str, axes: dict[str, dict[str, Any]]) -> None:
    """Writes ``axes`` to ``path`` atomically (a temporary file in the same folder, flushed
    to disk, renamed over ``path``)."""
    folder = os.path.dirname(os.path.abspath(path))
    text = json.dumps({"version": VERSION, "axes": axes}, indent=1, sort_keys=True) + "\n"
    fd, tmp = tempfile.mkstemp(prefix=".epics-", suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


class CalibrationStore:
    """The file's contents in memory: ``get(axis)`` at start, ``update(axis, **values)`` on
    every change (written at once when there is a path; without one nothing persists)."""

    def __init__(self, path: Optional[str]) -> None:
        self.path = path
        self.axes = load(path)
        self.writes = 0

    def get(self, axis: str) -> dict[str, Any]:
        return dict(self.axes.get(axis, {}))

    def update(self, axis: str, **values: Any) -> None:
        entry = self.axes.setdefault(axis, {})
        changed = False
        for key, value in values.items():
            value = _check(self.path or "<calibration>", axis, key, value)
            if entry.get(key) != value:
                entry[key] = value
                changed = True
        if changed and self.path:
            save(self.path, self.axes)
            self.writes += 1
