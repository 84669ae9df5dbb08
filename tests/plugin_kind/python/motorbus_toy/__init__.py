"""motorbus_toy: a drive kind written outside motorbus, as another package would.

What it takes (docs/plugins.md): one C++ folder (``tests/plugin_kind/cpp/toy/``: the
simulator, a ``serial::LineDevice`` on a ``motion::MotorModel``, and the client over a
``LineLink``), one bindings file (``tests/plugin_kind/bindings/toy.cpp``, compiled in
through ``MOTORBUS_EXTRA_VENDOR_DIRS``) and this module, whose :class:`ToyDrive` is
the plugin: the entry point in ``motorbus_toy-0.1.dist-info/entry_points.txt`` names
it.  Nothing in motorbus names the kind.

The protocol (ASCII, CR / CR LF, ``@<address> <command>``) is described in
``cpp/toy/toy.hpp``; native units are steps.
"""
from __future__ import annotations

import os
from typing import Any, Optional

from motorbus import _core
from motorbus.drive import (Capability, Drive, DriveStatus, MoveFaulted, MoveInterrupted, ParamInfo, Params,
                            StopReason, Units)

__all__ = ["ToyDrive", "LINE_SETTINGS"]

LINE_SETTINGS = {"request_terminator": b"\r", "reply_terminators": [b"\r\n"], "max_line": 64}

#: The drive's settings (``<NAME>?`` / ``<NAME> <value>``): type, range, unit, writable.
_SETTINGS = {
    "SPEED": ParamInfo("SPEED", "int", 1, 100000, "steps/s", 4000, description="speed of a MOVE"),
    "ACCEL": ParamInfo("ACCEL", "int", 1, 10_000_000, "steps/s^2", 40000, description="every ramp"),
    "WINDOW": ParamInfo("WINDOW", "int", 0, 1000, "steps", 0,
                        description="how far from its target a move may end and count as arrived"),
    "ADDR": ParamInfo("ADDR", "int", 1, 9, "", None, writable=False, description="the drive's address"),
}

#: How a motion ended, as STATUS? says it, and the error a move that ended so raises.
_STOPS = {"STOP": "a STOP on the line (another program, or a stop input)",
          "ABORT": "an ABORT on the line (another program)",
          "DISABLE": "a DISABLE on the line (another program)"}


class ToyParams(Params):
    def _names(self) -> list:
        return list(_SETTINGS)

    def _info(self, name: str) -> Optional[ParamInfo]:
        return _SETTINGS.get(name.upper())

    async def _read(self, info: ParamInfo) -> Any:
        return int(await self._drive.io.get(info.name))

    async def _write(self, info: ParamInfo, value: Any) -> None:
        if value != int(value):
            raise _core.InvalidArgument(f"toy: {info.name} takes an integer, not {value!r}")
        await self._drive.io.set(info.name, int(value))


class ToyDrive(Drive):
    """A toy stepper behind :class:`motorbus.Drive` (native unit: the step).

    ``stop()``: STOP (a ramp at ACCEL); ``quick_stop()``: ABORT.  ``velocity=`` of a
    move sets SPEED for that move only.  ``home()``: HOME, the counter set to 0 where
    the axis stands.  A move has arrived at rest within WINDOW steps of its target
    (half a step at least: the counter is whole); a STOP, ABORT or DISABLE from
    another program ends it in ``MoveInterrupted``, the fault input in ``MoveFaulted``.
    No watchdog."""

    kind = "toy"
    capabilities = frozenset({Capability.POSITION, Capability.VELOCITY, Capability.HOMING})
    has_watchdog = False

    # ---- the plugin: what the kind is ------------------------------------------------------
    description = "the out-of-tree test kind: an ASCII serial stepper (MOVE n, POS?, STOP, STATUS?)"
    transport = "serial"
    default_address = "1"
    line_settings = LINE_SETTINGS
    default_baud = 9600
    sim_options = ("speed", "accel", "start_position")
    probe_addresses = tuple("123456789")
    probe_bauds = (9600,)

    # ---- the plugin's hooks ------------------------------------------------------------------
    @classmethod
    def open(cls, *, line: Any, bus: Any = None, address: str = "1", units: Optional[Units] = None,
             timeout: float = 0.5, on_error: Optional[str] = "stop", on_exit: Optional[str] = "stop") -> "ToyDrive":
        """``line``: a port path (opened here, closed with the drive) or a shared LineLink."""
        if bus is not None:
            raise _core.InvalidArgument("toy: a serial drive takes line=, not bus=")
        port = None
        if isinstance(line, (str, os.PathLike)):
            port = _core.serial.open_port(os.fspath(line), cls.default_baud)
            line = _core.serial.LineLink(port, reply_timeout=timeout, **LINE_SETTINGS)
        elif not isinstance(line, _core.serial.LineLink):
            raise _core.InvalidArgument(f"toy: line= a port path or a LineLink, not {type(line).__name__}")
        try:
            return cls(_core.toy.Client(line, int(cls.check_address(address))), units=units, on_error=on_error,
                       on_exit=on_exit, close_native=None if port is None else port.close)
        except BaseException:
            if port is not None:
                port.close()
            raise

    @classmethod
    def make_sim(cls, address: Any = "1", clock: Any = None, **options: Any) -> Any:
        unknown = set(options) - set(cls.sim_options)
        if unknown:
            raise _core.InvalidArgument(f"toy sim options: unknown {sorted(unknown)}; known {list(cls.sim_options)}")
        return _core.toy.Sim(clock, int(cls.check_address(address)), **options)

    @classmethod
    def check_address(cls, text: Any) -> str:
        if isinstance(text, int) and not isinstance(text, bool):
            text = str(text)
        if not isinstance(text, str) or text.strip() not in ("1", "2", "3", "4", "5", "6", "7", "8", "9"):
            raise _core.InvalidArgument(f"toy address: a digit 1..9, not {text!r}")
        return text.strip()

    @classmethod
    def probe(cls, link: Any, address: str) -> Optional[dict]:
        """Discovery: STATUS? and ADDR? of the drive at ``address`` (reads only)."""
        client = _core.toy.Client(link, int(address))
        client.status()
        return {"model": "toy stepper", "address": str(int(client.get("ADDR")))}

    @classmethod
    def sim_faults(cls) -> dict:
        return {
            # the fault input (an overtemperature): the motor stops, the stage switches off, FAULT latches
            "fault": lambda sim, active=True: sim.set_fault_input(bool(active)),
            # a STOP arrives as from another program on the line: the motor ramps down
            "stop_input": lambda sim: sim.on_line(f"@{sim.address} STOP".encode()),
        }

    # ---- the Drive's hooks, native units (steps) -----------------------------------------------
    # Coroutines over self.io (motorbus.faces): the same code serves drive.move_to(...) and
    # `await aio_drive.move_to(...)`.
    def _io_link(self) -> Any:
        return self.native.link

    async def _enable(self) -> None:
        await self.io.enable()

    async def _disable(self) -> None:
        await self.io.disable()

    async def _move_to(self, target: float, velocity: Optional[float]) -> None:
        if velocity is not None:
            await self._for_this_move(lambda: self.io.get("SPEED"), lambda v: self.io.set("SPEED", v),
                                      max(1, min(100000, round(velocity))))
        await self.io.move_to(round(target))

    async def _jog(self, velocity: float) -> None:
        await self.io.jog(velocity)

    async def _stop(self) -> None:
        await self.io.urgent.stop()

    async def _quick_stop(self) -> None:
        await self.io.urgent.abort()

    async def _home(self, method: Any) -> None:
        if method not in (None, "here"):
            raise _core.InvalidArgument(f"toy: home method 'here' (the only one), not {method!r}")
        await self.io.home()

    async def _clear_faults(self) -> None:
        await self.io.clear()

    async def _position(self) -> float:
        return float(await self.io.position())

    async def _velocity(self) -> float:
        return await self.io.velocity()

    async def _status(self) -> DriveStatus:
        st = await self.io.status()
        state = "fault" if st.fault else "moving" if st.moving else "enabled" if st.enabled else "disabled"
        return DriveStatus(enabled=st.enabled, moving=st.moving, homed=st.homed, fault=st.fault,
                           at_target=not st.moving and st.last_stop.name in ("TARGET", "NONE") and not st.fault,
                           limit_positive=False, limit_negative=False, raw=st,
                           text=f"toy {self.native.address}: {state}, last motion ended by {st.last_stop.name}")

    async def _is_idle(self) -> bool:
        return not (await self.io.status()).moving

    def _stop_reason(self, status: DriveStatus) -> Optional[StopReason]:
        last = status.raw.last_stop.name
        if last == "FAULT" or status.fault:
            return StopReason(MoveFaulted, "the fault input (STATUS? FAULT)")
        move = self._move
        if last in _STOPS and not (move is not None and move.stopped_by is not None):
            return StopReason(MoveInterrupted, _STOPS[last])
        return None     # this program's stop(): Drive says so

    async def _in_position_window(self) -> float:
        return max(0.5, float(await self.io.get("WINDOW")))

    def _make_params(self) -> Params:
        return ToyParams(self)

    async def _console(self, line: str) -> str:
        return await self.io.command(line)
