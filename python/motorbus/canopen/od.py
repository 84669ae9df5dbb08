"""Object dictionary: variables addressed by (index, subindex) or by name."""
from __future__ import annotations

from .._core import DataType, ObjectDictionary, Variable  # noqa: F401

__all__ = ["ObjectDictionary", "Variable", "DataType"]
