"""14: a served bench over EPICS Channel Access: ophyd's EpicsMotor in a bluesky scan,
pyepics' Motor, and a move that ends short seen as a failure by the client.

`motorbus serve BENCH --sim` owns the bench (here the simulated twin of the bench
below) and serves every axis as an EPICS motor record, `<prefix><axis>`, on
127.0.0.1.  Any Channel Access client then drives it with no motorbus code at all:
the standard motor classes of ophyd (a bluesky RunEngine scan) and pyepics, from
this process, another one, or another machine (docs/epics.md).

    pip install "motorbus[epics]" ophyd pyepics bluesky
    python examples/14_epics_bluesky.py
"""
import os
import signal
import socket
import subprocess
import sys
import tempfile

BENCH = """\
[epics]
prefix = "lab:"

[line.rs485]
port = "/dev/ttyUSB0"            # the twin puts a pty here

[bus.can0]
spec = "socketcan:can0"          # the twin puts a served virtual bus here

[axis.x]
kind = "arcus"
line = "rs485"
address = "01"
units = { name = "mm", scale = 0.01 }
params = { HSPD = 20000, ACC = 20 }

[axis.z]
kind = "cia402"
bus = "can0"
address = 5
units = { name = "mm", scale = 0.01 }
params = { "0x6081" = 20000, "0x6083" = 400000, "0x6084" = 400000 }
"""


def free_port() -> int:
    """A port free for both CA's UDP search and its TCP circuits (the service uses one
    number for both), so the example never meets another server on 5064."""
    while True:
        with socket.socket(socket.AF_INET, socket.SOCK_DGRAM) as u:
            u.bind(("127.0.0.1", 0))
            port = u.getsockname()[1]
            with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as t:
                try:
                    t.bind(("127.0.0.1", port))
                except OSError:
                    continue
            return port


def start_service(bench_file: str) -> subprocess.Popen:
    """`motorbus serve` in the background; its `export` lines are the environment a CA
    client sets: they go into os.environ before pyepics loads libca."""
    service = subprocess.Popen([sys.executable, "-m", "motorbus", "serve", bench_file, "--sim",
                                "--ca-port", str(free_port())],
                               stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True)
    for line in service.stdout:
        if line.startswith("export "):
            name, _, value = line[len("export "):].strip().partition("=")
            os.environ[name] = value
        if line.startswith("ready"):
            return service
    raise SystemExit(f"motorbus serve ended with {service.wait()}")


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        bench_file = os.path.join(tmp, "lab.toml")
        with open(bench_file, "w") as f:
            f.write(BENCH)
        service = start_service(bench_file)
        try:
            clients()
        finally:
            service.send_signal(signal.SIGTERM)      # stops every axis, then ends the service
            print("service ended:", service.wait(timeout=30))


def clients() -> None:
    import epicscorelibs.path.pyepics  # noqa: F401  (pyepics uses the libca of the epicscorelibs wheel)
    import epics
    from bluesky import RunEngine
    from bluesky.plans import scan
    from ophyd import EpicsMotor

    # pyepics: the motor record's own client class.
    z = epics.Motor("lab:z")
    z.put("CNEN", 1, wait=True)                        # enable the drive (the record's CNEN field)
    z.put("LLM", -10.0, wait=True)                     # soft limits (pyepics checks them before a move too)
    z.put("HLM", 10.0, wait=True)
    z.move(2.5, wait=True)
    print(f"pyepics: z at {z.get_position(readback=True):.2f} {z.EGU}, DMOV={z.DMOV}")
    # Past the client's own check, the record refuses it: LVIO, and nothing moves.
    refused = z.move(20.0, wait=True, ignore_limits=True)
    print(f"pyepics: move to 20 refused by the soft limit: {refused == -4} (LVIO={z.LVIO}), "
          f"z still at {z.get_position(readback=True):.2f}")

    # ophyd + bluesky: EpicsMotor in a RunEngine scan, z read at every point.
    # settle_time: ophyd's EpicsMotor can lose the next move's status when the RunEngine
    # sends it before ophyd's own DMOV callback has finished with the previous one, and
    # the scan then waits forever (ophyd#782, open upstream).  A short settle closes that
    # window; a real motor wants one anyway.
    x = EpicsMotor("lab:x", name="x", settle_time=0.05)
    zr = EpicsMotor("lab:z", name="z", settle_time=0.05)
    for m in (x, zr):
        m.wait_for_connection(timeout=10)
    x.user_setpoint.set(0.0).wait(10)                  # the record's own put completion
    RE = RunEngine({})
    RE(scan([zr], x, 0.0, 4.0, 5),
       lambda name, doc: print(f"event {doc['seq_num']}: x={doc['data']['x']:.2f} z={doc['data']['z']:.2f}")
       if name == "event" else print("run:", doc["exit_status"]) if name == "stop" else None)
    print(f"ophyd: x stands at {x.position:.2f} mm")

    # A move that ends short is a failed move for the client, not a success: x is
    # stopped mid-move (the STOP field, as another program or an operator would).
    x.velocity.set(20.0).wait(10)                     # VELO: 20 mm/s, so 40 mm take 2 s
    status = x.move(40.0, wait=False)
    while not x.moving:
        epics.poll(0.01)
    epics.caput("lab:x.STOP", 1)                        # as another program would: not ophyd's own stop()
    try:
        status.wait(20)
        print("ophyd: the stopped move reported success")
    except Exception as e:                               # noqa: BLE001 - what ophyd raises is its own
        print(f"ophyd: the stopped move failed ({type(e).__name__}), x at rest short of 40: {x.position < 40.0}")


if __name__ == "__main__":
    main()
