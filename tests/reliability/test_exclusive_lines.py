"""Promise 5: one serial line, one opener — another process opening the pty slave a motorbus
server or client holds gets LinkDown naming "busy" (and this process, when the child holds it)."""
import os
import subprocess
import sys

import pytest

import motorbus
from motorbus.serial import PtyLineServer, open_port

from _soak import size

ROUNDS = size(3, 50)

CHILD = """
import sys, motorbus
from motorbus.serial import open_port
try:
    open_port(sys.argv[1], 115200)
except motorbus.LinkDown as e:
    print("LinkDown", e); sys.exit(0)
print("opened"); sys.exit(1)
"""

HOLDER = """
import sys
from motorbus.serial import open_port
p = open_port(sys.argv[1], 115200)
print("held", flush=True)
sys.stdin.readline()
p.close()
"""


@pytest.mark.subprocess
@pytest.mark.parametrize("round_", range(ROUNDS))
def test_second_opener_of_a_line_is_refused(round_):
    with PtyLineServer([]) as server:
        mine = open_port(server.slave_path, 115200)
        child = subprocess.run([sys.executable, "-c", CHILD, server.slave_path],
                               capture_output=True, text=True, timeout=60)
        assert child.returncode == 0, child.stdout + child.stderr
        assert "busy" in child.stdout and server.slave_path in child.stdout
        assert f"pid {os.getpid()}" in child.stdout
        mine.close()
        # The other way round: a child holds it, we are refused, then it is free again.
        holder = subprocess.Popen([sys.executable, "-c", HOLDER, server.slave_path],
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        try:
            assert holder.stdout.readline().strip() == "held"
            with pytest.raises(motorbus.LinkDown, match=rf"{server.slave_path}.*busy.*pid {holder.pid}"):
                open_port(server.slave_path, 115200)
        finally:
            holder.stdin.write("\n")
            holder.stdin.close()
            assert holder.wait(30) == 0
        open_port(server.slave_path, 115200).close()
