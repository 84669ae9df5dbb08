"""Vendor drive clients and simulators, one module per vendor."""
from __future__ import annotations

from pathlib import Path

__all__ = ["data_file"]


def data_file(vendor: str, name: str) -> Path:
    """The path of a vendor's data file (an EDS, a register table) as motorbus ships it.

    A vendor's data files live in its folder, ``cpp/motorbus/drives/<vendor>/``, beside
    the C++ that generates or reads the same table; CMake installs them as
    ``motorbus/drives/<vendor>/<name>`` next to the ``_core`` extension (in a wheel and in
    an editable install alike).  A checkout run with ``PYTHONPATH=python`` and an
    in-place ``_core`` finds them in the source folder instead.
    """
    from .. import _core

    installed = Path(_core.__file__).resolve().parent / "drives" / vendor / name
    if installed.is_file():
        return installed
    source = Path(__file__).resolve().parents[3] / "cpp" / "motorbus" / "drives" / vendor / name
    if source.is_file():
        return source
    raise FileNotFoundError(f"motorbus data file {vendor}/{name}: neither installed ({installed}) "
                            f"nor in a source checkout ({source})")
