"""04: two Midi DMAC modules on one line, moving along a streamed interpolated path.

Both simulators run on one SimClock, so 40 segments of 50 ms (2 s of motion)
are played in a moment and the end positions are exact.

    python examples/04_dmac_interpolation.py
"""
from motorbus._core.runtime import SimClock
from motorbus.drives.dmac import DmacClient, make_sim, open_line, stream_interpolation
from motorbus.serial import PtyLineServer

clock = SimClock()
sleep = lambda s: clock.advance(int(s * 1e9))  # noqa: E731 - waits advance the simulated time
sims = [make_sim("00", clock=clock), make_sim("01", clock=clock)]
with PtyLineServer(sims) as server:
    line = open_line(server.slave_path)
    x, y = (DmacClient(line, address=a, sleep=sleep) for a in (0, 1))
    for axis in (x, y):
        axis.brake(False)                              # DMAC34: the factory brake is ON (annex 7.1)
    # A quarter circle of radius 10000 increments (one turn), as 40 straight segments.
    import math
    points = [(round(10000 * math.cos(math.pi / 2 * k / 40)), round(10000 * math.sin(math.pi / 2 * k / 40)))
              for k in range(41)]
    segments = [[b[0] - a[0], b[1] - a[1]] for a, b in zip(points, points[1:])]
    stats = stream_interpolation([x, y], segments, interpol_time_ms=50, fifo_size=16, sleep=sleep)
    print(f"segments {stats.segments}, xon_errors {stats.xon_errors}, underruns {stats.underruns}")
    clock.advance(3_000_000_000)                       # let the path finish
    print(f"x {x.position} y {y.position}")            # -10000 and +10000 from the start
    x.close(); y.close()
