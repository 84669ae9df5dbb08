"""Recording and replaying buses (candump -L and Vector ASC logs).

    with motorbus.Recorder(bus, "run.log"):     # or "run.asc"
        ...
    entries, bad = motorbus.read_log("run.log")
    motorbus.play(bus, entries, speed=1.0)      # 0 = as fast as possible

python-can's ``can.LogReader`` reads these files back frame for frame.
"""
from ._core.can import LogEntry, Recorder, parse_candump_line, play, read_log

__all__ = ["LogEntry", "Recorder", "parse_candump_line", "play", "read_log"]
