"""``motorbus serve BENCH [--sim] [--prefix P] [--interface ADDR]... [--ca-port N]
[--socket PATH] [--no-epics] [--http [HOST:]PORT [--allow-motion]]``: one process owns the
bench and serves every axis (docs/serve.md; the CA face: docs/epics.md; the web page:
docs/web.md).

It prints one line per face and the environment a Channel Access client sets, then
serves until SIGTERM, SIGINT or SIGHUP, which stop every axis before it exits (exit
code 0).  SIGUSR1 prints the counters (``counters {json}``) on stderr; so does the end.
While it runs, ``motorbus status|move|home|stop|config|monitor BENCH`` go through it.
"""
from __future__ import annotations

import argparse
import asyncio
import sys
from typing import Any

from . import _core


def _say(line: str) -> None:
    print(line, flush=True)


def cmd_serve(args: argparse.Namespace) -> int:
    from .serve.service import BenchService
    from .serve.web import parse_http_address

    if args.allow_motion and args.http is None:
        raise _core.InvalidArgument("motorbus serve --allow-motion: lets the web page move axes; give --http too")
    service = BenchService(args.bench, sim=args.sim, prefix=args.prefix,
                           interfaces=tuple(args.interface or ("127.0.0.1",)), ca_port=args.ca_port,
                           socket_path=args.socket, epics=not args.no_epics,
                           http=None if args.http is None else parse_http_address(args.http),
                           allow_motion=args.allow_motion)

    async def main() -> int:
        info = await service.start()
        service.on_usr1 = service.report_counters
        axes = ", ".join(service.bench.axes)
        _say(f"serving {info.bench}{' (simulated twin)' if info.sim else ''}, pid {info.pid}: {axes}")
        _say(f"rpc unix:{info.socket}")
        if info.http is not None:
            _say(f"http {info.http}{' (the page may move axes: --allow-motion)' if service.allow_motion else ''}")
        if info.prefix is not None:
            hosts = ", ".join(info.interfaces)
            _say(f"ca {info.prefix}<axis> on {hosts} port {info.ca_port}")
            for key, value in info.env.items():
                _say(f"export {key}={value}")
        for name in ([] if info.sim else service.unarmed_watchdogs()):   # a --sim twin dies with the service
            print(f"motorbus serve: note: axis {name}'s drive has a watchdog the bench file does not arm: a killed "
                  f"service would leave it running (options = {{ watchdog = {{ host_node = 127, period = 0.1 }} }}, "
                  f"docs/serve.md)", file=sys.stderr, flush=True)
        _say("ready (SIGTERM, SIGINT or SIGHUP stops every axis, then ends the service)")
        try:
            await service.run()
        finally:
            service.report_counters()
        return 0

    try:
        return asyncio.run(main())
    except KeyboardInterrupt:       # pragma: no cover - a Ctrl-C before the loop's handler was set
        return 0


def add_commands(sub: Any, common: Any = None) -> None:
    help_ = "own a bench and serve every axis: to motorbus's programs and over EPICS Channel Access"
    p = sub.add_parser("serve", help=help_, parents=[common] if common is not None else [],
                       formatter_class=argparse.RawDescriptionHelpFormatter, description=help_ + (
                           ".\n\nWhile it runs, `motorbus status|move|home|stop|config|monitor BENCH` go "
                           "through it (--no-server: not); `terminal` and raw protocol access are refused. "
                           "SIGTERM, SIGINT or SIGHUP stop every axis, then end it (exit 0). docs/serve.md"))
    p.add_argument("bench", metavar="BENCH", help="the bench file (TOML)")
    p.add_argument("--sim", action="store_true",
                   help="serve the bench's simulated twin (it lasts as long as the service)")
    p.add_argument("--prefix", default=None,
                   help="CA prefix of the PVs (default: the bench file's [epics] prefix, else its name and ':')")
    p.add_argument("--interface", action="append", metavar="ADDR",
                   help="an address to serve Channel Access on (repeatable; default 127.0.0.1: this host only)")
    p.add_argument("--ca-port", type=int, default=None, metavar="N",
                   help="the CA server port (default: EPICS_CA_SERVER_PORT, else 5064)")
    p.add_argument("--socket", default=None, metavar="PATH",
                   help="the Unix socket of motorbus's own programs (default: under $XDG_RUNTIME_DIR or "
                        "/tmp/motorbus-UID, named by the bench file)")
    p.add_argument("--no-epics", action="store_true",
                   help="no Channel Access: serve motorbus's own programs only (caproto not needed)")
    p.add_argument("--http", default=None, metavar="[HOST:]PORT",
                   help="serve a live web page of the bench on PORT (default host 127.0.0.1: this host only; "
                        "0.0.0.0 for every network); its STOP buttons always work")
    p.add_argument("--allow-motion", action="store_true",
                   help="let the web page move, jog, home, enable and clear axes too (default: it only stops)")
    p.set_defaults(func=cmd_serve)


def main(argv: Any = None) -> int:  # pragma: no cover - via motorbus.cli
    from .cli import main as cli_main
    return cli_main(argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
