"""The web face of ``motorbus serve BENCH --http [HOST:]PORT`` (docs/web.md).

One page (``serve/web/``: index.html, app.js, style.css, shipped in the wheel) shows the
served bench live: every axis' position, velocity, state, fault and its reason, the last
move's outcome, identity and kind; the last minute of positions and of each CAN bus' load;
the service's counters.  It is served by aiohttp on the service's one event loop, so every
drive call goes through the same ``aio.Bench`` as the other faces.

What it costs the drives does not depend on how many browsers look:

* one ``Sampler`` reads the bench for every browser: the positions from one C++
  ``Poller`` (``POSITION_HZ``), the status of each axis through the Drive API
  (``STATUS_HZ``; it also judges a move nobody waited for, so its outcome shows), each
  CAN bus' load from the bus' own bit counters (no listener per frame);
* it makes one JSON update when something changed (or once a second), at most
  ``UPDATE_HZ`` a second, encoded once and handed to every browser's socket.  A slow
  browser gets the latest update, never a backlog; a browser that goes away leaves
  nothing behind (its sender task ends with its socket).

A STOP per axis and a STOP ALL are plain HTTP POSTs (``/api/axes/NAME/stop``,
``/api/stop``) that work whatever the page's websocket does, from any HTTP client.  Motion
(move, jog, home, enable, disable, clear) is refused with 403 unless the service was
started with ``--allow-motion``, and then only as a JSON POST: a page of another origin
cannot send one (the browser's CORS preflight is never answered).
"""
from __future__ import annotations

import asyncio
import collections
import contextlib
import json
import logging
import math
import os
import re
import time
from importlib import resources
from typing import Any, Awaitable, Callable, Optional

from .. import _core

log = logging.getLogger(__name__)

__all__ = ["WebFace", "start_web", "parse_http_address", "POSITION_HZ", "STATUS_HZ", "UPDATE_HZ", "HISTORY_S"]

#: Updates a second, at most, to each browser (coalesced: the latest state, never a backlog).
UPDATE_HZ = 20.0
#: The face's one Poller of the positions.
POSITION_HZ = 20.0
#: Status reads of every axis a second (they judge moves nobody waits for).
STATUS_HZ = 5.0
#: Seconds of positions and bus loads a page that opens is given, sampled at HISTORY_HZ.
HISTORY_S = 60.0
HISTORY_HZ = 10.0
#: Seconds of polled positions a velocity is taken over.
VELOCITY_WINDOW = 0.2
#: With nothing changing, an update still goes out this often (the page's clock and counters).
KEEPALIVE_S = 1.0
#: The CAN bit rate a load is a share of when the bench file gives none (CiA 301's most common).
DEFAULT_BITRATE = 500_000
#: A status read that takes longer than this leaves the axis' last values, with the error said.
STATUS_TIMEOUT = 2.0
#: Bodies larger than this are refused (a JSON POST of the page is a few dozen bytes).
MAX_BODY = 4096
#: The commands that move or power an axis: refused (403) without --allow-motion.
MOTION_VERBS = ("move", "jog", "home", "enable", "disable", "clear")

_ASSETS = {"index.html": "text/html", "app.js": "text/javascript", "style.css": "text/css"}


def parse_http_address(text: str) -> tuple[str, int]:
    """``--http`` argument: ``PORT`` (on 127.0.0.1) or ``HOST:PORT`` (``[::1]:PORT`` for IPv6);
    InvalidArgument naming what is wrong."""
    if not isinstance(text, str) or not text.strip():
        raise _core.InvalidArgument("motorbus serve --http: [HOST:]PORT, e.g. 8080 or 0.0.0.0:8080")
    text = text.strip()
    host, sep, port = text.rpartition(":")
    if not sep:
        host, port = "127.0.0.1", text
    host = host[1:-1] if host.startswith("[") and host.endswith("]") else host
    if not host:
        raise _core.InvalidArgument(f"motorbus serve --http {text!r}: a host before ':' (or only the port)")
    if not port.isdigit() or not 0 <= int(port) <= 65535:
        raise _core.InvalidArgument(f"motorbus serve --http {text!r}: the port is a number 0..65535 "
                                    f"(0: any free port), not {port!r}")
    return host, int(port)


def _json_number(v: Any) -> Optional[float]:
    """A float JSON can carry (NaN/inf are not JSON): None instead."""
    return float(v) if isinstance(v, (int, float)) and math.isfinite(v) else None


def _error_text(e: BaseException) -> str:
    return f"{type(e).__name__}: {e}"


def _bus_bitrates(bench_path: str, names: list) -> dict:
    """Each bus' bit rate from the bench file's spec (``bitrate=``), else DEFAULT_BITRATE
    and ``assumed``: a load is said as a share of a rate the page names."""
    from ..bench import parse_file
    from ..bus import parse_spec

    out = {}
    try:
        _text, data = parse_file(bench_path)
        buses = data.get("bus", {}) if isinstance(data, dict) else {}
    except Exception:  # noqa: BLE001 - the bench opened from this file: a reread failing only loses the rates
        buses = {}
    for name in names:
        rate = 0
        spec = buses.get(name, {}).get("spec") if isinstance(buses.get(name), dict) else None
        if isinstance(spec, str):
            with contextlib.suppress(Exception):
                rate = int(parse_spec(spec)[1].get("bitrate") or 0)
        out[name] = (rate, False) if rate > 0 else (DEFAULT_BITRATE, True)
    return out


class Sampler:
    """Reads the bench for every browser at once (module doc) and keeps the latest update,
    encoded once, and the last HISTORY_S seconds of positions and bus loads."""

    def __init__(self, bench: Any, buses: dict, bitrates: dict, counters: Callable[[], dict],
                 live_counters: Callable[[], dict] = dict) -> None:
        self.bench, self.buses, self.bitrates = bench, buses, bitrates
        self._counters, self._live_counters = counters, live_counters
        self.names = list(bench.axes)
        self.t0 = time.monotonic()
        self.axes: dict[str, dict] = {n: {"position": None, "velocity": None, "enabled": False, "moving": False,
                                          "at_target": False, "homed": False, "limit_positive": False,
                                          "limit_negative": False, "fault": False, "text": "", "error": None,
                                          "last_move": None} for n in self.names}
        self.bus_load: dict[str, dict] = {b: {"load": None, "bits_per_s": None} for b in buses}
        self._positions: dict[str, collections.deque] = {n: collections.deque(maxlen=64) for n in self.names}
        self._bits_seen: dict[str, tuple[float, int]] = {}
        self.history: collections.deque = collections.deque(maxlen=int(HISTORY_S * HISTORY_HZ))
        self.update_json = ""           # the latest update, encoded once for every browser
        self.version = 0
        self._changed = asyncio.Event()
        self._tasks: list[asyncio.Task] = []
        self._poller: Any = None
        self.poll_error: Optional[str] = None     # set when the position poll ended
        self._counter_cache: tuple[float, dict] = (-math.inf, {})

    def now(self) -> float:
        return round(time.monotonic() - self.t0, 3)

    # ---- running ----------------------------------------------------------------------------
    async def start(self) -> None:
        from ..poller import Poller

        drives = {n: self.bench[n].sync for n in self.names}
        # Setting a poll up may map PDOs by SDO: off the loop, as the native face starts its polls.
        self._poller = await asyncio.to_thread(Poller, drives, ("position",), POSITION_HZ, keep=0)
        self._tasks = [asyncio.ensure_future(c) for c in (self._read_positions(), self._read_statuses(),
                                                          self._publish())]

    async def close(self) -> None:
        for t in self._tasks:
            t.cancel()
        for t in self._tasks:
            with contextlib.suppress(BaseException):
                await t
        self._tasks = []
        if self._poller is not None:
            poller, self._poller = self._poller, None
            await asyncio.to_thread(poller.stop)

    async def wait_update(self, seen: int) -> int:
        """The version of an update newer than ``seen`` (waits for one)."""
        while self.version == seen:
            await self._changed.wait()
        return self.version

    async def _read_positions(self) -> None:
        try:
            await self._follow_poll()
        finally:
            # The poll ended (a link failed: its stats say why): the last positions are no
            # longer where the axes are, so the page shows none, and the reason.
            why = "; ".join(f"{g}: {st.get('error_type')}: {st.get('error')}"
                            for g, st in (self._poller.stats or {}).items() if st.get("error")) \
                if self._poller is not None else ""
            self.poll_error = f"the position poll ended{': ' + why if why else ''}"
            for a in self.axes.values():
                a.update(position=None, velocity=None, error=self.poll_error)

    async def _follow_poll(self) -> None:
        async for chunk in self._poller.chunks(1):
            for name in self.names:
                ts, ps = chunk.get(f"{name}.t", chunk.get("t")), chunk.get(f"{name}.position")
                if ts is None or ps is None:
                    continue
                for t, p in zip(ts[-16:], ps[-16:]):
                    if math.isfinite(p):
                        self._positions[name].append((float(t), float(p)))
                h = self._positions[name]
                if h:
                    self.axes[name]["position"] = h[-1][1]
                    self.axes[name]["velocity"] = self._velocity(h)

    @staticmethod
    def _velocity(h: collections.deque) -> Optional[float]:
        t1, p1 = h[-1]
        for t0, p0 in reversed(h):
            if t1 - t0 >= VELOCITY_WINDOW:
                return (p1 - p0) / (t1 - t0)
        t0, p0 = h[0]
        return (p1 - p0) / (t1 - t0) if t1 > t0 else None

    async def _read_statuses(self) -> None:
        period = 1.0 / STATUS_HZ
        while True:
            started = time.monotonic()
            await asyncio.gather(*(self._read_status(n) for n in self.names))
            self._read_bus_loads()
            await asyncio.sleep(max(0.0, period - (time.monotonic() - started)))

    async def _read_status(self, name: str) -> None:
        d = self.bench[name]
        a = self.axes[name]
        try:
            st = await asyncio.wait_for(d.sync._co_status(), STATUS_TIMEOUT)
        except asyncio.TimeoutError:
            a["error"] = f"TimeoutError: no status within {STATUS_TIMEOUT:g} s"
            return
        except Exception as e:  # noqa: BLE001 - the page says why this axis could not be read
            a["error"] = _error_text(e)
            return
        a.update(enabled=st.enabled, moving=st.moving, at_target=st.at_target, homed=st.homed,
                 limit_positive=st.limit_positive, limit_negative=st.limit_negative, fault=st.fault,
                 text=st.text or "", error=self.poll_error, last_move=_outcome(st.last_move))

    def _read_bus_loads(self) -> None:
        now = time.monotonic()
        for name, bus in self.buses.items():
            try:
                c = bus.counters
                bits = int(c.rx_bits) + int(c.tx_bits)
            except Exception:  # noqa: BLE001 - a closed bus has no load to show
                self.bus_load[name] = {"load": None, "bits_per_s": None}
                continue
            seen = self._bits_seen.get(name)
            self._bits_seen[name] = (now, bits)
            if seen is None or now <= seen[0]:
                continue
            rate = (bits - seen[1]) / (now - seen[0])
            self.bus_load[name] = {"load": round(100.0 * rate / self.bitrates[name][0], 2),
                                   "bits_per_s": round(rate)}

    def counters(self) -> dict:
        """The service's counters, asked at most once a second (they walk every SDO client),
        with the live ones (this face's) as they are now."""
        at, cached = self._counter_cache
        if time.monotonic() - at >= 1.0:
            cached = self._counters()
            self._counter_cache = (time.monotonic(), cached)
        return {**cached, **self._live_counters()}

    async def _publish(self) -> None:
        period, last_json, last_sent, next_history = 1.0 / UPDATE_HZ, "", -math.inf, 0.0
        while True:
            started = time.monotonic()
            body = {"axes": self.axes, "buses": self.bus_load, "counters": self.counters()}
            text = json.dumps(body, sort_keys=True)
            if text != last_json or started - last_sent >= KEEPALIVE_S:
                last_json, last_sent = text, started
                self.update_json = json.dumps({"type": "update", "t": self.now(), **body})
                self.version += 1
                self._changed.set()
                self._changed = asyncio.Event()
            if started >= next_history:
                next_history = started + 1.0 / HISTORY_HZ
                self.history.append((self.now(), {n: _json_number(a["position"]) for n, a in self.axes.items()},
                                     {b: v["load"] for b, v in self.bus_load.items()}))
            await asyncio.sleep(max(0.0, period - (time.monotonic() - started)))

    def history_json(self) -> dict:
        rows = list(self.history)
        return {"t": [r[0] for r in rows],
                "axes": {n: [r[1].get(n) for r in rows] for n in self.names},
                "buses": {b: [r[2].get(b) for r in rows] for b in self.buses}}


def _product(drive: Any) -> str:
    """What the drive is, from its kind's description without the details (the kind's
    own words, not asked of the drive: the product, before its details)."""
    text = getattr(type(drive), "description", "") or drive.kind
    text = re.sub(r"\s*\([^)]*\)", "", text)
    return re.split(r"[,;]", text, maxsplit=1)[0].strip() or drive.kind


def _outcome(last: Any) -> Optional[dict]:
    if last is None:
        return None
    return {"what": last.what, "target": _json_number(last.target), "position": _json_number(last.position),
            "state": last.state, "reason": last.reason or "", "ok": last.ok}


class WebFace:
    """The running web face: ``url``, ``counters`` (browsers, browsers_total, updates_sent,
    http_posts, stops, refused), ``close()``."""

    def __init__(self, bench: Any, *, bench_path: str, sim: bool, allow_motion: bool,
                 counters: Callable[[], dict]) -> None:
        self.bench, self.bench_path, self.sim, self.allow_motion = bench, bench_path, sim, allow_motion
        self.counters: dict[str, int] = dict.fromkeys(
            ("browsers", "browsers_total", "updates_sent", "http_posts", "stops", "refused"), 0)
        buses = dict(getattr(bench.sync, "buses", {}) or {})
        self.bitrates = _bus_bitrates(bench_path, list(buses))
        self.sampler = Sampler(bench, buses, self.bitrates, counters, lambda: {"web": dict(self.counters)})
        self.url = ""
        self._runner: Any = None
        self._sockets: set = set()
        self._commands: set[asyncio.Task] = set()

    # ---- what a page is told once ------------------------------------------------------------
    def describe(self) -> dict:
        sync = self.bench.sync
        axes = []
        for name, d in self.bench.axes.items():
            cfg = sync.config.get(name)
            where = (f"line {cfg.line}" if cfg.line else f"bus {cfg.bus}") + f", address {cfg.address}" \
                if cfg is not None else ""
            axes.append({"name": name, "kind": d.kind, "units": d.units.name,
                         "identity": _product(d.sync) + (" (simulated)" if self.sim else ""), "where": where})
        return {"bench": os.path.basename(self.bench_path), "pid": os.getpid(), "sim": self.sim,
                "allow_motion": self.allow_motion, "rate_hz": UPDATE_HZ, "history_s": HISTORY_S, "axes": axes,
                "buses": [{"name": b, "bitrate": rate, "bitrate_assumed": assumed}
                          for b, (rate, assumed) in self.bitrates.items()]}

    # ---- serving -----------------------------------------------------------------------------
    async def start(self, host: str, port: int) -> str:
        from aiohttp import web

        app = web.Application(client_max_size=MAX_BODY)
        app.router.add_get("/", self._asset("index.html"))
        for name in ("app.js", "style.css"):
            app.router.add_get(f"/static/{name}", self._asset(name))
        app.router.add_get("/api/bench", self._get_bench)
        app.router.add_get("/ws", self._websocket)
        app.router.add_post("/api/stop", self._stop_all)
        app.router.add_post("/api/axes/{axis}/stop", self._stop_one)
        for verb in MOTION_VERBS:
            app.router.add_post(f"/api/axes/{{axis}}/{verb}", self._motion(verb))
        await self.sampler.start()
        self._runner = web.AppRunner(app, access_log=None, handle_signals=False, shutdown_timeout=1.0)
        await self._runner.setup()
        site = web.TCPSite(self._runner, host, port, reuse_address=True)
        try:
            await site.start()
        except OSError as e:
            await self.close()
            raise _core.InvalidArgument(f"motorbus serve --http {host}:{port}: cannot listen there: "
                                        f"{e.strerror or e}") from None
        bound_host, bound_port = self._runner.addresses[0][:2]
        self.url = f"http://{'[' + bound_host + ']' if ':' in bound_host else bound_host}:{bound_port}/"
        return self.url

    async def close(self) -> None:
        """Every page's socket closes with 1001 (going away: the page says the service is
        gone), the commands it started are let go, the sampler and the server end."""
        from aiohttp import WSCloseCode

        await asyncio.gather(*(asyncio.wait_for(ws.close(code=WSCloseCode.GOING_AWAY, message=b"service ends"), 1.0)
                               for ws in list(self._sockets)), return_exceptions=True)   # together: 1 s at most
        for t in list(self._commands):
            t.cancel()
        await self.sampler.close()
        if self._runner is not None:
            runner, self._runner = self._runner, None
            await runner.cleanup()

    def _asset(self, name: str) -> Callable[[Any], Awaitable[Any]]:
        from aiohttp import web

        body = resources.files("motorbus.serve").joinpath("web", name).read_bytes()

        async def handler(request: Any) -> Any:
            return web.Response(body=body, content_type=_ASSETS[name], charset="utf-8",
                                headers={"Cache-Control": "no-cache"})
        return handler

    async def _get_bench(self, request: Any) -> Any:
        from aiohttp import web

        return web.json_response(self.describe())

    async def _websocket(self, request: Any) -> Any:
        from aiohttp import WSMsgType, web

        ws = web.WebSocketResponse(heartbeat=10.0, max_msg_size=MAX_BODY)
        await ws.prepare(request)
        self._sockets.add(ws)
        self.counters["browsers"] += 1
        self.counters["browsers_total"] += 1
        sender = asyncio.ensure_future(self._send_updates(ws))
        try:
            async for msg in ws:        # the page sends nothing; this sees it leave
                if msg.type == WSMsgType.ERROR:
                    break
        finally:
            sender.cancel()
            with contextlib.suppress(BaseException):
                await sender
            self._sockets.discard(ws)
            self.counters["browsers"] -= 1
        return ws

    async def _send_updates(self, ws: Any) -> None:
        """The hello, then the latest update whenever there is a newer one, at most
        UPDATE_HZ a second: a browser that reads slowly skips updates, it never queues them."""
        hello = {"type": "hello", **self.describe(), "history": self.sampler.history_json()}
        try:
            await ws.send_str(json.dumps(hello))
            seen, period = -1, 1.0 / UPDATE_HZ
            while not ws.closed:
                seen = await self.sampler.wait_update(seen)
                sent_at = time.monotonic()
                await ws.send_str(self.sampler.update_json)
                self.counters["updates_sent"] += 1
                await asyncio.sleep(max(0.0, period - (time.monotonic() - sent_at)))
        except (ConnectionError, RuntimeError):   # the page went away mid-send
            pass

    # ---- commands ----------------------------------------------------------------------------
    def _origin(self, request: Any) -> str:
        peer = request.remote or "?"
        return f"the web page ({peer})"

    async def _stop_one(self, request: Any) -> Any:
        self.counters["http_posts"] += 1
        name = request.match_info["axis"]
        if name not in self.bench.axes:
            return _refuse(404, f"no axis {name!r} on this bench (axes: {', '.join(self.bench.axes)})")
        return await self._stop([name], f"STOP on {self._origin(request)}")

    async def _stop_all(self, request: Any) -> Any:
        self.counters["http_posts"] += 1
        return await self._stop(list(self.bench.axes), f"STOP ALL on {self._origin(request)}")

    async def _stop(self, names: list, by: str) -> Any:
        from aiohttp import web

        self.counters["stops"] += 1

        async def one(name: str) -> Optional[str]:
            d = self.bench[name]
            if d.closed:
                return None
            try:
                # ``by`` names the page in the outcome every program reads (drive.stopped_by_text)
                await d.sync._co_stop(by=by)
                return None
            except Exception as e:  # noqa: BLE001 - said in the reply, the other axes still stop
                return f"{name}: {_error_text(e)}"

        failed = [f for f in await asyncio.gather(*(one(n) for n in names)) if f]
        if failed:
            return web.json_response({"ok": False, "error": "; ".join(failed)}, status=500)
        return web.json_response({"ok": True, "stopped": names})

    def _motion(self, verb: str) -> Callable[[Any], Awaitable[Any]]:
        async def handler(request: Any) -> Any:
            self.counters["http_posts"] += 1
            if not self.allow_motion:
                self.counters["refused"] += 1
                return _refuse(403, f"{verb}: this service was started without --allow-motion: the web page "
                                    f"may only stop axes")
            if request.content_type != "application/json":
                self.counters["refused"] += 1
                return _refuse(415, f"{verb}: a JSON body (Content-Type: application/json)")
            name = request.match_info["axis"]
            if name not in self.bench.axes:
                return _refuse(404, f"no axis {name!r} on this bench (axes: {', '.join(self.bench.axes)})")
            try:
                body = await request.json() if request.can_read_body else {}
            except ValueError as e:
                return _refuse(400, f"{verb}: the body is not JSON: {e}")
            if not isinstance(body, dict):
                return _refuse(400, f"{verb}: the body is a JSON object, not {type(body).__name__}")
            try:
                start = _command(self.bench[name], verb, body)
            except _core.InvalidArgument as e:
                return _refuse(400, str(e))
            return await self._run_command(name, verb, start)
        return handler

    async def _run_command(self, name: str, verb: str, start: Awaitable[Any]) -> Any:
        """Runs a command; a move, jog or homing is accepted (202) once it has started, and
        goes on in the background: its outcome shows in the axis' ``last_move``."""
        from aiohttp import web

        task = asyncio.ensure_future(start)
        self._commands.add(task)
        task.add_done_callback(self._command_done(name, verb))
        done, _ = await asyncio.wait({task}, timeout=0.5 if verb in ("move", "home") else None)
        if task in done and task.exception() is not None:
            e = task.exception()
            status = 400 if isinstance(e, (_core.InvalidArgument, ValueError)) else 409
            return web.json_response({"ok": False, "error": _error_text(e)}, status=status)
        return web.json_response({"ok": True}, status=202)

    def _command_done(self, name: str, verb: str) -> Callable[[asyncio.Task], None]:
        def done(task: asyncio.Task) -> None:
            self._commands.discard(task)
            if not task.cancelled() and task.exception() is not None:
                # The outcome is in the axis' last_move, which every program and the page read.
                log.info("web: %s %s: %s", verb, name, _error_text(task.exception()))
        return done


def _command(d: Any, verb: str, body: dict) -> Awaitable[Any]:
    """The coroutine of one motion verb, its body checked (InvalidArgument naming the field)."""

    def number(key: str) -> float:
        v = body.get(key)
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
            raise _core.InvalidArgument(f"{verb}: {key!r} is a finite number in {d.units.name}, not {v!r}")
        return float(v)

    if verb == "move":
        if ("target" in body) == ("distance" in body):
            raise _core.InvalidArgument("move: one of 'target' (absolute) or 'distance' (relative), in "
                                        f"{d.units.name}")
        if "target" in body:
            return d.move_to(number("target"), stop_on_cancel=False)
        return d.move_by(number("distance"), stop_on_cancel=False)
    if verb == "jog":
        v = number("velocity")
        return d.sync._co_stop(by="jog 0 on the web page") if v == 0 else d.jog(v)
    if verb == "home":
        return d.home(stop_on_cancel=False)
    return {"enable": d.enable, "disable": d.disable, "clear": d.clear_faults}[verb]()


def _refuse(status: int, text: str) -> Any:
    from aiohttp import web

    return web.json_response({"ok": False, "error": text}, status=status)


async def start_web(bench: Any, host: str, port: int, *, bench_path: str, sim: bool = False,
                    allow_motion: bool = False, counters: Callable[[], dict] = dict) -> WebFace:
    """Starts the web face on ``host:port`` (0: a free port; ``face.url`` says which)."""
    face = WebFace(bench, bench_path=bench_path, sim=sim, allow_motion=allow_motion, counters=counters)
    await face.start(host, port)
    return face
