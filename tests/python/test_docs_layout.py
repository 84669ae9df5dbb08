"""docs/architecture.md's file table names what the tree holds, and only that.

The table ("Where each file's job is") fell behind the tree once: `cpp/motorbus/poll/` and half of the
Python product layer were missing while rows for moved files stayed.  This keeps it true both ways:
every `python/motorbus/*.py` module, every `cpp/motorbus/*/` folder and every `bindings/*.cpp` file is
named in the table, and every path the table names exists (the paths git tracks, so a file deleted but
still on disk counts as gone).
"""
from __future__ import annotations

import re
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
DOC = ROOT / "docs" / "architecture.md"
HEADING = "## Where each file's job is"


def _tracked() -> list[str]:
    try:
        out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    except (OSError, subprocess.CalledProcessError) as e:  # an unpacked sdist has no git
        pytest.skip(f"git ls-files unavailable: {e}")
    return out.splitlines()


def _table_rows() -> list[str]:
    text = DOC.read_text(encoding="utf-8")
    assert HEADING in text, f"{DOC.name} lost its section {HEADING!r}"
    section = text.split(HEADING, 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("| `")]
    assert len(rows) > 20, f"the file table of {DOC.name} has only {len(rows)} rows"
    return rows


def _named_paths(rows: list[str]) -> list[str]:
    """The paths a row's first cell names: `a/b.py`, `c.py` (relative to the first one's folder)."""
    paths = []
    for row in rows:
        first_cell = row.split("|")[1]
        names = re.findall(r"`([^`]+)`", first_cell)
        base = ""
        for i, name in enumerate(names):
            if i == 0:
                path = name
                base = name.rsplit("/", 1)[0] + "/" if "/" in name.rstrip("/") else ""
            elif "/" in name:
                path = name
            else:
                path = base + name
            paths.append(path)
    return paths


def _matches(pattern: str, tracked: list[str]) -> bool:
    """A named path exists: a file, a folder (`x/`), or a pattern with `<vendor>`, `<kind>` or `*`."""
    regex = re.escape(pattern)
    regex = regex.replace(re.escape("<vendor>"), "[a-z0-9_]+").replace(re.escape("<kind>"), "[a-z0-9_]+")
    regex = regex.replace(r"\*", "[^/]+")
    if pattern.endswith("/"):
        return any(re.match(regex, f) for f in tracked)
    return any(re.fullmatch(regex, f) for f in tracked)


def _covered(path: str, named: list[str]) -> bool:
    """`path` (a file or a folder ending in /) is named by one of the table's paths or patterns.

    A folder whose row describes its sub-folders (`cpp/motorbus/drives/<vendor>/`) counts as named.
    """
    for pattern in named:
        if path.endswith("/") and pattern.startswith(path + "<"):
            return True
        regex = re.escape(pattern)
        regex = regex.replace(re.escape("<vendor>"), "[a-z0-9_]+").replace(re.escape("<kind>"), "[a-z0-9_]+")
        regex = regex.replace(r"\*", "[^/]+")
        if re.fullmatch(regex, path):
            return True
    return False


def test_every_path_the_table_names_exists():
    tracked = _tracked()
    named = _named_paths(_table_rows())
    missing = [p for p in named if not _matches(p, tracked)]
    assert not missing, f"docs/architecture.md's file table names paths git does not track: {missing}"


def test_every_module_folder_and_bindings_file_is_in_the_table():
    tracked = _tracked()
    named = _named_paths(_table_rows())
    wanted = set()
    for f in tracked:
        parts = f.split("/")
        if len(parts) == 3 and parts[:2] == ["python", "motorbus"] and f.endswith(".py"):
            wanted.add(f)                                   # python/motorbus/*.py
        elif len(parts) >= 4 and parts[:2] == ["cpp", "motorbus"]:
            wanted.add("/".join(parts[:3]) + "/")           # cpp/motorbus/<area>/
        elif len(parts) == 2 and parts[0] == "bindings" and f.endswith(".cpp"):
            wanted.add(f)                                   # bindings/*.cpp
    assert len(wanted) > 30, f"the tree has only {len(wanted)} of the paths the table must name: {sorted(wanted)}"
    absent = sorted(p for p in wanted if not _covered(p, named))
    assert not absent, f"docs/architecture.md's file table does not name: {absent}"


def test_the_python_subpackages_and_vendor_files_are_covered():
    # The sub-packages and the per-vendor files are named by a folder or a pattern row.
    tracked = _tracked()
    named = _named_paths(_table_rows())
    wanted = {f for f in tracked
              if re.fullmatch(r"python/motorbus/drives/[a-z0-9_]+\.py|bindings/drives/[a-z0-9_]+\.cpp", f)}
    wanted |= {"/".join(f.split("/")[:3]) + "/" for f in tracked
               if f.startswith("python/motorbus/") and f.count("/") >= 3 and not f.startswith("python/motorbus/drives/")
               and not f.startswith("python/motorbus/_core/")}
    absent = sorted(p for p in wanted if not _covered(p, named))
    assert not absent, f"docs/architecture.md's file table does not name: {absent}"
