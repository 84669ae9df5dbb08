"""NMT (CiA 301): the master that commands nodes and tracks their states.

    from motorbus.canopen import NmtMaster
    nmt = NmtMaster(bus)
    nmt.start(5)                        # or nmt.start() for every node
    nmt.wait_for_state(5, "OPERATIONAL", timeout=1.0)
    nmt.set_state(5, "PRE-OPERATIONAL") # the command by the state it leads to

Heartbeat supervision is in motorbus.canopen.heartbeat.

Awaitable waits (any loop, no thread; the bus's receive thread completes them
through the loop's completion queue):

    await nmt.wait_for_state_async(5, "OPERATIONAL", timeout=1.0)   # True / False
    await node.nmt.wait_for_bootup_async(10.0)      # motorbus.TimeoutError if none
    await node.nmt.wait_for_heartbeat_async(10.0)   # the state it reports

States are the strings INITIALISING, STOPPED, OPERATIONAL, PRE-OPERATIONAL and
UNKNOWN (nothing heard, or a byte outside that set: never treated as running).
"""
from __future__ import annotations

import asyncio
from typing import Callable, Optional

from .. import _core, faces

__all__ = ["NmtCommand", "NmtMaster", "NMT_STATES", "nmt_encode", "nmt_decode"]

NMT_STATES = ("INITIALISING", "STOPPED", "OPERATIONAL", "PRE-OPERATIONAL", "UNKNOWN")

from .._core.canopen import nmt_encode, nmt_decode, NmtCommand  # noqa: E402,F401

class _NmtEvent:
    """One awaited NMT event (C++ ``canopen::NmtEventWait``): subscribed on creation
    (before any state check, so nothing is missed in between), awaited with a timeout,
    unsubscribed after.  ``state``: a heartbeat in that state; ``boot_up``: a boot-up;
    neither: any heartbeat."""

    def __init__(self, bus: _core.can.Bus, node: int, state: Optional[str] = None, boot_up: bool = False) -> None:
        self.bridge = faces.bridge_for()
        self.token, self.future = self.bridge.expect()
        try:
            self.waiter = _core.canopen.nmt_wait_async(bus, node, state, boot_up, self.bridge.completions,
                                                        self.token)
        except BaseException:
            self.bridge.forget(self.token)
            raise

    async def state(self, timeout: Optional[float]) -> Optional[str]:
        """The state the event reported; None after ``timeout`` s (None = no limit)."""
        try:
            return await asyncio.wait_for(self.future, timeout)
        except asyncio.TimeoutError:
            return None
        finally:
            self.close()

    def close(self) -> None:
        self.waiter.cancel()
        self.bridge.forget(self.token)


class NmtMaster:
    """Commands nodes (node 0 = all) and tracks their states from heartbeats."""

    def __init__(self, bus: _core.can.Bus, own_node_id: Optional[int] = None) -> None:
        self._m = _core.canopen.NmtMaster(bus, own_node_id)
        self.bus = bus
        self._cb: Optional[Callable[[int, str, str], None]] = None

    def send(self, command: "NmtCommand | int", node: int = 0) -> None:
        self._m.send(command, node)

    def start(self, node: int = 0) -> None:
        self.send(NmtCommand.START, node)

    def stop(self, node: int = 0) -> None:
        self.send(NmtCommand.STOP, node)

    def enter_pre_operational(self, node: int = 0) -> None:
        self.send(NmtCommand.ENTER_PRE_OPERATIONAL, node)

    pre_operational = enter_pre_operational

    def reset_node(self, node: int = 0) -> None:
        self.send(NmtCommand.RESET_NODE, node)

    def reset_communication(self, node: int = 0) -> None:
        self.send(NmtCommand.RESET_COMMUNICATION, node)

    def set_state(self, node: int, state: str) -> None:
        """The command that leads to ``state``: OPERATIONAL, PRE-OPERATIONAL,
        STOPPED, RESET (node) or RESET COMMUNICATION; node 0 = every node."""
        self._m.set_state(node, state)

    def state(self, node: int) -> str:
        return self._m.state(node)

    def raw_state(self, node: int) -> Optional[int]:
        return self._m.raw_state(node)

    def wait_for_state(self, node: int, state: str, timeout: float = 1.0) -> bool:
        return self._m.wait_for_state(node, state, timeout)

    def wait_for_boot(self, node: int, timeout: float = 1.0) -> bool:
        return self._m.wait_for_boot(node, timeout)

    def wait_for_heartbeat(self, node: int, timeout: float = 1.0) -> Optional[str]:
        """State reported by the next heartbeat or boot-up of ``node``; None on timeout."""
        return self._m.wait_for_heartbeat(node, timeout)

    # ---- awaitable waits: the same answers without blocking the loop ----
    async def wait_for_state_async(self, node: int, state: str, timeout: float = 1.0) -> bool:
        """Awaitable :meth:`wait_for_state`: True once ``node`` reports ``state`` (at
        once if it last did), False after ``timeout``."""
        event = _NmtEvent(self.bus, node, state=state)
        if self._m.wait_for_state(node, state, 0):      # the last state heard is it: no wait
            event.close()
            return True
        return await event.state(timeout) is not None

    async def wait_for_boot_async(self, node: int, timeout: float = 1.0) -> bool:
        """Awaitable :meth:`wait_for_boot`: True when the node's next boot-up comes."""
        return await _NmtEvent(self.bus, node, boot_up=True).state(timeout) is not None

    async def wait_for_heartbeat_async(self, node: int, timeout: float = 1.0) -> Optional[str]:
        """Awaitable :meth:`wait_for_heartbeat`: the state of the next heartbeat or boot-up; None on timeout."""
        return await _NmtEvent(self.bus, node).state(timeout)

    @property
    def on_state_change(self) -> Optional[Callable[[int, str, str], None]]:
        """callback(node, old_state, new_state), called on the bus thread."""
        return self._cb

    @on_state_change.setter
    def on_state_change(self, cb: Optional[Callable[[int, str, str], None]]) -> None:
        self._cb = cb
        self._m.set_callback(cb)

    @property
    def foreign_commands_ignored(self) -> int:
        return self._m.foreign_commands_ignored


class NodeNmt:
    """``node.nmt``: NMT of one remote node, as the `canopen` package spells it.

    ``state`` reads the last state the node reported (heartbeat or boot-up;
    UNKNOWN until one is heard) and, assigned, sends the command leading to it
    (OPERATIONAL, PRE-OPERATIONAL, STOPPED, RESET, RESET COMMUNICATION)."""

    def __init__(self, master: NmtMaster, node_id: int) -> None:
        self._m = master
        self.node_id = node_id

    @property
    def state(self) -> str:
        return self._m.state(self.node_id)

    @state.setter
    def state(self, new_state: str) -> None:
        self._m.set_state(self.node_id, new_state)

    def send_command(self, command: int) -> None:
        self._m.send(command, self.node_id)

    #: ``node.nmt(0x01)``: a command by its code (0x01 start, 0x02 stop, 0x80 pre-op,
    #: 0x81 reset node, 0x82 reset communication), as send_command.
    __call__ = send_command

    def wait_for_bootup(self, timeout: float = 10.0) -> None:
        """Waits for the node's next boot-up message; motorbus.TimeoutError if none comes."""
        if not self._m.wait_for_boot(self.node_id, timeout):
            raise _core.TimeoutError(f"node {self.node_id}: no boot-up within {timeout} s")

    def wait_for_heartbeat(self, timeout: float = 10.0) -> str:
        """Waits for the node's next heartbeat; returns the state it reports.
        motorbus.TimeoutError if none comes."""
        state = self._m.wait_for_heartbeat(self.node_id, timeout)
        if state is None:
            raise _core.TimeoutError(f"node {self.node_id}: no heartbeat within {timeout} s")
        return state

    async def wait_for_bootup_async(self, timeout: float = 10.0) -> None:
        """Awaitable :meth:`wait_for_bootup` (motorbus.TimeoutError if none comes)."""
        if not await self._m.wait_for_boot_async(self.node_id, timeout):
            raise _core.TimeoutError(f"node {self.node_id}: no boot-up within {timeout} s")

    async def wait_for_heartbeat_async(self, timeout: float = 10.0) -> str:
        """Awaitable :meth:`wait_for_heartbeat` (motorbus.TimeoutError if none comes)."""
        state = await self._m.wait_for_heartbeat_async(self.node_id, timeout)
        if state is None:
            raise _core.TimeoutError(f"node {self.node_id}: no heartbeat within {timeout} s")
        return state

    async def wait_for_state_async(self, state: str, timeout: float = 10.0) -> None:
        """Waits until the node reports ``state`` (motorbus.TimeoutError if it does not)."""
        if not await self._m.wait_for_state_async(self.node_id, state, timeout):
            raise _core.TimeoutError(f"node {self.node_id}: not {state} within {timeout} s")
