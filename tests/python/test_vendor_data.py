"""A vendor's data files (EDS, register tables) live in its folder and ship with the package.

Their one home is ``cpp/motorbus/drives/<vendor>/``, beside the C++ that generates or reads
the same table; CMake installs them as ``motorbus/drives/<vendor>/<file>`` next to ``_core``
(in a wheel as in the editable install the tests run on), where
``motorbus.drives.data_file`` and ``importlib.resources`` find them.
"""
from __future__ import annotations

import importlib.resources
import pathlib

import pytest

from motorbus import _core
from motorbus.drives import data_file

ROOT = pathlib.Path(__file__).resolve().parents[2]
SOURCES = sorted(p for pattern in ("*.eds", "*.toml") for p in (ROOT / "cpp/motorbus/drives").glob(f"*/{pattern}"))


def test_there_are_data_files_and_none_left_in_the_python_tree():
    assert {(p.parent.name, p.suffix) for p in SOURCES} >= {("pmc007", ".eds"), ("unitek", ".toml"), ("arcus", ".eds")}
    stray = [p for pattern in ("*.eds", "*.toml") for p in (ROOT / "python/motorbus").rglob(pattern)
             if p.name != "demo_bench.toml"]   # the demo bench is the package's own data, not a vendor's
    assert stray == [], "a vendor's data file belongs in cpp/motorbus/drives/<vendor>/"


@pytest.mark.parametrize("source", SOURCES, ids=lambda p: f"{p.parent.name}/{p.name}")
def test_each_data_file_is_installed_beside_core_and_current(source):
    vendor, name = source.parent.name, source.name
    path = data_file(vendor, name)
    assert path == pathlib.Path(_core.__file__).resolve().parent / "drives" / vendor / name, \
        "not the installed copy: is the package built (make build)?"
    assert path.read_bytes() == source.read_bytes(), f"{path} is older than {source}: rebuild (make build)"
    res = importlib.resources.files("motorbus").joinpath("drives").joinpath(vendor).joinpath(name)
    assert res.read_bytes() == source.read_bytes()


def test_a_missing_data_file_names_where_it_was_looked_for():
    with pytest.raises(FileNotFoundError, match=r"motorbus data file nope/x\.eds: neither installed \(.*\) nor in a "
                                                r"source checkout \(.*cpp/motorbus/drives/nope/x\.eds\)"):
        data_file("nope", "x.eds")


def test_the_vendor_modules_read_their_data_from_there():
    from motorbus.drives import pmc007, unitek

    assert pathlib.Path(pmc007.EDS_PATH) == data_file("pmc007", "pmc007.eds")
    assert "ProductName=PMC007" in pathlib.Path(pmc007.EDS_PATH).read_text()
    assert unitek.ndrive_registers()["POS_IST"].regid == 0x6D               # a row only the NDrive list has
