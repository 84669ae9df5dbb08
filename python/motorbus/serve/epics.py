"""The Channel Access face of ``motorbus serve``: every axis of an ``aio.Bench`` as an
EPICS motor record, served by caproto on the service's event loop (docs/epics.md).

    face = await start_ca(bench, prefix="lab2:", interfaces=["127.0.0.1"], port=5064,
                          calibration_path="lab2.epics.json")
    face.client_env()        # what a CA client on this host sets
    await face.close()

Per axis ``<prefix><axis>`` is a ``motor`` record (RTYP "motor", the fields ophyd's
``EpicsMotor``, ophyd-async's ``Motor`` and pyepics' ``Motor`` use, with their types
and enum strings) and ``<prefix><axis>_able`` its Enable/Disable bo; bench-wide
``<prefix>allstop`` (bo release/stop), ``<prefix>alldone`` (bi moving/done) and
``<prefix>moving`` (the number of axes moving), the names of the motor module's
motorUtil.db.

The record's behaviour is the motor record's (motorRecord.cc), over the awaitable Drive
API: every drive call is awaited on the service's loop, so a slow drive delays only
its own record.  The state machine of one axis is ``epics_axis.AxisRecord``.
"""
from __future__ import annotations

import asyncio
import logging
import os
import time
from collections.abc import Sequence
from typing import Any, Optional

from .. import _core

try:
    import caproto  # noqa: F401
except ImportError as e:  # pragma: no cover - the extra is missing
    raise _core.InvalidArgument("motorbus serve's Channel Access face needs caproto, the optional extra "
                                "motorbus[epics]: pip install 'motorbus[epics]'") from e

from caproto import ChannelType
from caproto.server import PVGroup, pvproperty

from .calibration import CalibrationStore
from .epics_axis import PUT_NOTIFY, RESERVED, AxisRecord, PutRefused, check_axis_name

__all__ = ["start_ca", "CaFace", "set_server_environment", "BenchRecords", "AxisRecord", "PutRefused",
           "LATENCY_SETTINGS"]

log = logging.getLogger(__name__)

#: caproto's subscription batching (research brief, gotcha 5): by default an update waits up
#: to 10 ms for company and a busy circuit up to 1 s.  The write lock: a read or subscribe
#: on a circuit waits up to this long for the write in flight, so that a read after a
#: plain put sees it (as an IOC, which processes a put before the next request); a
#: put-callback move releases the lock at once (``_context_class``), a plain put's putter
#: returns once the move is started.
LATENCY_SETTINGS = {
    "CAPROTO_SERVER_HIGH_LOAD_TIMEOUT_SEC": ("HIGH_LOAD_TIMEOUT", 0.0005),
    "CAPROTO_SERVER_MAX_LATENCY_SEC": ("MAX_LATENCY", 0.005),
    "CAPROTO_SERVER_WRITE_LOCK_TIMEOUT_SEC": ("WRITE_LOCK_TIMEOUT", 0.003),
}
DEFAULT_PORT = 5064
#: The longest a put's completion waits for the monitor updates before it (``flush_monitors``).
FLUSH_LIMIT = 0.02


def _beacon_addresses(interfaces: Sequence[str]) -> list[str]:
    """Where beacons go: the interfaces served, loopback for the wildcard (never the LAN
    broadcast caproto defaults to: gotcha 6)."""
    out = []
    for iface in interfaces:
        addr = "127.0.0.1" if iface in ("0.0.0.0", "") else iface
        if addr not in out:
            out.append(addr)
    return out or ["127.0.0.1"]


def set_server_environment(interfaces: Sequence[str] = ("127.0.0.1",), port: Optional[int] = None) -> None:
    """Sets what caproto's server reads from the environment, before it starts: the
    interfaces (``EPICS_CAS_INTF_ADDR_LIST``), beacons only to the served interfaces
    (``EPICS_CAS_AUTO_BEACON_ADDR_LIST=NO``, ``EPICS_CAS_BEACON_ADDR_LIST``), the port
    (``EPICS_CA_SERVER_PORT`` when given) and the latency settings of ``LATENCY_SETTINGS``
    (environment and, caproto being imported, its module globals).  A value the user
    already exported for a latency setting is kept."""
    interfaces = list(interfaces) or ["127.0.0.1"]
    os.environ["EPICS_CAS_INTF_ADDR_LIST"] = " ".join(interfaces)
    os.environ["EPICS_CAS_AUTO_BEACON_ADDR_LIST"] = "NO"
    os.environ["EPICS_CAS_BEACON_ADDR_LIST"] = " ".join(_beacon_addresses(interfaces))
    if port is not None:
        os.environ["EPICS_CA_SERVER_PORT"] = str(int(port))
    import caproto.server.common as common

    for env, (name, value) in LATENCY_SETTINGS.items():
        chosen = float(os.environ.setdefault(env, repr(value)))
        setattr(common, name, chosen)


class _QuietRefusals(logging.Filter):
    """caproto logs every failed put with its traceback (gotcha 3); a refused or failed
    move is the record's answer, not a server error: one line, no traceback."""

    def filter(self, record: logging.LogRecord) -> bool:
        exc = record.exc_info[1] if record.exc_info else None
        if isinstance(exc, OSError) and isinstance(exc.__cause__, ConnectionRefusedError) \
                and str(record.msg).startswith("Failed to send beacon"):
            # No CA repeater listens on this host (none is needed to be found): the kernel
            # answers each beacon with "port unreachable", and caproto would log a traceback
            # every beacon period.
            return False
        if isinstance(exc, PutRefused):
            record.exc_info = None
            record.exc_text = None
            record.msg, record.args = "put refused: %s", (exc,)
            record.levelno, record.levelname = logging.INFO, "INFO"
            return log.isEnabledFor(logging.INFO)
        return True


_QUIET = _QuietRefusals()
#: caproto's loggers of failed puts (circuits) and of beacons (the context).
_QUIETENED = ("caproto.circ", "caproto.ctx")


class BenchRecords(PVGroup):
    """The bench-wide records of motorUtil.db: ``allstop``, ``alldone``, ``moving``."""

    allstop = pvproperty(name="allstop", value="release", dtype=ChannelType.ENUM, enum_strings=("release", "stop"),
                         record="bo", doc="stop every axis")
    alldone = pvproperty(name="alldone", value="done", dtype=ChannelType.ENUM, enum_strings=("moving", "done"),
                         record="bi", read_only=True, doc="every axis done")
    moving = pvproperty(name="moving", value=0, dtype=int, record="longout", read_only=True,
                        doc="axes moving")

    def __init__(self, *args: Any, face: "CaFace", **kwargs: Any) -> None:
        super().__init__(*args, **kwargs)
        self.face = face

    @allstop.putter
    async def allstop(self, instance: Any, value: Any) -> Any:
        if value in ("stop", 1):
            await self.face.stop_all()
        return "release"

    async def refresh(self) -> None:
        n = sum(1 for r in self.face.records.values() if r.fields["DMOV"].value == 0)
        if self.moving.value != n:
            await self.moving.write(n, verify_value=False)
        done = "done" if n == 0 else "moving"
        if self.alldone.value != done:
            await self.alldone.write(done, verify_value=False)


class CaFace:
    """The running CA face (``start_ca``)."""

    def __init__(self, bench: Any, prefix: str, interfaces: list[str], port: int,
                 calibration: CalibrationStore) -> None:
        self.bench = bench
        self.prefix = prefix
        self.interfaces = interfaces
        self.port = port
        self.calibration = calibration
        self.records: dict[str, AxisRecord] = {}
        self.counters: dict[str, int] = {"puts": 0, "failed_puts": 0, "moves": 0, "failed_moves": 0,
                                         "interrupted_moves": 0,
                                         "stops": 0, "readback_errors": 0, "accel_errors": 0}
        self.bench_records: Optional[BenchRecords] = None
        self.pvdb: dict[str, Any] = {}
        self.context: Any = None
        self._server: Optional[asyncio.Task] = None
        self._closed = False

    def client_env(self) -> dict[str, str]:
        """The environment a CA client on this host sets to find the service (and nothing else)."""
        # Explicit even at the default port: a client's environment may say otherwise.
        addrs = _beacon_addresses(self.interfaces)
        return {"EPICS_CA_AUTO_ADDR_LIST": "NO",
                "EPICS_CA_ADDR_LIST": " ".join(f"{a}:{self.port}" for a in addrs),
                "EPICS_CA_SERVER_PORT": str(self.port)}

    async def stop_all(self) -> None:
        """``allstop``: every axis's STOP at once."""
        await asyncio.gather(*(r.stop_axis("allstop") for r in self.records.values()), return_exceptions=True)

    async def flush_monitors(self) -> None:
        """Waits (at most ``FLUSH_LIMIT`` s) until the monitor updates posted so far have
        left for the clients: a put's completion must not overtake them, or a client that
        reads after the put (pyepics: LVIO, RBV, ``get_position()``) reads the old values.
        caproto sends a put's answer directly but batches monitor updates (gotcha 5)."""
        ctx = self.context
        if ctx is None:
            return
        import caproto.server.common as common

        deadline = time.monotonic() + FLUSH_LIMIT
        await asyncio.sleep(0)
        while time.monotonic() < deadline:
            if ctx.subscription_queue.empty() and all(c.subscription_queue.empty() for c in list(ctx.circuits)):
                break
            await asyncio.sleep(0.0002)
        # The circuit's loop sends once its queue stays empty for HIGH_LOAD_TIMEOUT.
        await asyncio.sleep(common.HIGH_LOAD_TIMEOUT + 0.0003)

    async def _dmov_changed(self) -> None:
        if self.bench_records is not None:
            await self.bench_records.refresh()

    async def close(self) -> None:
        """Stops serving (no axis is stopped: the service decides that) and ends every task."""
        if self._closed:
            return
        self._closed = True
        if self._server is not None:          # first: no put starts while the records close
            self._server.cancel()
            try:
                await self._server
            except (asyncio.CancelledError, Exception):  # noqa: BLE001 - closing anyway
                pass
        for r in self.records.values():
            await r.shutdown()
        for name in _QUIETENED:
            logging.getLogger(name).removeFilter(_QUIET)


def _udp_port_shared(interfaces: Sequence[str], port: int) -> list[str]:
    """The interfaces whose UDP ``port`` another socket already holds (another CA server on
    this host: caproto would bind beside it with SO_REUSEPORT, and the kernel would then
    hand each client's searches to one of the two servers only -- gotcha 7)."""
    import errno
    import socket

    taken = []
    for iface in interfaces:
        probe = socket.socket(socket.AF_INET, socket.SOCK_DGRAM)
        try:
            probe.bind((iface, port))
        except OSError as e:
            if e.errno == errno.EADDRINUSE:
                taken.append(iface)
        finally:
            probe.close()
    return taken


def _context_class() -> Any:
    """caproto's asyncio server whose circuits tell each write task whether its client waits
    for the put's completion (``PUT_NOTIFY``): a plain put of a target the record refuses is
    not answered with an error, as a real IOC would not."""
    from caproto import WriteNotifyRequest, WriteRequest
    from caproto.asyncio.server import Context, VirtualCircuit

    class Circuit(VirtualCircuit):
        async def _process_command(self, command: Any) -> Any:
            if not isinstance(command, (WriteRequest, WriteNotifyRequest)):
                return await super()._process_command(command)
            # The write task is created inside: it inherits this context.
            notify = isinstance(command, WriteNotifyRequest)
            token = PUT_NOTIFY.set(notify)
            try:
                return await super()._process_command(command)
            finally:
                PUT_NOTIFY.reset(token)
                if notify:
                    # Its client waits for the completion before it reads; other reads on
                    # the circuit (monitors' gets in other threads) need not wait for a move.
                    self.write_event.set()

    class MotorbusContext(Context):
        CircuitClass = Circuit

    return MotorbusContext


async def build_face(bench: Any, *, prefix: str, interfaces: Sequence[str] = ("127.0.0.1",),
                     port: Optional[int] = None, calibration_path: Optional[str] = None) -> CaFace:
    """The records of every axis, started (readbacks running), without a CA server: what
    ``start_ca`` serves, and what tests drive through the putters directly."""
    if not isinstance(prefix, str) or any(c.isspace() or c == "." for c in prefix):
        raise _core.InvalidArgument(f"CA prefix: text without spaces or dots, not {prefix!r}")
    names = list(bench.axes)
    for name in names:
        check_axis_name(name, names)
    if port is None:
        port = int(os.environ.get("EPICS_CA_SERVER_PORT", DEFAULT_PORT))
    face = CaFace(bench, prefix, list(interfaces) or ["127.0.0.1"], int(port), CalibrationStore(calibration_path))
    try:
        for name in names:
            record = AxisRecord(prefix=f"{prefix}{name}", axis=name, drive=bench[name], face=face)
            face.records[name] = record
            face.pvdb.update(record.pvdb)
        # Every axis reads its drive at once: the links work in parallel (a bench of 64 axes
        # on a few lines starts in the time of its busiest line, not of all its exchanges).
        started = await asyncio.gather(*(r.start() for r in face.records.values()), return_exceptions=True)
        for outcome in started:
            if isinstance(outcome, BaseException):
                raise outcome
        face.bench_records = BenchRecords(prefix=prefix, face=face)
        face.pvdb.update(face.bench_records.pvdb)
        await face.bench_records.refresh()
    except BaseException:
        await face.close()
        raise
    return face


async def start_ca(bench: Any, *, prefix: str, interfaces: Sequence[str] = ("127.0.0.1",),
                   port: Optional[int] = None, calibration_path: Optional[str] = None) -> CaFace:
    """Serves every axis of ``bench`` (an ``aio.Bench``) over Channel Access on
    ``interfaces`` (loopback by default), UDP search port ``port`` (None:
    ``EPICS_CA_SERVER_PORT`` or 5064); the calibration is read from and kept in
    ``calibration_path``.  Returns once the server listens."""
    interfaces = list(interfaces) or ["127.0.0.1"]
    set_server_environment(interfaces, port)
    for name in _QUIETENED:
        logging.getLogger(name).addFilter(_QUIET)
    face = await build_face(bench, prefix=prefix, interfaces=interfaces, port=port, calibration_path=calibration_path)
    shared = _udp_port_shared(interfaces, face.port)
    if shared:
        log.warning("UDP port %d on %s is already taken by another CA server on this host: a client's searches "
                    "may reach only one of the two (give this service its own port: --ca-port)", face.port,
                    ", ".join(shared))
        face.counters["shared_udp_port"] = 1
    try:
        ctx = _context_class()(face.pvdb, interfaces=interfaces)
        ctx.ca_server_port = face.port
        face.context = ctx
        face._server = asyncio.create_task(ctx.run(), name="motorbus-ca-server")
        # Listening once every interface's UDP search socket is bound (run() binds TCP first).
        for _ in range(500):
            if face._server.done():
                face._server.result()        # the bind error
                raise _core.InvalidArgument("CA server ended at start")
            if len(ctx.udp_socks) >= len(interfaces):
                break
            await asyncio.sleep(0.01)
        else:
            raise _core.TimeoutError("CA server: not listening after 5 s")
    except BaseException:
        await face.close()
        raise
    log.info("serving %d motor records on %s port %d (prefix %r)", len(face.records), ", ".join(interfaces),
             face.port, prefix)
    return face


__all__ += ["build_face", "RESERVED"]
