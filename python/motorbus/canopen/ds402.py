"""CiA 402 on the host (Ds402) and on a simulated device (Ds402Device).

    from motorbus.canopen import Ds402, OpMode
    drive = Ds402(bus, node=5)                  # or an SDO client object
    drive.use_statusword_pdo(rx)                # optional: wait on TPDOs, not SDO polls
    drive.set_mode(OpMode.PROFILE_POSITION)
    drive.go_to("OPERATION ENABLED")            # walks 2, 3, 4 (fault reset first if needed)
    drive.move_to(10_000)                       # new set-point / acknowledge handshake
    drive.wait_target_reached(timeout=5.0)

A statusword outside the CiA 402 table decodes as "UNKNOWN" and is never taken
for "OPERATION ENABLED".
"""
from __future__ import annotations

import enum

from .. import _core

__all__ = ["Ds402", "Ds402Host", "Ds402Device", "OpMode", "STATES", "decode_statusword",
           "Controlword", "next_step"]

STATES = ("NOT READY TO SWITCH ON", "SWITCH ON DISABLED", "READY TO SWITCH ON", "SWITCHED ON",
          "OPERATION ENABLED", "QUICK STOP ACTIVE", "FAULT REACTION ACTIVE", "FAULT", "UNKNOWN")

decode_statusword = _core.ds402_decode_statusword
next_step = _core.ds402_next_step


class OpMode(enum.IntEnum):
    NONE = 0
    PROFILE_POSITION = 1
    VELOCITY = 2
    PROFILE_VELOCITY = 3
    PROFILE_TORQUE = 4
    HOMING = 6
    INTERPOLATED_POSITION = 7
    CYCLIC_SYNC_POSITION = 8
    CYCLIC_SYNC_VELOCITY = 9
    CYCLIC_SYNC_TORQUE = 10


class Controlword(enum.IntEnum):
    SHUTDOWN = 0x0006
    SWITCH_ON = 0x0007
    DISABLE_VOLTAGE = 0x0000
    QUICK_STOP = 0x0002
    DISABLE_OPERATION = 0x0007
    ENABLE_OPERATION = 0x000F
    FAULT_RESET = 0x0080


class Ds402(_core.Ds402Host):
    """Host-side CiA 402 state machine of one drive."""

    def set_mode(self, mode: int) -> None:  # accepts OpMode or int
        super().set_mode(int(mode))

    @property
    def op_mode(self) -> OpMode:
        return OpMode(self.mode)

    def enable(self) -> None:
        self.go_to("OPERATION ENABLED")

    def disable(self) -> None:
        self.go_to("SWITCH ON DISABLED")


Ds402Host = Ds402
Ds402Device = _core.Ds402Device
