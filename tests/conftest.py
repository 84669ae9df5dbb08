"""Shared pytest configuration.

Every test that drives the C++ core's threads (buses, servers, clients,
simulators) is marked `threaded`, so tools/sanitize.sh runs it again under
AddressSanitizer + UBSan.  Modules listed here only spawn subprocesses or do
single-threaded math, which the sanitizer run would not add anything to; a
single test that does its work in a child process is marked `subprocess`.
"""
import pytest

NOT_THREADED = {
    "test_demo", "test_examples", "test_cli_bus_serve", "test_sim_serve_pyserial",  # subprocesses
    "test_motion", "test_motion_ruckig", "test_frame",  # no threads
    # The command line and the served twin, run as child processes; the client paths they
    # reach are the in-process outcome tests' (test_outcomes_*), which do run under ASan.
    "test_cli", "test_cli_outcomes", "test_sim_serve_bench", "test_move_outcomes",
    # motorbus serve: the service as a child process (test_serve_service, test_serve_shared), and
    # its CA face, pure Python over caproto, with CA clients (test_serve_record,
    # test_epics_clients); the service's C++ paths (shared Poller fan-out, SDO, links) run under
    # ASan in-process in test_serve_rpc.
    "test_serve_service", "test_serve_shared", "test_serve_record", "test_epics_clients",
    # its web face: aiohttp and the browser (a chromium under the sanitizer's preload is not
    # what is under test); the C++ it reaches (Poller, bus bit counters) runs under ASan in
    # test_poller and test_virtual_bus.
    "test_serve_web", "test_web_browser",
}


def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.get_closest_marker("subprocess"):
            continue
        if item.module.__name__.rsplit(".", 1)[-1] not in NOT_THREADED:
            item.add_marker(pytest.mark.threaded)
