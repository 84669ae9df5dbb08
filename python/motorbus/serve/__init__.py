"""``motorbus serve``: one process owns a bench and serves its axes to every other
program (docs/serve.md).

* :mod:`.lockfile` -- how a program finds the service of a bench file
  (:func:`find_service`, :class:`ServiceInfo`, :class:`ServedElsewhere`);
* :mod:`.service` -- :class:`BenchService`, which owns an ``aio.Bench`` and starts the faces:
* :mod:`.rpc` / :mod:`.client` -- motorbus's own programs (``connect()``: a RemoteBench);
* :mod:`.epics` -- every axis as an EPICS motor record over Channel Access (``motorbus[epics]``).

Importing this package imports neither caproto nor the service's event-loop code:
``find_service`` is what every CLI command calls first, and must stay cheap.
"""
from __future__ import annotations

from typing import Any

from .lockfile import ServedElsewhere, ServiceInfo, default_socket_path, find_service, lock_path

__all__ = ["BenchService", "ServiceInfo", "ServedElsewhere", "find_service", "lock_path", "default_socket_path"]


def __getattr__(name: str) -> Any:
    if name == "BenchService":
        from .service import BenchService
        return BenchService
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
