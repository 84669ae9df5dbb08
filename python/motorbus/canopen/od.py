"""Object dictionary: variables addressed by (index, subindex) or by name."""
from __future__ import annotations

from .._core import MotorbusError  # noqa: F401
from .._core.canopen import DataType, ObjectDictionary, Variable, decode_value, encode_value  # noqa: F401

__all__ = ["ObjectDictionary", "Variable", "DataType", "NotFound", "decode_value", "encode_value"]


class NotFound(MotorbusError, KeyError):
    """A name, index or node id that is not there (in a node's dictionary, on a
    network); the message names it.  Also a KeyError, as dict lookups raise."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""
