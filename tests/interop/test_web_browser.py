"""The page of ``motorbus serve --http`` in a real browser: Debian's chromium, headless,
driven by selenium through Debian's chromedriver (both installed by ``make test-deps``,
which ``make test`` and ``make bench`` run; nothing is downloaded).  One service of the demo bench's simulated twin and one browser
for the module; what the page makes happen is asserted on the simulators (the shafts),
not on what the page says.

The module ends with the service going away, which the page must notice.  It writes a
screenshot of the page (MOTORBUS_SCREENSHOT_DIR, default build/screenshots) while an axis
moves and a fault shows.
"""
from __future__ import annotations

import os
import pathlib
import shutil
import sys
import time

import pytest

pytest.importorskip("aiohttp")
webdriver = pytest.importorskip("selenium.webdriver")

from selenium.webdriver.chrome.service import Service  # noqa: E402
from selenium.webdriver.common.by import By  # noqa: E402

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "python"))
from served_web import ServedWeb, wait_until  # noqa: E402

from motorbus.drive import MoveInterrupted  # noqa: E402

DEMO_AXES = ["x", "y", "rot", "z", "tilt", "feed", "spindle"]
CHROMIUM = shutil.which("chromium") or "/usr/bin/chromium"
CHROMEDRIVER = shutil.which("chromedriver") or "/usr/bin/chromedriver"
SHOTS = pathlib.Path(os.environ.get("MOTORBUS_SCREENSHOT_DIR",
                                    pathlib.Path(__file__).resolve().parents[2] / "build" / "screenshots"))

pytestmark = pytest.mark.timeout(180)


def _browser_missing() -> str:
    missing = [p for p in (CHROMIUM, CHROMEDRIVER) if not os.access(p, os.X_OK)]
    return f"{', '.join(missing)} not installed (make test-deps installs Debian's chromium and chromium-driver)" \
        if missing else ""


@pytest.fixture(scope="module")
def served(tmp_path_factory):
    s = ServedWeb(str(tmp_path_factory.mktemp("webpage")), allow_motion=True).start()
    yield s
    s.close()


@pytest.fixture(scope="module")
def browser(served):
    why = _browser_missing()
    if why:
        if os.environ.get("CI"):
            pytest.fail(why)        # CI's set-up installs them: a missing browser is a broken set-up
        pytest.skip(why)
    os.environ["SE_OFFLINE"] = "true"     # selenium-manager: never fetch a browser or a driver
    options = webdriver.ChromeOptions()
    options.binary_location = CHROMIUM
    for arg in ("--headless=new", "--no-sandbox", "--disable-dev-shm-usage", "--disable-gpu",
                "--window-size=1400,1750", "--no-first-run", "--disable-extensions"):
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(options=options, service=Service(executable_path=CHROMEDRIVER))
    driver.set_page_load_timeout(30)
    driver.get(served.url)
    yield driver
    driver.quit()




def row(driver, axis: str):
    return driver.find_element(By.CSS_SELECTOR, f'tr[data-axis="{axis}"]')


def cell(driver, axis: str, cls: str) -> str:
    return row(driver, axis).find_element(By.CSS_SELECTOR, f".{cls}").text


def shown_number(text: str) -> float:
    return float(text.split()[0])


def console_errors(driver) -> list:
    return [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]


def test_the_page_loads_with_every_axis_of_the_demo_bench(served, browser):
    wait_until(lambda: browser.find_element(By.TAG_NAME, "body").get_attribute("data-connection") == "live",
               what="the page live")
    rows = browser.find_elements(By.CSS_SELECTOR, "table#axes tr[data-axis]")
    assert [r.get_attribute("data-axis") for r in rows] == DEMO_AXES
    kinds = {a: cell(browser, a, "kind") for a in DEMO_AXES}
    assert kinds == {"x": "arcus", "y": "arcus", "rot": "dmac", "z": "cia402", "tilt": "arcus-canopen",
                     "feed": "pmc007", "spindle": "unitek"}
    assert "Arcus DMX-CAN" in cell(browser, "x", "identity")
    assert "PMC007" in cell(browser, "feed", "identity")
    # positions in each axis' units, read (not placeholders)
    wait_until(lambda: cell(browser, "rot", "position").endswith("deg"), what="rot's position in deg")
    assert cell(browser, "z", "position").endswith("mm")
    assert "enabled" in cell(browser, "z", "state")
    assert "demo_bench.toml" in browser.find_element(By.ID, "bench").text
    assert browser.find_element(By.ID, "stop-all").is_enabled()
    assert browser.find_elements(By.CSS_SELECTOR, "canvas#plot") and \
        browser.find_elements(By.CSS_SELECTOR, "canvas#busload")
    wait_until(lambda: "rpc" in browser.find_element(By.ID, "counters").text, what="the service's counters")
    assert console_errors(browser) == []


def test_a_position_moves_on_the_page_while_the_axis_moves(served, browser):
    start = served.rest_mm("x")
    target = round(start + 150.0, 2)             # 3 s at the demo's 50 mm/s
    move = served.submit(served.bench["x"].move_to(target))      # another program moves x
    seen = []
    deadline = time.monotonic() + 20
    while not move.done() and time.monotonic() < deadline:
        seen.append(shown_number(cell(browser, "x", "position")))
        time.sleep(0.05)
    move.result(20)
    distinct = sorted(set(seen))
    # several positions between start and target shown while it moved, in order
    assert len([p for p in distinct if start + 0.5 < p < target - 0.5]) >= 3, seen
    assert seen == sorted(seen), seen
    wait_until(lambda: abs(shown_number(cell(browser, "x", "position")) - target) < 0.005, what="x at target")
    wait_until(lambda: cell(browser, "x", "outcome").startswith("done"), what="x's outcome")
    assert f"{target:.3f}" in cell(browser, "x", "outcome")


def test_stop_on_the_page_stops_the_simulated_axis(served, browser):
    start = served.rest_mm("y")
    move = served.submit(served.bench["y"].move_to(start + 400.0))     # 8 s at the demo's speed
    wait_until(lambda: abs(served.shaft_mm("y") - start) > 2.0, what="y moving")
    wait_until(lambda: "moving" in cell(browser, "y", "state"), what="the page showing y moving")
    row(browser, "y").find_element(By.CSS_SELECTOR, "button.stop").click()
    with pytest.raises(MoveInterrupted, match=r"STOP on the web page \(127\.0\.0\.1\)"):
        move.result(15)
    at = served.rest_mm("y")
    assert start + 2.0 < at < start + 390.0
    time.sleep(0.3)
    assert served.shaft_mm("y") == at                     # stopped, asserted on the simulator
    wait_until(lambda: cell(browser, "y", "outcome").startswith("interrupted"), what="y's outcome on the page")
    assert "web page" in cell(browser, "y", "outcome")


def test_stop_all_on_the_page_stops_every_moving_axis(served, browser):
    starts = {a: served.rest_mm(a) for a in ("x", "z")}
    moves = {a: served.submit(served.bench[a].move_to(starts[a] + 600.0)) for a in starts}
    for a in starts:
        wait_until(lambda a=a: abs(served.shaft_mm(a) - starts[a]) > 1.0, what=f"{a} moving")
    browser.find_element(By.ID, "stop-all").click()
    for a, m in moves.items():
        with pytest.raises(MoveInterrupted, match="STOP ALL on the web page"):
            m.result(15)
        assert served.rest_mm(a) < starts[a] + 590.0


def test_a_fault_appears_on_the_page_with_its_reason(served, browser):
    sim = served.sims["z"]
    start = served.rest_mm("z")
    move = served.submit(served.bench["z"].move_to(start + 600.0))
    wait_until(lambda: abs(served.shaft_mm("z") - start) > 1.0, what="z moving")
    sim.inject_fault(0x5441)                 # a CiA 402 drive fault: 0x5441 (EMCY code of the sim)
    with pytest.raises(Exception):
        move.result(15)
    wait_until(lambda: "faulted" in (row(browser, "z").get_attribute("class") or ""), what="z's row faulted")
    fault = cell(browser, "z", "fault")
    assert fault.startswith("FAULT") and "5441" in fault, fault
    outcome = cell(browser, "z", "outcome")
    assert outcome.startswith("fault"), outcome
    # The screenshot: z faulted, the others' traces in the plot (looked at: docs/web.md shows it).
    SHOTS.mkdir(parents=True, exist_ok=True)
    x0 = served.rest_mm("x")
    mover = served.submit(served.bench["x"].move_to(x0 - 40.0))
    time.sleep(0.4)
    shot = SHOTS / "web_page.png"
    assert browser.save_screenshot(str(shot))
    assert shot.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and shot.stat().st_size > 20_000
    mover.result(20)
    sim.clear_fault() if hasattr(sim, "clear_fault") else None
    served.run(served.bench["z"].clear_faults())
    served.run(served.bench["z"].enable())
    wait_until(lambda: "faulted" not in (row(browser, "z").get_attribute("class") or ""), what="z's fault cleared")


def test_move_from_the_page_with_allow_motion(served, browser):
    start = served.rest_mm("rot")
    box = row(browser, "rot").find_element(By.CSS_SELECTOR, "input.target")
    box.clear()
    box.send_keys(f"{start + 90.0:.3f}")
    row(browser, "rot").find_element(By.CSS_SELECTOR, "button.move").click()
    wait_until(lambda: abs(served.shaft_mm("rot") - (start + 90.0)) < 0.05, timeout=20, what="rot at target")
    wait_until(lambda: cell(browser, "rot", "outcome").startswith("done"), what="rot's outcome")
    assert console_errors(browser) == []


def test_the_page_notices_the_service_going_away(served, browser):
    served.stop()
    wait_until(lambda: browser.find_element(By.TAG_NAME, "body").get_attribute("data-connection") == "gone",
               timeout=10, what="the page saying the service is gone")
    assert "service gone" in browser.find_element(By.ID, "connection").text.lower()
    SHOTS.mkdir(parents=True, exist_ok=True)
    browser.save_screenshot(str(SHOTS / "web_page_gone.png"))
