"""
motorbus C++ core: the errors at top level, one submodule per area and per vendor
"""
from __future__ import annotations
from motorbus import ArcusBadSspd
from motorbus import ArcusEnableRs485
from motorbus import ArcusError
from motorbus import ArcusIndexOutOfRange
from motorbus import ArcusMotorNotMoving
from motorbus import ArcusMoving
from motorbus import ArcusScvOn
from motorbus import ArcusSpeedOutOfRange
from motorbus import ArcusStateError
from motorbus import ArcusUnknownCommand
from motorbus import ClosedError
from motorbus import DmacCommandRejected
from motorbus import DmacUnknownCommand
from motorbus import DriveFault
from motorbus import InvalidArgument
from motorbus import LimitExceeded
from motorbus import LinkDown
from motorbus import MotorbusError
from motorbus import ProtocolError
from motorbus import ReplyTooLong
from motorbus import TimeoutError
from motorbus import UnitekCyclicLimit
from motorbus import UnitekFrameError
from motorbus import UnitekUnknownRegister
from motorbus.canopen import SdoAbortError
from motorbus.canopen import SdoProtocolError
from motorbus.canopen import SdoTimeout
from . import runtime
from . import poll
from . import can
from . import serial
from . import canopen
from . import motion
from . import arcus
from . import cia402
from . import dmac
from . import pmc007
from . import unitek
__all__: list[str] = ['ArcusBadSspd', 'ArcusEnableRs485', 'ArcusError', 'ArcusIndexOutOfRange', 'ArcusMotorNotMoving', 'ArcusMoving', 'ArcusScvOn', 'ArcusSpeedOutOfRange', 'ArcusStateError', 'ArcusUnknownCommand', 'ClosedError', 'DmacCommandRejected', 'DmacUnknownCommand', 'DriveFault', 'InvalidArgument', 'LimitExceeded', 'LinkDown', 'MotorbusError', 'ProtocolError', 'ReplyTooLong', 'SdoAbortError', 'SdoProtocolError', 'SdoTimeout', 'TimeoutError', 'UnitekCyclicLimit', 'UnitekFrameError', 'UnitekUnknownRegister', 'arcus', 'can', 'canopen', 'cia402', 'dmac', 'motion', 'pmc007', 'poll', 'runtime', 'serial', 'unitek']
