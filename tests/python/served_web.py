"""A `motorbus serve --sim --http` of the demo bench, run in this process from a thread
with its own event loop (the way the service runs it), so a test reaches the simulators
behind it -- to assert where a shaft stands, to make a drive fault -- while HTTP clients
and browsers talk to it over 127.0.0.1 as they would to `motorbus serve`."""
from __future__ import annotations

import asyncio
import os
import shutil
import threading
import time
from importlib import resources
from typing import Any

DEMO_BENCH = resources.files("motorbus").joinpath("demo_bench.toml")


class ServedWeb:
    def __init__(self, directory: str, *, allow_motion: bool = False) -> None:
        # A copy: the service's lock file lives next to its bench file, and another test
        # module may serve the demo bench at the same time.
        self.bench_path = os.path.join(directory, "demo_bench.toml")
        with resources.as_file(DEMO_BENCH) as src:
            shutil.copy(src, self.bench_path)
        self.socket_path = os.path.join(directory, "serve.sock")
        self.allow_motion = allow_motion
        self.loop = asyncio.new_event_loop()
        self.service: Any = None
        self._thread = threading.Thread(target=self.loop.run_forever, name="web-service", daemon=True)
        self._running: Any = None

    def start(self, timeout: float = 60.0) -> "ServedWeb":
        """Serves the twin, with the bench file's parameters applied (the demo's speeds, as
        `motorbus config BENCH apply` would) and every axis enabled."""
        from motorbus.serve.service import BenchService

        self._thread.start()

        async def open_() -> None:
            self.service = BenchService(self.bench_path, sim=True, epics=False, socket_path=self.socket_path,
                                        http=("127.0.0.1", 0), allow_motion=self.allow_motion)
            await self.service.start()
            self._running = asyncio.ensure_future(self.service.run())
            await self.service.bench.sync._co_apply()
            for d in self.service.bench.axes.values():
                await d.clear_faults()
                await d.enable()

        self.run(open_(), timeout)
        return self

    @property
    def url(self) -> str:
        return self.service.web.url

    @property
    def bench(self) -> Any:
        return self.service.bench          # the service's aio.Bench

    @property
    def sims(self) -> dict:
        return self.service.bench.sync.sims

    def shaft_mm(self, axis: str) -> float:
        """Where the axis' motor stands, in its units, read on its simulator (not the drive's word)."""
        from drive_kinds import KINDS

        cfg = self.bench.sync.config[axis]
        return KINDS[cfg.kind].shaft(self.sims[axis]) * cfg.units.scale

    def rest_mm(self, axis: str, timeout: float = 15.0) -> float:
        """Where the shaft stands once two reads 50 ms apart agree."""
        deadline = time.monotonic() + timeout
        at = self.shaft_mm(axis)
        while time.monotonic() < deadline:
            time.sleep(0.05)
            now, at = at, self.shaft_mm(axis)
            if now == at:
                return at
        raise AssertionError(f"{axis} still moves")

    def run(self, coro: Any, timeout: float = 30.0) -> Any:
        """Runs a coroutine on the service's loop; returns its result."""
        return asyncio.run_coroutine_threadsafe(coro, self.loop).result(timeout)

    def submit(self, coro: Any) -> Any:
        """Starts a coroutine on the service's loop (a concurrent.futures.Future)."""
        return asyncio.run_coroutine_threadsafe(coro, self.loop)

    def stop(self, timeout: float = 30.0) -> None:
        """What SIGTERM does: every axis stopped, the faces closed (the pages' sockets with
        1001), the bench let go."""
        if self.service is None or self._running is None:
            return
        self.loop.call_soon_threadsafe(self.service.request_stop)
        running, self._running = self._running, None

        async def ended() -> None:
            await running

        self.run(ended(), timeout)

    def close(self) -> None:
        try:
            self.stop()
        finally:
            self.loop.call_soon_threadsafe(self.loop.stop)
            self._thread.join(10)


def wait_until(predicate: Any, timeout: float = 10.0, what: str = "condition") -> Any:
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout:g} s waiting for {what}")
        time.sleep(0.02)
