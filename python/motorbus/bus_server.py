"""Serving one CAN bus to other processes: socketcand servers (TCP) and SLCAN
adapters (ptys), as ``motorbus bus serve`` and ``motorbus sim serve`` do.

    with BusServers("virtual:bench", socketcand=["127.0.0.1:0"], slcan_ptys=1) as servers:
        for line in servers.announce():
            print(line)      # "socketcand 127.0.0.1:40123 can0", "slcan /dev/pts/7"

Each server gets its own endpoint on a virtual bus, so a frame from an SLCAN
client reaches socketcand clients and the reverse, as on a real bus; a real
bus (slcan:, socketcan:...) is opened once and shared by its servers.
"""
from __future__ import annotations

from typing import Any, Optional, Sequence

from . import _core
from .bus import open_bus, parse_spec

__all__ = ["BusServers", "parse_host_port"]


def parse_host_port(text: str) -> tuple[str, int]:
    """``"127.0.0.1:0"`` -> ("127.0.0.1", 0); InvalidArgument naming the problem."""
    host, colon, port = text.rpartition(":")
    try:
        value = int(port)
    except ValueError:
        value = -1
    if not colon or not 0 <= value <= 65535:
        raise _core.InvalidArgument(f"server address {text!r}: expected HOST:PORT with PORT 0..65535")
    return host or "127.0.0.1", value


class BusServers:
    """socketcand servers and SLCAN adapters exposing the bus ``spec``.

    ``bus_options`` go to every ``open_bus`` of the spec (``bitrate=`` for a
    virtual bus).  ``endpoint()`` gives further endpoints on the same bus (the
    simulated drives of ``sim serve`` each get one)."""

    def __init__(self, spec: str, *, socketcand: Sequence[str] = (), slcan_ptys: int = 0,
                 channel: str = "can0", **bus_options: Any) -> None:
        scheme, _ = parse_spec(spec)
        self.spec = spec
        self.channel = channel
        self._options = bus_options
        self._shared: Optional[_core.can.Bus] = None if scheme == "virtual" else open_bus(spec, **bus_options)
        self._buses: list[_core.can.Bus] = []
        self.servers: list[Any] = []
        self._lines: list[str] = []
        try:
            for text in socketcand:
                host, port = parse_host_port(text)
                srv = _core.can.SocketcandServer(self.endpoint(), host=host, port=port, channel=channel)
                self.servers.append(srv)
                self._lines.append(f"socketcand {srv.host}:{srv.port} {channel}")
            for _ in range(int(slcan_ptys)):
                srv = _core.can.SlcanServer(self.endpoint())
                self.servers.append(srv)
                self._lines.append(f"slcan {srv.pty_path}")
        except Exception:
            self.close()
            raise

    def endpoint(self) -> _core.can.Bus:
        """A bus endpoint on the served bus (closed with the servers)."""
        if self._shared is not None:
            return self._shared
        bus = open_bus(self.spec, **self._options)
        self._buses.append(bus)
        return bus

    def announce(self) -> list[str]:
        """One line per server: ``socketcand HOST:PORT CHANNEL`` or ``slcan PTY``."""
        return list(self._lines)

    def report(self) -> list[str]:
        """One line per server with what it forwarded and what it dropped (the
        counters a person checks when a client says frames went missing)."""
        out = []
        for line, srv in zip(self._lines, self.servers):
            st = srv.stats
            if hasattr(st, "queue_drops"):   # socketcand
                out.append(f"{line}: clients {st.clients_active} active / {st.clients_accepted} accepted, "
                           f"to clients {st.frames_to_clients}, to bus {st.frames_to_bus}, "
                           f"dropped {st.queue_drops} (per client {list(srv.client_drops)}), "
                           f"bus send failures {st.bus_send_failures}, bad elements {st.bad_elements}")
            else:                            # SLCAN adapter
                out.append(f"{line}: commands {st.commands} ({st.invalid_commands} invalid), "
                           f"transmitted {st.transmitted} (failed {st.transmit_failed}), "
                           f"forwarded {st.forwarded}, dropped {st.forward_dropped}")
        return out

    def set_faults(self, **faults: Any) -> None:
        """Frame faults on the served bus (``VirtualBus.set_faults``: drop_every,
        drop_probability, corrupt_probability, delay, seed) applied to every
        endpoint this object opened, so frames in both directions suffer them:
        requests from clients (through the servers' endpoints) and replies from
        the simulated drives.  Only a served virtual bus can be made faulty."""
        if self._shared is not None:
            raise _core.InvalidArgument(f"bus {self.spec}: frame faults need a served virtual bus")
        for b in self._buses:
            b.set_faults(**faults)

    def close(self) -> None:
        for s in self.servers:
            s.close()
        for b in self._buses:
            b.close()
        if self._shared is not None:
            self._shared.close()
        self.servers, self._buses, self._shared = [], [], None

    def __enter__(self) -> "BusServers":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()
