"""Our logs read by python-can's LogReader, and python-can's logs read by us."""
import time

import can
import pytest

import motorbus
from motorbus import Frame
from motorbus.bus import wall_time
from polling import wait_for

FRAMES = [Frame(0x123, b"\xde\xad\xbe\xef"), Frame(0x7FF, b""), Frame(0x1FFFFFFF, bytes(range(8)), extended=True),
          Frame(0x001, b"", rtr=True, dlc=4), Frame(0x0, b"\x00", extended=True), Frame(0x55, b"", rtr=True)]


@pytest.mark.parametrize("suffix", [".log", ".asc"])
def test_python_can_reads_our_logs_identically(tmp_path, suffix):
    path = tmp_path / f"run{suffix}"
    with motorbus.open_bus("virtual:log-1") as tx, motorbus.open_bus("virtual:log-1") as rx:
        rec = motorbus.Recorder(rx, str(path))
        received = []
        sub = rx.subscribe(received.append)
        for f in FRAMES:
            tx.send(f)
        wait_for(lambda: rec.count >= len(FRAMES), 2.0)
        rx.unsubscribe(sub)
        rec.stop()
    # ASC: python-can reports times relative to the trigger block unless asked for absolute ones
    reader = can.ASCReader(str(path), relative_timestamp=False) if suffix == ".asc" else can.LogReader(str(path))
    msgs = list(reader)
    assert len(msgs) == len(FRAMES)
    ours, bad = motorbus.read_log(str(path))
    assert bad == 0 and len(ours) == len(msgs)
    for e, m in zip(ours, msgs):  # both readers recover the same instants from the text
        assert m.timestamp == pytest.approx(e.time, abs=1e-6)
    for f, m in zip(received, msgs):
        assert (m.arbitration_id, m.is_extended_id, m.is_remote_frame, m.dlc) == (f.id, f.extended, f.rtr, f.dlc)
        assert bytes(m.data or b"") == f.data
        assert m.is_rx
        # The recorder maps monotonic to wall time with its own offset, taken when it
        # started; the test's offset is another reading of the same two clocks.
        assert m.timestamp == pytest.approx(wall_time(f.timestamp_ns), abs=5e-3)


@pytest.mark.parametrize("suffix", [".log", ".asc"])
def test_we_read_python_can_logs(tmp_path, suffix):
    path = tmp_path / f"pc{suffix}"
    t0 = time.time()
    msgs = [can.Message(timestamp=t0 + i * 0.01, arbitration_id=0x100 + i, data=bytes([i] * i), is_extended_id=i % 2 == 1)
            for i in range(8)]
    msgs.append(can.Message(timestamp=t0 + 0.1, arbitration_id=0x42, is_remote_frame=True, dlc=2))
    with can.Logger(str(path)) as log:
        for m in msgs:
            log.on_message_received(m)
    entries, bad = motorbus.read_log(str(path))
    assert bad == 0
    # python-can's candump writer drops a remote frame's DLC ("042#R"), so it reads back as 0
    expected = [(m.arbitration_id, m.is_extended_id, m.is_remote_frame,
                 0 if (m.is_remote_frame and suffix == ".log") else m.dlc, bytes(m.data or b"")) for m in msgs]
    assert [(e.frame.id, e.frame.extended, e.frame.rtr, e.frame.dlc, e.frame.data) for e in entries] == expected
    if suffix == ".log":
        assert [e.time for e in entries] == pytest.approx([m.timestamp for m in msgs], abs=1e-6)
    else:  # ASC stores times relative to the first message; spacing is preserved
        assert [e.time - entries[0].time for e in entries] == pytest.approx(
            [m.timestamp - msgs[0].timestamp for m in msgs], abs=1e-6)


def test_player_replays_with_original_timing_and_flat_out(tmp_path):
    path = tmp_path / "timed.log"
    path.write_text("".join(f"({1000 + i * 0.02:.6f}) can0 {0x200 + i:03X}#{i:02X} R\n" for i in range(6))
                    + "garbage line\n(1.0) can0 800#00 R\n")
    entries, bad = motorbus.read_log(str(path))
    assert len(entries) == 6 and bad == 2  # the 12-bit id 0x800 is refused too
    with motorbus.open_bus("virtual:play") as tx, motorbus.open_bus("virtual:play") as rx:
        start = time.monotonic_ns()
        assert motorbus.play(tx, entries, speed=1.0) == 6
        got = [rx.recv(1.0) for _ in range(6)]
        assert [f.id for f in got] == [0x200 + i for i in range(6)]
        # The player keeps an absolute schedule from its start: frame i is never
        # sent before 20*i ms.  (The upper
        # bound is loose: a loaded machine may deschedule the player.)
        offsets = [(f.timestamp_ns - start) / 1e9 for f in got]
        assert all(0.02 * i <= off < 0.02 * i + 1.0 for i, off in enumerate(offsets)), offsets
        # Flat out ignores the log's timing: 6 frames 10 s apart go at once
        # (paced they would take 50 s).
        slow_path = tmp_path / "slow.log"
        slow_path.write_text("".join(f"({1000 + i * 10.0:.6f}) can0 {0x200 + i:03X}#{i:02X}\n" for i in range(6)))
        slow_log, bad = motorbus.read_log(str(slow_path))
        assert len(slow_log) == 6 and bad == 0
        t = time.monotonic()
        assert motorbus.play(tx, slow_log, speed=0) == 6
        assert time.monotonic() - t < 10.0
        assert [rx.recv(1.0).id for _ in range(6)] == [0x200 + i for i in range(6)]
