"""What the web page of ``motorbus serve --http`` costs the service: its CPU with 0, 1 and 5
browsers open, at rest and with axes moving.

The service is ``motorbus serve <the demo bench> --sim --no-epics`` in a child process (its
seven simulated drives live in it, so every phase includes their CPU), once without
``--http`` for scale and once with it.  Its CPU is read from /proc/<pid>/stat (utime +
stime) over each phase and shown as a share of one core (CPU time / wall time).  The
browsers are Debian's chromium, headless, each its own selenium session (chromedriver):
each page holds a websocket and redraws its table and plots.  In the moving phases this
process moves x and y (the two arcus axes on one RS-485 line) back and forth through the
service's native face (``motorbus.Bench.connect``), so positions change at every sample
and the page gets every update it may (20 a second).  The reference is the same service
without the page: what the page costs is the difference, and per browser the difference
between 5 browsers and none, divided by 5.

    .venv/bin/python bench/web_cpu.py [--seconds 10]
"""
from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import threading
import time
from importlib import resources
from typing import Any, Optional

BROWSERS = 5


def cpu_seconds(pid: int) -> float:
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def tree_cpu_seconds(root: int) -> float:
    """CPU of ``root`` and every process below it (a chromium is a dozen processes)."""
    children: dict[int, list[int]] = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    ppid = int(f.read().rsplit(")", 1)[1].split()[1])
                children.setdefault(ppid, []).append(int(entry))
            except (OSError, ValueError):
                pass
    total, todo = 0.0, [root]
    while todo:
        pid = todo.pop()
        try:
            total += cpu_seconds(pid)
        except OSError:
            pass
        todo += children.get(pid, [])
    return total


class Service:
    def __init__(self, bench: str, http: bool) -> None:
        cmd = [sys.executable, "-m", "motorbus", "serve", bench, "--sim", "--no-epics"]
        if http:
            cmd += ["--http", "127.0.0.1:0"]
        self.proc = subprocess.Popen(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
        self.url: Optional[str] = None
        for line in self.proc.stdout:
            if line.startswith("http "):
                self.url = line.split()[1]
            if line.startswith("ready"):
                return
        raise SystemExit(f"motorbus serve ended: {self.proc.wait()}: {self.proc.stderr.read()}")

    def cpu(self) -> float:
        return cpu_seconds(self.proc.pid)

    def close(self) -> dict:
        self.proc.terminate()
        _out, err = self.proc.communicate(timeout=60)
        for line in err.splitlines():
            if line.startswith("counters "):
                return json.loads(line[len("counters "):])
        return {}


def browser(url: str) -> Any:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service as DriverService

    os.environ["SE_OFFLINE"] = "true"
    options = webdriver.ChromeOptions()
    options.binary_location = shutil.which("chromium") or "/usr/bin/chromium"
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu",
                "--window-size=1400,1100", "--no-first-run", "--disable-extensions"):
        options.add_argument(arg)
    driver = webdriver.Chrome(options=options, service=DriverService(
        executable_path=shutil.which("chromedriver") or "/usr/bin/chromedriver"))
    driver.get(url)
    deadline = time.monotonic() + 20
    while driver.execute_script("return document.body.dataset.connection") != "live":
        if time.monotonic() > deadline:
            raise SystemExit("the page never went live")
        time.sleep(0.1)
    return driver


class Mover:
    """x and y back and forth through the service, until stopped."""

    def __init__(self, bench: str) -> None:
        import motorbus

        self.remote = motorbus.Bench.connect(bench)
        for a in ("x", "y"):
            self.remote[a].enable()
        self.moves = 0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        target = 20.0
        while not self._stop.is_set():
            self.remote.move_together({"x": target, "y": target}, wait=True)
            self.moves += 2
            target = 0.0 if target else 20.0

    def close(self) -> None:
        self._stop.set()
        self._thread.join(30)
        self.remote.close()


def measure(service: Service, seconds: float, browsers: list) -> tuple[float, float]:
    """(service share of a core, browsers' share) over ``seconds``."""
    c0, b0, t0 = service.cpu(), sum(tree_cpu_seconds(b.service.process.pid) for b in browsers), time.monotonic()
    time.sleep(seconds)
    c1, b1, t1 = service.cpu(), sum(tree_cpu_seconds(b.service.process.pid) for b in browsers), time.monotonic()
    return (c1 - c0) / (t1 - t0), (b1 - b0) / (t1 - t0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seconds", type=float, default=10.0, help="seconds per phase")
    args = ap.parse_args()
    if not (shutil.which("chromium") or os.path.exists("/usr/bin/chromium")):
        print(json.dumps({"bench": "web_cpu", "error": "chromium not installed (make test-deps)"}))
        return
    tmp = tempfile.mkdtemp()
    bench = os.path.join(tmp, "demo_bench.toml")
    with resources.as_file(resources.files("motorbus").joinpath("demo_bench.toml")) as src:
        shutil.copy(src, bench)
    results: dict[str, float] = {}
    browsers_cpu: dict[str, float] = {}
    print(f"service CPU (CPU time / wall, share of one core), the demo bench's 7 simulated axes, "
          f"{args.seconds:.0f} s per phase")

    def phase(label: str, service: Service, open_browsers: list) -> None:
        share, btotal = measure(service, args.seconds, open_browsers)
        results[label] = share
        if open_browsers:
            browsers_cpu[label] = btotal
        extra = f"   (the {len(open_browsers)} browsers: {btotal * 100:.0f} %)" if open_browsers else ""
        print(f"{label:44s} {share * 100:6.1f} % of a core{extra}", flush=True)

    service = Service(bench, http=False)
    phase("no --http, at rest", service, [])
    mover = Mover(bench)
    phase("no --http, x and y moving", service, [])
    mover.close()
    service.close()

    service = Service(bench, http=True)
    opened: list = []
    try:
        phase("--http, 0 browsers, at rest", service, opened)
        opened.append(browser(service.url))
        phase("--http, 1 browser, at rest", service, opened)
        while len(opened) < BROWSERS:
            opened.append(browser(service.url))
        phase(f"--http, {BROWSERS} browsers, at rest", service, opened)
        mover = Mover(bench)
        phase(f"--http, {BROWSERS} browsers, x and y moving", service, opened)
        for b in opened:
            b.quit()
        opened = []
        phase("--http, 0 browsers, x and y moving", service, opened)
        mover.close()
    finally:
        for b in opened:
            b.quit()
        counters = service.close()
    web = counters.get("web", {})
    rest_per = (results[f"--http, {BROWSERS} browsers, at rest"] - results["--http, 0 browsers, at rest"]) / BROWSERS
    move_per = (results[f"--http, {BROWSERS} browsers, x and y moving"]
                - results["--http, 0 browsers, x and y moving"]) / BROWSERS
    print(f"per browser: +{rest_per * 100:.2f} points of a core at rest, +{move_per * 100:.2f} moving "
          f"(updates sent: {web.get('updates_sent')}, pages served: {web.get('browsers_total')})")
    print(json.dumps({"bench": "web_cpu", "seconds": args.seconds, "browsers": BROWSERS,
                      "service_share": {k: round(v, 4) for k, v in results.items()},
                      "browsers_share": {k: round(v, 4) for k, v in browsers_cpu.items()},
                      "per_browser_rest": round(rest_per, 4), "per_browser_moving": round(move_per, 4),
                      "web_counters": web}))


if __name__ == "__main__":
    main()
