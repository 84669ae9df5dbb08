"""SDO client and the SDO errors (C++ core; see docs/canopen.md)."""
from __future__ import annotations

from .._core import (  # noqa: F401
    ABORT_CODES,
    SdoAbortError,
    SdoClient,
    SdoProtocolError,
    SdoTimeout,
    abort_text,
)

__all__ = ["SdoClient", "SdoAbortError", "SdoTimeout", "SdoProtocolError", "abort_text", "ABORT_CODES"]
