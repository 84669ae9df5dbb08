"""The web face of ``motorbus serve --http`` (serve/web.py) over HTTP and its websocket,
without a browser (tests/interop/test_web_browser.py drives the page in Chromium): what the
page is told, the live updates, the STOP POSTs, motion only with --allow-motion, bad
requests, several pages and pages that go away, the end of the service.

One in-process service of the demo bench per module (served_web.ServedWeb), with
--allow-motion; a second face without it for the refusals.  What a command did is read on
the simulators themselves.
"""
from __future__ import annotations

import asyncio
import json
import subprocess
import sys
import time
import urllib.error
import urllib.request

import pytest

pytest.importorskip("aiohttp")

import motorbus  # noqa: E402
from motorbus.drive import MoveInterrupted  # noqa: E402
from motorbus.serve.web import UPDATE_HZ, parse_http_address  # noqa: E402

from served_web import ServedWeb, wait_until  # noqa: E402

DEMO_AXES = ["x", "y", "rot", "z", "tilt", "feed", "spindle"]


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    s = ServedWeb(str(tmp_path_factory.mktemp("web")), allow_motion=True).start()
    yield s
    s.close()


def post(url: str, body=None, content_type: str = "application/json") -> tuple[int, dict]:
    data = None if body is None else (body if isinstance(body, bytes) else json.dumps(body).encode())
    req = urllib.request.Request(url, data=data if data is not None else b"", method="POST")
    if data is not None:
        req.add_header("Content-Type", content_type)
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read())


def get(url: str) -> tuple[int, bytes, str]:
    with urllib.request.urlopen(url, timeout=10) as r:
        return r.status, r.read(), r.headers.get("Content-Type", "")




async def _updates(url: str, n: int, *, seconds: float = 10.0) -> tuple[dict, list]:
    import aiohttp

    async with aiohttp.ClientSession() as session:
        async with session.ws_connect(url.replace("http", "ws", 1) + "ws") as ws:
            hello = json.loads((await ws.receive(timeout=seconds)).data)
            out = []
            while len(out) < n:
                out.append(json.loads((await ws.receive(timeout=seconds)).data))
            return hello, out


def test_the_page_and_its_assets_are_served_from_the_package(served):
    status, body, ctype = get(served.url)
    assert status == 200 and ctype.startswith("text/html")
    assert b"static/app.js" in body and b"static/style.css" in body
    assert b"http://" not in body and b"https://" not in body      # no CDN: nothing from elsewhere
    for asset, kind in (("app.js", "javascript"), ("style.css", "css")):
        status, body, ctype = get(served.url + "static/" + asset)
        assert status == 200 and kind in ctype and len(body) > 100
        assert b"https://" not in body


def test_api_bench_names_every_axis_with_kind_identity_and_units(served):
    _, body, _ = get(served.url + "api/bench")
    bench = json.loads(body)
    assert [a["name"] for a in bench["axes"]] == DEMO_AXES
    by = {a["name"]: a for a in bench["axes"]}
    assert by["rot"]["kind"] == "dmac" and by["rot"]["units"] == "deg"
    assert by["z"]["kind"] == "cia402" and by["z"]["where"] == "bus can0, address 5"
    assert by["x"]["identity"] == "Arcus DMX-CAN integrated stepper (simulated)"
    assert bench["allow_motion"] is True and bench["sim"] is True and bench["bench"] == "demo_bench.toml"
    assert {b["name"] for b in bench["buses"]} == {"can0", "can1"}
    assert all(b["bitrate"] == 500_000 and b["bitrate_assumed"] for b in bench["buses"])


def test_websocket_hello_then_live_updates_with_every_field(served):
    hello, updates = asyncio.run(_updates(served.url, 5))
    assert hello["type"] == "hello" and [a["name"] for a in hello["axes"]] == DEMO_AXES
    h = hello["history"]
    assert set(h["axes"]) == set(DEMO_AXES) and set(h["buses"]) == {"can0", "can1"}
    assert all(len(v) == len(h["t"]) for v in h["axes"].values())
    u = updates[-1]
    assert u["type"] == "update" and set(u["axes"]) == set(DEMO_AXES)
    for name, a in u["axes"].items():
        assert {"position", "velocity", "enabled", "moving", "at_target", "homed", "limit_positive",
                "limit_negative", "fault", "text", "error", "last_move"} <= set(a), name
        assert a["error"] is None and isinstance(a["position"], float), (name, a)
        assert a["enabled"] is True, (name, a["text"])
    # The drives' own words come through (the status text of each kind).
    assert "statusword" in u["axes"]["z"]["text"]
    assert {"rpc", "sdo", "web"} <= set(u["counters"])
    assert u["counters"]["web"]["browsers"] >= 1
    ts = [x["t"] for x in updates]
    assert ts == sorted(ts)


def test_updates_are_coalesced_to_at_most_update_hz(served):
    async def count() -> int:
        import aiohttp

        async with aiohttp.ClientSession() as session:
            async with session.ws_connect(served.url.replace("http", "ws", 1) + "ws") as ws:
                await ws.receive()
                mover = served.submit(served.bench["y"].move_by(100.0))   # 2 s: changes at every sample
                n, t0 = 0, time.monotonic()
                while time.monotonic() - t0 < 1.0:
                    await ws.receive(timeout=2)
                    n += 1
                await asyncio.wrap_future(mover)
                return n

    n = asyncio.run(count())
    assert 5 <= n <= UPDATE_HZ + 2, n


def test_bus_load_of_each_can_bus_comes_from_its_bit_counters(served):
    _, updates = asyncio.run(_updates(served.url, 12))
    loads = [u["buses"]["can0"]["load"] for u in updates if u["buses"]["can0"]["load"] is not None]
    assert loads and all(0 < x < 100 for x in loads)          # the service's own SDO/poll traffic
    bits = updates[-1]["buses"]["can0"]["bits_per_s"]
    assert bits == pytest.approx(updates[-1]["buses"]["can0"]["load"] * 5000, rel=0.01)   # % of 500 kbit/s
    bus = served.bench.sync.buses["can0"]
    c = bus.counters
    assert c.rx_bits > 0 and c.tx_bits > 0 and c.tx_bits >= 47 * c.tx_frames


def test_stop_post_stops_the_moving_axis_and_names_the_page(served):
    start = served.rest_mm("x")
    move = served.submit(served.bench["x"].move_to(start + 200.0))
    wait_until(lambda: abs(served.shaft_mm("x") - start) > 1.0, what="x moving")
    status, reply = post(served.url + "api/axes/x/stop")
    assert status == 200 and reply == {"ok": True, "stopped": ["x"]}
    with pytest.raises(MoveInterrupted) as e:
        move.result(15)
    assert "STOP on the web page (127.0.0.1)" in str(e.value)
    at = served.rest_mm("x")
    assert start + 1.0 < at < start + 199.0
    # Every program reads the same outcome, the page too.
    _, updates = asyncio.run(_updates(served.url, 6))
    last = updates[-1]["axes"]["x"]["last_move"]
    assert last["state"] == "interrupted" and last["ok"] is False and "web page" in last["reason"]
    assert last["position"] == pytest.approx(at, abs=0.01)


def test_stop_all_post_stops_every_moving_axis(served):
    starts = {a: served.rest_mm(a) for a in ("x", "z")}
    moves = {a: served.submit(served.bench[a].move_to(starts[a] + 600.0)) for a in starts}
    for a in starts:
        wait_until(lambda a=a: abs(served.shaft_mm(a) - starts[a]) > 0.5, what=f"{a} moving")
    status, reply = post(served.url + "api/stop", None)
    assert status == 200 and reply["stopped"] == DEMO_AXES
    for a, m in moves.items():
        with pytest.raises(MoveInterrupted, match="STOP ALL on the web page"):
            m.result(15)
        assert served.rest_mm(a) < starts[a] + 599.0


def test_motion_verbs_move_jog_and_home_with_allow_motion(served):
    start = served.rest_mm("z")
    status, reply = post(served.url + "api/axes/z/move", {"target": round(start + 3.0, 2)})
    assert status == 202 and reply == {"ok": True}
    wait_until(lambda: served.run(_last_state(served, "z")) == "done", what="z's move done")
    assert served.rest_mm("z") == pytest.approx(start + 3.0, abs=0.02)
    status, _ = post(served.url + "api/axes/z/move", {"distance": -1.0})
    assert status == 202
    wait_until(lambda: served.run(_last_state(served, "z")) == "done" and
               abs(served.rest_mm("z") - (start + 2.0)) < 0.02, what="z's relative move")
    status, _ = post(served.url + "api/axes/y/jog", {"velocity": 10.0})
    assert status == 202
    y0 = served.shaft_mm("y")
    wait_until(lambda: served.shaft_mm("y") > y0 + 0.5, what="y jogging")
    status, _ = post(served.url + "api/axes/y/jog", {"velocity": 0})
    assert status == 202
    y1 = served.rest_mm("y")
    time.sleep(0.2)
    assert served.shaft_mm("y") == y1


async def _last_state(s, axis: str):
    st = await s.bench[axis].status()
    return st.last_move.state if st.last_move else None


@pytest.mark.parametrize("path,body,ctype,code,words", [
    ("api/axes/nope/move", {"target": 1}, "application/json", 404, "no axis 'nope'"),
    ("api/axes/nope/stop", None, "application/json", 404, "no axis 'nope'"),
    ("api/axes/z/move", {"target": "far"}, "application/json", 400, "'target' is a finite number in mm"),
    ("api/axes/z/move", {"target": 1, "distance": 1}, "application/json", 400, "one of 'target'"),
    ("api/axes/z/move", {}, "application/json", 400, "one of 'target'"),
    ("api/axes/z/jog", {"velocity": float("inf")}, "application/json", 400, "finite number"),
    ("api/axes/z/move", b"{not json", "application/json", 400, "not JSON"),
    ("api/axes/z/move", b"[1, 2]", "application/json", 400, "a JSON object"),
    ("api/axes/z/move", b"target=1", "application/x-www-form-urlencoded", 415, "a JSON body"),
    ("api/axes/z/move", b"x" * 10_000, "application/json", 413, None),
])
def test_bad_requests_get_a_typed_answer_and_move_nothing(served, path, body, ctype, code, words):
    before = {a: served.shaft_mm(a) for a in ("z",)}
    status, reply = post(served.url + path, body, ctype) if code != 413 else _post_raw(served.url + path, body)
    assert status == code, reply
    if words is not None:
        assert reply["ok"] is False and words in reply["error"]
    time.sleep(0.05)
    assert served.shaft_mm("z") == before["z"]


def _post_raw(url: str, body: bytes) -> tuple[int, dict]:
    req = urllib.request.Request(url, data=body, method="POST", headers={"Content-Type": "application/json"})
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            return r.status, {}
    except urllib.error.HTTPError as e:
        return e.code, {}


def test_a_page_that_goes_away_leaves_nothing_and_several_are_served(served):
    async def many() -> int:
        import aiohttp

        async with aiohttp.ClientSession() as session:
            sockets = [await session.ws_connect(served.url.replace("http", "ws", 1) + "ws") for _ in range(5)]
            for ws in sockets:
                assert json.loads((await ws.receive(timeout=5)).data)["type"] == "hello"
                assert json.loads((await ws.receive(timeout=5)).data)["type"] == "update"
            during = served.service.web.counters["browsers"]
            for ws in sockets[:4]:
                await ws.close()
            sockets[4]._response.connection.transport.abort()      # one just vanishes (no close frame)
        return during

    base = served.service.web.counters["browsers"]
    during = asyncio.run(many())
    assert during == base + 5
    wait_until(lambda: served.service.web.counters["browsers"] == base, what="the pages' sockets gone")
    web = served.service.web
    assert not web._sockets and all(not t.done() for t in web.sampler._tasks)


def test_without_allow_motion_the_page_may_only_stop(tmp_path):
    s = ServedWeb(str(tmp_path)).start()
    try:
        _, body, _ = get(s.url + "api/bench")
        assert json.loads(body)["allow_motion"] is False
        for verb, body in (("move", {"target": 1.0}), ("jog", {"velocity": 1.0}), ("home", {}), ("enable", {}),
                           ("disable", {}), ("clear", {})):
            status, reply = post(s.url + f"api/axes/z/{verb}", body)
            assert status == 403 and "--allow-motion" in reply["error"], verb
        status, reply = post(s.url + "api/axes/z/stop")
        assert status == 200 and reply["ok"]
        assert s.service.web.counters["refused"] == 6
    finally:
        s.close()


def test_the_end_of_the_service_closes_every_page_going_away(tmp_path):
    import aiohttp

    s = ServedWeb(str(tmp_path)).start()

    async def watch() -> tuple:
        async with aiohttp.ClientSession() as session:
            async with session.ws_connect(s.url.replace("http", "ws", 1) + "ws") as ws:
                await ws.receive(timeout=5)
                # The page keeps reading while the service ends, as a browser does.
                stopping = asyncio.get_running_loop().run_in_executor(None, s.stop)
                try:
                    while True:
                        msg = await ws.receive(timeout=30)
                        if msg.type != aiohttp.WSMsgType.TEXT:
                            return msg.type, msg.data     # a close frame's data: its code
                finally:
                    await stopping

    url = s.url
    try:
        kind, code = asyncio.run(watch())
        assert code == 1001, (kind, code)
        with pytest.raises(urllib.error.URLError):      # nothing listens there any more
            get(url + "api/bench")
    finally:
        s.close()


@pytest.mark.parametrize("text,want", [("8080", ("127.0.0.1", 8080)), ("0.0.0.0:80", ("0.0.0.0", 80)),
                                       ("[::1]:0", ("::1", 0)), (" localhost:9 ", ("localhost", 9))])
def test_http_address(text, want):
    assert parse_http_address(text) == want


@pytest.mark.parametrize("text,words", [("", "[HOST:]PORT"), ("host:", "the port is a number"),
                                        (":80", "a host before ':'"), ("99999", "0..65535"), ("x:y", "not 'y'")])
def test_http_address_refused(text, words):
    with pytest.raises(motorbus.InvalidArgument, match=words.replace("[", r"\[").replace("]", r"\]")):
        parse_http_address(text)


def test_cli_allow_motion_needs_http(tmp_path):
    r = subprocess.run([sys.executable, "-m", "motorbus", "serve", str(tmp_path / "b.toml"), "--allow-motion"],
                       capture_output=True, text=True, timeout=60)
    assert r.returncode == 2 and "--allow-motion" in r.stderr and "--http" in r.stderr


def test_a_port_already_taken_is_refused_by_name_and_leaves_nothing_open(served, tmp_path):
    from urllib.parse import urlsplit

    from motorbus.serve.lockfile import find_service
    from motorbus.serve.service import BenchService

    port = urlsplit(served.url).port
    other = ServedWeb(str(tmp_path))           # its copy of the demo bench, not started
    other.loop.close()
    service = BenchService(other.bench_path, sim=True, epics=False, socket_path=other.socket_path,
                           http=("127.0.0.1", port))
    with pytest.raises(motorbus.InvalidArgument, match=rf"--http 127.0.0.1:{port}: cannot listen there"):
        asyncio.run(service.start())
    assert service.bench is None and find_service(other.bench_path) is None
    get(served.url + "api/bench")              # the first service serves on


def test_positions_of_a_poll_that_ended_are_not_shown_as_current(tmp_path):
    s = ServedWeb(str(tmp_path)).start()
    try:
        poller = s.service.web.sampler._poller

        async def end_poll() -> None:               # what a failed link does to the poll
            await asyncio.to_thread(poller.stop)

        s.run(end_poll())
        wait_until(lambda: s.service.web.sampler.poll_error is not None, what="the sampler seeing the poll end")
        time.sleep(0.5)                              # a status round after it
        _, updates = asyncio.run(_updates(s.url, 2))
        for name, a in updates[-1]["axes"].items():
            assert a["position"] is None and a["velocity"] is None, name
            assert a["error"].startswith("the position poll ended"), (name, a["error"])
    finally:
        s.close()
