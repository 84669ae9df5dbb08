"""LocalNode: serve an object dictionary on a bus (SDO server, boot-up, NMT slave)."""
from __future__ import annotations

from .._core import LocalNode  # noqa: F401

__all__ = ["LocalNode"]
