"""``BenchService``: one process owns a bench and serves it (docs/serve.md).

    service = BenchService("bench.toml", sim=True, epics=False)
    await service.start()          # lock, bench, faces, lock file published
    await service.run()            # until SIGTERM / SIGINT / SIGHUP (or request_stop())

The order of ``start()`` is the order of what may fail, cheapest first: the lock (a
second service of the same bench fails before it opens, or disturbs, any transport),
caproto's presence (``--no-epics`` needs none), the bench's transports, the CA face,
the RPC face, and last the lock file's JSON -- a program that finds the service finds
it ready.  Every drive call of either face goes through the one ``aio.Bench`` on this
process's one event loop (contract: no blocking drive call on the loop).

Shutdown (a signal or ``request_stop()``): every axis is stopped at once, the faces are
closed (no new command can start a motor), every axis is stopped again (one that a
client started in between), each is given ``STOP_WAIT`` seconds to come to rest
(quick stop for one that does not; a second signal quick-stops every axis still
moving at once), then the bench and the lock are let go.  After a
SIGKILL none of this runs: only the drives' own watchdogs act (docs/serve.md says per
kind what a killed service leaves).
"""
from __future__ import annotations

import asyncio
import importlib.util
import json
import logging
import os
import signal
import stat
import sys
from typing import Any, Callable, Optional, Sequence

from .. import _core
from ..bench import parse_file
from .lockfile import ServiceInfo, ServiceLock, check_socket_path, default_socket_path, register, unregister

log = logging.getLogger(__name__)

__all__ = ["BenchService", "SIGNALS", "STOP_WAIT", "EPICS_EXTRA_HINT"]

#: The signals that end a service cleanly (every axis stopped first).
SIGNALS: tuple = tuple(getattr(signal, n) for n in ("SIGTERM", "SIGINT", "SIGHUP") if hasattr(signal, n))
#: Seconds each axis gets to come to rest after the shutdown's stop, before its quick stop.
STOP_WAIT = 5.0
#: Seconds a face gets to close before the shutdown goes on without it.
FACE_CLOSE_WAIT = 5.0
EPICS_EXTRA_HINT = ("serving EPICS Channel Access needs caproto, the optional extra motorbus[epics]: "
                    "pip install 'motorbus[epics]' (or --no-epics: serve motorbus's own programs only)")


def default_prefix(bench_path: Any) -> str:
    """The CA prefix when neither ``[epics] prefix`` nor ``--prefix`` gives one: the bench
    file's name without its extension, then ``:`` (``lab2.toml`` -> ``lab2:``)."""
    stem = os.path.splitext(os.path.basename(os.fspath(bench_path)))[0]
    return f"{stem}:"


def file_prefix(bench_path: Any) -> Optional[str]:
    """``[epics] prefix`` of the bench file (the bench's checker has vetted it), or None."""
    _text, data = parse_file(os.fspath(bench_path))
    epics = data.get("epics") if isinstance(data, dict) else None
    value = epics.get("prefix") if isinstance(epics, dict) else None
    return value.strip() if isinstance(value, str) and value.strip() else None


def _require(module: str, hint: str) -> None:
    """An optional extra's module, checked before any transport opens."""
    if importlib.util.find_spec(module) is None:
        raise _core.InvalidArgument(f"motorbus serve: {hint}")


WEB_EXTRA_HINT = ("serving the web page (--http) needs aiohttp, the optional extra motorbus[web]: "
                  "pip install 'motorbus[web]'")


class BenchService:
    """Owns ``bench_path``'s bench (or, ``sim=True``, its simulated twin, which then lasts
    as long as the service) and serves it: over Channel Access (``epics=True``, needs
    caproto) and to motorbus's own programs over a Unix socket (always)."""

    def __init__(self, bench_path: Any, *, sim: bool = False, prefix: Optional[str] = None,
                 interfaces: Sequence[str] = ("127.0.0.1",), ca_port: Optional[int] = None,
                 socket_path: Optional[str] = None, epics: bool = True, http: Optional[tuple] = None,
                 allow_motion: bool = False) -> None:
        self.bench_path = os.path.realpath(os.fspath(bench_path))
        if not os.path.isfile(self.bench_path):
            raise _core.InvalidArgument(f"motorbus serve: {os.fspath(bench_path)}: no such bench file")
        if ca_port is not None and (isinstance(ca_port, bool) or not isinstance(ca_port, int)
                                    or not 1 <= ca_port <= 65535):
            raise _core.InvalidArgument(f"motorbus serve: --ca-port: a port 1..65535, not {ca_port!r}")
        interfaces = list(interfaces)
        if not interfaces:
            raise _core.InvalidArgument("motorbus serve: --interface: at least one address to serve on")
        self.sim = sim
        self.epics = epics
        self.prefix = prefix
        self.interfaces = interfaces
        self.ca_port = ca_port
        self.socket_path = check_socket_path(socket_path or default_socket_path(self.bench_path))
        self.http = http                # (host, port) of the web face (serve.web), None: no page
        self.allow_motion = allow_motion
        self.bench: Any = None          # the aio.Bench
        self.ca: Any = None             # serve.epics.CaFace
        self.rpc: Any = None            # serve.rpc.RpcFace
        self.web: Any = None            # serve.web.WebFace
        self.info: Optional[ServiceInfo] = None
        self._lock = ServiceLock(self.bench_path)
        self._stop: Optional[asyncio.Event] = None
        self._hurry: Optional[asyncio.Event] = None
        self._signal: Optional[int] = None
        self._signals_installed: list[int] = []
        self._loop: Optional[asyncio.AbstractEventLoop] = None
        self.on_usr1: Optional[Callable[[], None]] = None
        self._final: dict = {}          # the counters of what has closed

    # ---- starting -------------------------------------------------------------------------
    async def start(self) -> ServiceInfo:
        """Takes the bench (see the module doc for the order); raises ServedElsewhere when
        another service holds it, and leaves nothing behind when any step fails."""
        self._loop = asyncio.get_running_loop()
        self._stop = asyncio.Event()
        self._hurry = asyncio.Event()
        self._install_signals()         # before any transport opens: a signal meanwhile still stops cleanly
        self._lock.acquire()
        try:
            if self.http is not None:
                _require("aiohttp", WEB_EXTRA_HINT)
            if self.epics:
                _require("caproto", EPICS_EXTRA_HINT)
                if self.prefix is None:
                    self.prefix = file_prefix(self.bench_path) or default_prefix(self.bench_path)
            self._clear_stale_socket()
            from .. import aio

            log.info("serve: opening %s%s", self.bench_path, " (simulated twin)" if self.sim else "")
            self.bench = await aio.Bench.load(self.bench_path, sim=self.sim)
            env: dict = {}
            if self.epics:
                from . import epics as ca_face

                calibration = os.path.splitext(self.bench_path)[0] + ".epics.json"
                if hasattr(ca_face, "set_server_environment"):
                    ca_face.set_server_environment(self.interfaces, self.ca_port)
                self.ca = await ca_face.start_ca(self.bench, prefix=self.prefix, interfaces=self.interfaces,
                                                 port=self.ca_port, calibration_path=calibration)
                self.ca_port = getattr(self.ca, "port", self.ca_port)
                env = dict(self.ca.client_env())
            info = ServiceInfo(pid=os.getpid(), bench=self.bench_path, socket=self.socket_path, sim=self.sim,
                               prefix=self.prefix if self.epics else None,
                               ca_port=self.ca_port if self.epics else None,
                               interfaces=list(self.interfaces) if self.epics else [], env=env,
                               links=self._links())
            from . import rpc

            self.rpc = await rpc.start_rpc(self.bench, self.socket_path, info=_info_dict(info))
            if self.http is not None:
                from . import web

                self.web = await web.start_web(self.bench, *self.http, bench_path=self.bench_path, sim=self.sim,
                                               allow_motion=self.allow_motion, counters=self.counters)
                info.http = self.web.url
            self._lock.publish(info)
            register(self.bench_path)
            self.info = info
            return info
        except BaseException:
            await self._close_everything()
            raise

    def unarmed_watchdogs(self) -> list:
        """The axes whose drive has a link-loss watchdog (Capability.WATCHDOG) the bench file
        does not arm (``options.watchdog``): a killed service leaves them running."""
        from ..drive import Capability

        out = []
        for name, d in self.bench.axes.items():
            cfg = self.bench.sync.config.get(name)
            if Capability.WATCHDOG in d.capabilities and not (cfg is not None and cfg.options.get("watchdog")):
                out.append(name)
        return out

    def _links(self) -> list:
        """The bus specs and serial ports the bench opened (as opened: under sim, the
        twin's ptys and socketcand servers)."""
        sync = self.bench.sync
        links = [cfg.get("spec") for cfg in getattr(sync, "_bus_cfg", {}).values()]
        links += [cfg.get("port") for cfg in getattr(sync, "_line_cfg", {}).values()]
        return [str(x) for x in links if x]

    def _clear_stale_socket(self) -> None:
        """Checked before the bench opens: a socket file left by a service that died is
        removed; one a live process answers on (another bench's service given the same
        --socket) or a file that is not a socket is refused, not removed."""
        import socket

        try:
            st = os.lstat(self.socket_path)
        except FileNotFoundError:
            return
        if not stat.S_ISSOCK(st.st_mode):
            raise _core.InvalidArgument(f"motorbus serve: --socket {self.socket_path}: exists and is not a "
                                        f"socket (give another path)")
        probe = socket.socket(socket.AF_UNIX, socket.SOCK_STREAM)
        try:
            probe.settimeout(1.0)
            probe.connect(self.socket_path)
        except OSError:
            os.unlink(self.socket_path)       # nobody answers: a dead service's
            return
        finally:
            probe.close()
        raise _core.InvalidArgument(f"motorbus serve: --socket {self.socket_path}: another service answers there "
                                    f"(give another path)")

    def _install_signals(self) -> None:
        assert self._loop is not None
        if threading_main():
            for sig in SIGNALS:
                try:
                    self._loop.add_signal_handler(sig, self.request_stop, sig)
                    self._signals_installed.append(sig)
                except (ValueError, RuntimeError, NotImplementedError):   # not the main thread's loop
                    pass
            if hasattr(signal, "SIGUSR1"):
                try:
                    self._loop.add_signal_handler(signal.SIGUSR1, self._usr1)
                    self._signals_installed.append(signal.SIGUSR1)
                except (ValueError, RuntimeError, NotImplementedError):
                    pass

    def _usr1(self) -> None:
        if self.on_usr1 is not None:
            self.on_usr1()

    # ---- running and stopping ------------------------------------------------------------
    def request_stop(self, signum: Optional[int] = None) -> None:
        """Ends ``run()`` (a signal handler, or another task of the loop)."""
        if signum is not None and self._signal is None:
            self._signal = signum
        if self._stop is not None:
            if self._stop.is_set() and self._hurry is not None:
                self._hurry.set()     # a second signal: quick stops now, no more waiting for rest
            self._stop.set()

    @property
    def stopped_by(self) -> Optional[int]:
        """The signal that ended the service (None: request_stop() or not ended)."""
        return self._signal

    async def run(self) -> None:
        """Serves until a signal (or request_stop()), then shuts down (module doc)."""
        if self._stop is None:
            raise _core.ClosedError("BenchService.run: start() first")
        try:
            await self._stop.wait()
        finally:
            await self.shutdown()

    async def stop_all(self) -> list:
        """Stops every axis now (the bench's stop_all: each stop ahead of queued exchanges)."""
        if self.bench is None:
            return []
        failures = await self.bench.stop_all("stop")
        for name, e in failures:
            log.warning("serve: %s: stop failed: %s: %s", name, type(e).__name__, e)
        return failures

    async def shutdown(self) -> None:
        """Stop, close the faces, stop again, wait for rest, close (module doc)."""
        if self.bench is not None:
            await self._safely(self.stop_all(), "stop every axis")
        await self._close_faces()
        if self.bench is not None:
            await self._safely(self.stop_all(), "stop every axis again")
            await self._settle()
        await self._close_everything()

    async def _settle(self) -> None:
        """Each axis gets STOP_WAIT s to come to rest after the shutdown's stop; one that does
        not -- or every axis still moving when a second signal comes -- gets a quick stop."""
        from ..drive import MoveFailed

        async def at_rest(d: Any) -> bool:
            """True at rest (or its move ended, as it may), False on the second signal."""
            wait = asyncio.ensure_future(d.wait_idle(timeout=STOP_WAIT, stop_on_cancel=False))
            hurried = asyncio.ensure_future(self._hurry.wait()) if self._hurry is not None else None
            try:
                await asyncio.wait({wait} | ({hurried} if hurried else set()), return_when=asyncio.FIRST_COMPLETED)
            finally:
                if hurried is not None:
                    hurried.cancel()
            if not wait.done():
                wait.cancel()
                return False
            wait.result()
            return True

        async def one(name: str, d: Any) -> None:
            try:
                if await at_rest(d):
                    return
                why = "a second signal"
            except MoveFailed as e:
                # The move the stop cut short ended as it says; only a motor still moving needs more.
                if type(e).__name__ != "MoveTimedOut":
                    return
                why = f"not at rest {STOP_WAIT:g} s after the stop"
            except Exception as e:  # noqa: BLE001 - a link gone: nothing more this process can do
                log.warning("serve: %s: waiting for rest: %s: %s", name, type(e).__name__, e)
                return
            log.warning("serve: %s: %s: quick stop", name, why)
            await self._safely(d.quick_stop(), f"{name}: quick stop")

        await asyncio.gather(*(one(n, d) for n, d in self.bench.axes.items() if not d.closed))

    async def _safely(self, aw: Any, what: str) -> None:
        try:
            await aw
        except Exception as e:  # noqa: BLE001 - the shutdown must go on
            log.warning("serve: %s: %s: %s", what, type(e).__name__, e)

    async def _close_faces(self) -> None:
        for attr in ("web", "rpc", "ca"):      # the page first: its sockets say the service is going
            face = getattr(self, attr)
            setattr(self, attr, None)
            if face is None:
                continue
            self._final[attr] = dict(getattr(face, "counters", {}) or {})
            try:
                await asyncio.wait_for(face.close(), FACE_CLOSE_WAIT)
            except Exception as e:  # noqa: BLE001 - the other face and the bench must still close
                log.warning("serve: closing the %s face: %s: %s", attr, type(e).__name__, e)

    async def _close_everything(self) -> None:
        await self._close_faces()
        if self.bench is not None:
            self._final["sdo"] = self._sdo_counters()
        bench, self.bench = self.bench, None
        if bench is not None:
            try:
                await bench.aclose()
            except Exception as e:  # noqa: BLE001 - the lock must still go
                log.warning("serve: closing the bench: %s: %s", type(e).__name__, e)
        if self.info is not None:
            unregister(self.bench_path)
        self._lock.release()
        try:
            if self.info is not None and os.path.exists(self.socket_path):
                os.unlink(self.socket_path)
        except OSError:
            pass
        if self._loop is not None:
            for sig in self._signals_installed:
                try:
                    self._loop.remove_signal_handler(sig)
                except (ValueError, RuntimeError):
                    pass
            self._signals_installed = []

    # ---- what it did -----------------------------------------------------------------------
    def counters(self) -> dict:
        """The faces' counters and, per CANopen axis, its SDO client's: aborts and timeouts
        there are the collisions one owner process is for (docs/serve.md)."""
        out: dict = dict(self._final)
        if self.rpc is not None:
            out["rpc"] = dict(getattr(self.rpc, "counters", {}) or {})
        if self.ca is not None:
            out["ca"] = dict(getattr(self.ca, "counters", {}) or {})
        if self.web is not None:
            out["web"] = dict(self.web.counters)
        if self.bench is not None:
            out["sdo"] = self._sdo_counters()
        out.setdefault("sdo", {})
        return out

    def _sdo_counters(self) -> dict:
        sdo: dict = {}
        for name, d in self.bench.axes.items():
            c = _sdo_client_counters(d.sync)
            if c is None:
                continue
            sdo[name] = {k: int(getattr(c, k)) for k in ("transfers", "timeouts", "aborts_sent", "aborts_received",
                                                         "foreign_responses", "ignored_frames")}
        return sdo

    def report_counters(self, stream: Any = None) -> None:
        """One line ``counters {json}`` (stderr by default; SIGUSR1 and the end of
        ``motorbus serve`` print it)."""
        print(f"counters {json.dumps(self.counters(), sort_keys=True)}", file=stream or sys.stderr, flush=True)


def _sdo_client_counters(drive: Any) -> Any:
    """The SdoClientCounters of a CANopen axis's SDO client (the Drive's own, or its native
    client's), or None for a kind that talks no SDO."""
    native = getattr(drive, "native", None)
    sdo = getattr(native, "sdo", None)
    for client in (getattr(drive, "_sdo", None), getattr(sdo, "client", None), sdo):
        c = getattr(client, "counters", None)
        if c is not None and hasattr(c, "foreign_responses"):
            return c
    return None


def _info_dict(info: ServiceInfo) -> dict:
    import dataclasses

    return dataclasses.asdict(info)


def threading_main() -> bool:
    import threading

    return threading.current_thread() is threading.main_thread()
