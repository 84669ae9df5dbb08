"""EDS/DCF import and export (CiA 306)."""
from __future__ import annotations

import os
from typing import Optional

from .._core.canopen import ObjectDictionary

__all__ = ["load_eds", "save_eds", "to_eds"]


def load_eds(path: "str | os.PathLike[str]", node_id: int = 0,
             warnings: Optional[list] = None) -> ObjectDictionary:
    """Load an EDS/DCF file. ``$NODEID`` uses ``node_id`` (0: the file's [DeviceComissioning]).

    Entries the dictionary cannot represent are skipped and described in ``warnings``.
    """
    return ObjectDictionary.from_eds(os.fspath(path), node_id, warnings)


def to_eds(od: ObjectDictionary, dcf: bool = False) -> str:
    """The dictionary as EDS text (``dcf=True`` adds current values and commissioning)."""
    return od.to_eds(dcf)


def save_eds(od: ObjectDictionary, path: "str | os.PathLike[str]", dcf: bool = False) -> None:
    od.save_eds(os.fspath(path), dcf)
