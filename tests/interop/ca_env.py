"""Channel Access on 127.0.0.1 for the interop tests: the environment, and a served twin.

libca (pyepics, aioca, hence ophyd and ophyd-async) reads the EPICS environment once per
process, when its first context is made, so :func:`configure` runs at conftest import,
before any test module imports a client.  Every pytest-xdist worker gets its own CA port
(``20000 + 16 * worker``, the team's rule; the next free pair above it when another
pytest session on this machine holds it): caproto binds the UDP search port with
SO_REUSEPORT, and two servers on one port would share unicast searches by a hash of the
client address, sending a client to the wrong server for good.  Nothing leaves loopback:
no automatic address list, beacons to 127.0.0.1 only (caproto's default is
255.255.255.255, LAN broadcast).  ``MOTORBUS_TEST_CA_PORT_BASE`` moves the whole range.
"""
from __future__ import annotations

import asyncio
import os
import socket
import struct
import threading
from typing import Any, Callable, Optional

PORTS_PER_WORKER = 16


def worker_index() -> int:
    """0 for ``gw0`` (and outside xdist), 1 for ``gw1``, ..."""
    worker = os.environ.get("PYTEST_XDIST_WORKER", "gw0")
    return int(worker[2:]) if worker.startswith("gw") and worker[2:].isdigit() else 0


#: Offsets in the worker's range this helper may take (server port, repeater port = +1);
#: 7 and up are left to modules that pick their own (tests/python/test_serve_*.py).
OFFSETS = (0, 2, 4)
_chosen: Optional[int] = None


def _free(port: int) -> bool:
    """Nobody holds the UDP port (caproto's search socket, a repeater) or the TCP port.
    The probe binds without SO_REUSEADDR/SO_REUSEPORT, so a server holding the port with
    them still makes it fail."""
    for kind in (socket.SOCK_DGRAM, socket.SOCK_STREAM):
        s = socket.socket(socket.AF_INET, kind)
        try:
            s.bind(("127.0.0.1", port))
        except OSError:
            return False
        finally:
            s.close()
    return True


def server_port() -> int:
    """This process's CA server port: the first free pair of the worker's range
    (``20000 + 16 * worker + offset``), chosen once.  Two pytest sessions on one machine
    (both worker 0) then do not share a port; sharing one would split the searches between
    their servers by the kernel's SO_REUSEPORT hash."""
    global _chosen
    if _chosen is None:
        base = int(os.environ.get("MOTORBUS_TEST_CA_PORT_BASE", "20000")) + PORTS_PER_WORKER * worker_index()
        _chosen = next((base + k for k in OFFSETS if _free(base + k) and _free(base + k + 1)), base)
    return _chosen


def repeater_port() -> int:
    return server_port() + 1


def environment() -> dict[str, str]:
    """What server and clients of this worker set (the server side's variables are caproto's)."""
    port, repeater = str(server_port()), str(repeater_port())
    return {
        "EPICS_CA_SERVER_PORT": port,            # caproto's server binds TCP and UDP search here
        "EPICS_CA_REPEATER_PORT": repeater,
        "EPICS_CA_AUTO_ADDR_LIST": "NO",
        "EPICS_CA_ADDR_LIST": f"127.0.0.1:{port}",   # the port named: libca and caproto honour host:port
        "EPICS_CAS_INTF_ADDR_LIST": "127.0.0.1",
        "EPICS_CAS_AUTO_BEACON_ADDR_LIST": "NO",
        "EPICS_CAS_BEACON_ADDR_LIST": "127.0.0.1",
        "EPICS_CAS_BEACON_PORT": repeater,        # beacons go to this worker's repeater, not 5065
        # libca warns, then carries on, when no repeater answers (the wheels ship no caRepeater);
        # a test that wants one starts caproto's in a thread (start_repeater).
    }


def configure() -> None:
    """Sets this worker's CA environment in os.environ (forced: a developer's facility
    EPICS_CA_ADDR_LIST must not send test searches off this machine).  Called at conftest
    import and again by each module's server fixture: a CA server started by an earlier
    module of the worker (``start_ca`` sets ``EPICS_CA_SERVER_PORT`` to its own port) must
    not leave its port to the clients of the next."""
    os.environ.update(environment())


_repeater: Optional[threading.Thread] = None


def start_repeater() -> None:
    """caproto's repeater on 127.0.0.1:<repeater port>, in a daemon thread, once per process.
    If the port is taken (a repeater of an earlier run still lives), that one serves."""
    global _repeater
    if _repeater is not None:
        return
    from caproto.sync import repeater

    probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
    try:
        probe.bind(("127.0.0.1", repeater_port()))
    except OSError:
        return
    finally:
        probe.close()
    _repeater = threading.Thread(target=lambda: _quietly(repeater.run, "127.0.0.1"), name="ca-repeater",
                                 daemon=True)
    _repeater.start()


def _quietly(fn: Callable, *args: Any) -> None:
    try:
        fn(*args)
    except Exception:       # a repeater that cannot bind means another one serves: not the test's failure
        pass


def connected_udp_peers(pid: str = "self") -> list[tuple[str, int]]:
    """The remote (address, port) of every connected UDP socket of a process, from /proc:
    where its beacons go (caproto connects one UDP socket per beacon address)."""
    inodes = set()
    fd_dir = f"/proc/{pid}/fd"
    for fd in os.listdir(fd_dir):
        try:
            target = os.readlink(os.path.join(fd_dir, fd))
        except OSError:
            continue
        if target.startswith("socket:["):
            inodes.add(target[8:-1])
    peers = []
    with open(f"/proc/{pid}/net/udp") as f:
        next(f)
        for line in f:
            cols = line.split()
            remote, inode = cols[2], cols[9]
            if inode not in inodes:
                continue
            addr_hex, port_hex = remote.split(":")
            if int(port_hex, 16) == 0:
                continue            # not connected
            addr = socket.inet_ntoa(struct.pack("<I", int(addr_hex, 16)))
            peers.append((addr, int(port_hex, 16)))
    return peers


class ServedTwin:
    """A simulated bench served over CA from a thread of its own with its own event loop,
    the way ``motorbus serve`` runs it: every drive call of the CA face happens there."""

    def __init__(self, data: dict, *, prefix: str) -> None:
        self.data, self.prefix = data, prefix
        self.loop = asyncio.new_event_loop()
        self.bench: Any = None          # motorbus.aio.Bench
        self.face: Any = None           # motorbus.serve.epics.CaFace
        self._thread = threading.Thread(target=self.loop.run_forever, name="ca-face", daemon=True)

    def start(self, timeout: float = 30.0) -> "ServedTwin":
        self._thread.start()
        self.run(self._open(), timeout=timeout)
        return self

    async def _open(self) -> None:
        from motorbus import aio
        from motorbus.serve.epics import start_ca

        self.bench = await aio.Bench.from_dict(self.data, sim=True)
        await asyncio.gather(*(d.clear_faults() for d in self.bench.axes.values()))
        await asyncio.gather(*(d.enable() for d in self.bench.axes.values()))
        self.face = await start_ca(self.bench, prefix=self.prefix, interfaces=("127.0.0.1",), port=server_port())

    def run(self, coro: Any, timeout: float = 30.0) -> Any:
        """Runs a coroutine on the service's loop; returns its result."""
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout)

    @property
    def sims(self) -> dict:
        return self.bench.sync.sims

    def quiesce(self) -> None:
        """Every axis stopped and the records' readbacks ended, the CA server left serving
        (closed at exit, see test_epics_clients.twin): an idle twin for the rest of this
        worker's session -- no polling, so its link workers end and later modules of the
        worker see no thread of it."""
        async def still() -> None:
            await self.bench.stop_all()
            tasks = [r._readback for r in self.face.records.values()]
            for task in tasks:
                task.cancel()
            await asyncio.gather(*tasks, return_exceptions=True)

        self.run(still())

    def close(self) -> None:
        async def shut() -> None:
            try:
                if self.face is not None:
                    await self.face.close()
            finally:
                if self.bench is not None:
                    await self.bench.stop_all()
                    await self.bench.aclose()

        try:
            self.run(shut())
        finally:
            self.loop.call_soon_threadsafe(self.loop.stop)
            self._thread.join(10)
            self.loop.close()
