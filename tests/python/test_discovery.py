"""Discovery over simulated lines and buses: drives at unusual addresses and baud rates
are found exactly (the served lines garble requests sent at the wrong rate, as a UART
does), nothing moves, and the bench file written from the result loads and drives them."""
from __future__ import annotations

import subprocess
import sys

import pytest

from motorbus import Bench, _core, open_drive
from motorbus.bus_server import BusServers
from motorbus.discovery import discover
from motorbus.drives import arcus, arcus_canopen, cia402, dmac, pmc007, unitek


@pytest.fixture
def wired():
    """Arcus 07 and 42 on one line (9 600 baud), DMAC 13 at 19 200 (not its 38 400) on another,
    CiA 402 nodes 9 and 77, a PMC007 on node 5, a DMX-CAN (CANopen persona) on node 3 and a
    UNITEK servo on receive id 0x210 on a bus served over socketcand."""
    arcus_sims = [arcus.make_sim("07"), arcus.make_sim("42")]
    line1 = _core.serial.PtyLineServer(arcus_sims, 9600)
    line1.enforce_baud = True
    dmac_sim = dmac.make_sim("13")
    line2 = _core.serial.PtyLineServer([dmac_sim], 19200)
    line2.enforce_baud = True
    servers = BusServers("virtual:discovery-test", socketcand=["127.0.0.1:0"], channel="can0")
    nodes = [cia402.make_sim(n) for n in (9, 77)] + [unitek.make_sim("0x210"), pmc007.make_sim(5),
                                                     arcus_canopen.make_sim(3)]
    for n in nodes:
        n.attach(servers.endpoint())
    srv = servers.servers[0]
    yield {"lines": [line1.slave_path, line2.slave_path], "bus": f"socketcand:{srv.host}:{srv.port}/can0",
           "arcus": arcus_sims, "dmac": dmac_sim, "nodes": nodes}
    for n in nodes:
        n.close()
    servers.close()
    line2.close()
    line1.close()


def test_finds_exactly_the_connected_drives_and_writes_a_working_bench(wired, tmp_path):
    notes = []
    result = discover(wired["lines"], [wired["bus"]], reply_timeout=0.02, progress=notes.append)
    got = {(f.kind, f.address, f.line or f.bus, f.baud) for f in result.found}
    line1, line2 = wired["lines"]
    assert got == {("arcus", "07", line1, 9600), ("arcus", "42", line1, 9600),
                   ("dmac", "13", line2, 19200),
                   ("cia402", "9", wired["bus"], None), ("cia402", "77", wired["bus"], None),
                   ("unitek", "0x210", wired["bus"], None), ("pmc007", "5", wired["bus"], None),
                   ("arcus-canopen", "3", wired["bus"], None)}
    ids = {(f.kind, f.address): f.identity for f in result.found}
    assert ids[("arcus", "07")]["model"] == "DriveMax-CAN"
    assert ids[("dmac", "13")]["serial"] == "H142-10145"
    assert ids[("cia402", "9")]["device_type"] & 0xFFFF == 402
    assert not result.skipped or all("another kind" in s for s in result.skipped)
    assert any("answered" in n for n in notes)              # plain progress lines
    # Discovery reads only: nothing moved.
    assert all(s.pulse_position == 0 for s in wired["arcus"]) and wired["dmac"].state().position == 0

    path = tmp_path / "found.toml"
    result.write(str(path))
    with Bench.load(path) as bench:
        assert len(bench) == 8
        for name, d in bench.axes.items():
            # The sweep's requests at the wrong rates reached the DMAC as garbage, which it
            # latches as a syntax error (#ERROR), as the real module would: acknowledge it.
            d.clear_faults()
            d.enable()
            d.move_by(200, timeout=20)
            assert d.position == pytest.approx(200, abs=1), name


def test_kinds_filter_and_unknown_kind(wired):
    result = discover([wired["lines"][0]], [], kinds=["arcus"], reply_timeout=0.02)
    assert sorted(f.address for f in result.found) == ["07", "42"]
    with pytest.raises(_core.InvalidArgument, match="registered"):
        discover([], [], kinds=["nope"])


def test_scan_command_prints_a_table_and_writes_the_file(wired, tmp_path):
    out = tmp_path / "scan.toml"
    r = subprocess.run([sys.executable, "-m", "motorbus", "scan", "--can", wired["bus"], "--write", str(out),
                        "--quiet"], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    rows = r.stdout.splitlines()
    assert rows[0].split()[:3] == ["kind", "address", "where"]
    assert sum(1 for row in rows if row.startswith("cia402")) == 2
    assert 'kind = "cia402"' in out.read_text()


def test_written_bench_file_and_table_give_identities_in_hex():
    from motorbus.discovery import Found, bench_toml, identity_text

    ident = {"device_type": 0x00420192, "vendor_id": 0x1F4, "model": "DMX-K"}
    assert identity_text(ident) == "device_type=0x00420192, vendor_id=0x000001F4, model=DMX-K"
    f = Found(kind="cia402", address="5", bus="socketcand:127.0.0.1:1/can0", identity=ident)
    assert "# device_type=0x00420192, vendor_id=0x000001F4" in bench_toml([f])
