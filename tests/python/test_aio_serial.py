"""Serial line transactions awaited (``motorbus.aio.transact``): the completion-based
C++ entry point ``LineLink.transact_async`` over a real pty, against a served line device."""
from __future__ import annotations

import asyncio
import os

import pytest

import motorbus
from motorbus import aio, faces
from motorbus._core.serial import LineLink, PtyLineServer
from motorbus.serial import EchoLineDevice


def native_threads() -> int:
    """Threads of this process, C++ ones included (threading sees only Python's)."""
    return len(os.listdir("/proc/self/task"))


@pytest.fixture
def link():
    server = PtyLineServer([EchoLineDevice(prefix=b"P:")])
    port = motorbus._core.serial.open_port(server.slave_path, 0)
    link = LineLink(port, reply_timeout=1.0)
    yield link
    del link
    port.close()
    server.close()


async def test_awaited_transactions_come_back_in_order_with_their_replies(link):
    replies = await asyncio.gather(*(aio.transact(link, f"req{i}") for i in range(200)))
    assert replies == [f"P:req{i}".encode() for i in range(200)]
    # Every one went over the line, interleaved with blocking ones as they come.
    assert link.transact("sync") == b"P:sync"
    assert await aio.transact(link, b"\x01bytes") == b"P:\x01bytes"
    assert link.counters.replies == 202


async def test_three_hundred_awaited_transactions_cost_one_thread(link):
    before = native_threads()
    bridge = faces.bridge_for()
    pushed = bridge.completions.pushed
    await asyncio.gather(*(aio.transact(link, f"x{i}") for i in range(300)))
    assert native_threads() == before + 1                    # the link's one C++ worker, whatever the count
    assert bridge.completions.pushed - pushed == 300          # each reply came back through the loop's queue


async def test_no_reply_is_a_timeout_error_and_the_link_goes_on():
    server = PtyLineServer([])                                # nobody answers
    port = motorbus._core.serial.open_port(server.slave_path, 0)
    link = LineLink(port, reply_timeout=0.05)
    try:
        with pytest.raises(motorbus.TimeoutError, match="no reply to 'hello'"):
            await aio.transact(link, "hello")
        with pytest.raises(motorbus.InvalidArgument):
            await aio.transact(link, 123)
    finally:
        del link
        port.close()
        server.close()


async def test_a_cancelled_await_leaves_the_link_usable(link):
    task = asyncio.create_task(aio.transact(link, "slow"))
    await asyncio.sleep(0)
    task.cancel()
    with pytest.raises(asyncio.CancelledError):
        await task
    assert await aio.transact(link, "next") == b"P:next"


def test_a_link_closed_with_transactions_queued_fails_them_and_outlives_the_loop():
    """The link's worker completes into a queue the loop may no longer watch: nothing
    touches Python from the worker, and destroying the link fails what was still queued."""
    server = PtyLineServer([])
    port = motorbus._core.serial.open_port(server.slave_path, 0)
    link = LineLink(port, reply_timeout=0.2)
    done = motorbus._core.runtime.Completions()
    for token in range(5):
        link.transact_async(b"q", done, token)
    del link                                                  # joins the worker: the first times out, the rest close
    port.close()
    server.close()
    got = done.drain()
    assert [t for t, _, _ in got] == [0, 1, 2, 3, 4]
    errors = []
    for _, value, failure in got:
        assert value is None and failure is not None
        with pytest.raises(motorbus.MotorbusError) as e:
            failure.rethrow()
        errors.append(type(e.value).__name__)
    # At most the transaction in progress ran (and timed out); the rest were failed unrun.
    assert set(errors[1:]) == {"ClosedError"} and errors[0] in ("TimeoutError", "ClosedError")


@pytest.mark.subprocess
def test_an_interpreter_exiting_with_transactions_in_flight_exits_cleanly(tmp_path):
    """pybind11#3274: C++ threads that outlive the loop and the interpreter.  A script
    leaves awaited line transactions in flight (nobody answers) and returns from
    asyncio.run and from the interpreter at once: the link's worker completes into a
    queue no loop watches and touches no Python object, so the exit is clean."""
    import subprocess
    import sys

    script = tmp_path / "exit_in_flight.py"
    script.write_text(
        "import asyncio\n"
        "import motorbus\n"
        "from motorbus import aio\n"
        "from motorbus._core.serial import LineLink, PtyLineServer\n"
        "server = PtyLineServer([])\n"
        "port = motorbus._core.serial.open_port(server.slave_path, 0)\n"
        "link = LineLink(port, reply_timeout=0.3)\n"
        "async def main():\n"
        "    for i in range(20):\n"
        "        asyncio.get_running_loop().create_task(aio.transact(link, f'q{i}'))\n"
        "    await asyncio.sleep(0.05)\n"
        "asyncio.run(main())\n"
        "print('exiting with transactions in flight', flush=True)\n")
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr[-2000:]
    assert "exiting with transactions in flight" in done.stdout
    assert "Fatal Python error" not in done.stderr and "terminate called" not in done.stderr
