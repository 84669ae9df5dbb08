"""12: the Drive API from asyncio (motorbus.aio): three simulated drives of three kinds,
each on its real link, moved at once; then a move cancelled, which stops its motor.

    python examples/12_asyncio.py

Every verb of the blocking API is there, awaited, on the drive's twin
(``aio.Drive``); readings are awaitable methods (``await x.position()``).  The logic
is the blocking API's own, written once (docs/aio.md).
"""
import asyncio

from motorbus import Units, aio
from motorbus.sim import SimBench


async def main() -> None:
    with SimBench(["arcus:01", "dmac:00", "cia402:5"]) as bench:
        line = {served.label.split(":")[0]: served.pty_path for served in bench.lines}
        server = bench.can.servers[0]
        axes = [
            await aio.open_drive("arcus", line=line["arcus"], address="01", units=Units("mm", 0.01)),
            await aio.open_drive("dmac", line=line["dmac"], address="00", units=Units("mm", 0.001)),
            await aio.open_drive("cia402", bus=f"socketcand:{server.host}:{server.port}/can0", address=5,
                                 units=Units("mm", 0.01)),
        ]
        for x in axes:
            await x.enable()
        # Three moves at once; each ends at its target or raises a MoveFailed.
        await asyncio.gather(*(x.move_to(4.0, timeout=30) for x in axes))
        for x in axes:
            print(f"{x.kind}: at {await x.position():.2f} mm")

        # A move cancelled half-way: the axis is stopped before CancelledError arrives.
        x = axes[0]
        move = asyncio.create_task(x.move_to(400.0, timeout=60))
        while not (await x.status()).moving:
            await asyncio.sleep(0.01)
        move.cancel()
        await asyncio.gather(move, return_exceptions=True)
        st = await x.status()
        print(f"{x.kind}: cancelled at {await x.position():.2f} mm, moving={st.moving}, "
              f"last move {st.last_move.state}")
        for x in axes:
            await x.aclose()


asyncio.run(main())
