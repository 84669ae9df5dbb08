"""Keeps the _core stubs in sync with the compiled extension.

    python tools/gen_stubs.py write   # regenerate after changing bindings/
    python tools/gen_stubs.py check   # fail (exit 1) if the committed stubs are stale (`make test`)

_core has one submodule per area and per vendor, so its stubs are a stub package,
python/motorbus/_core/: __init__.pyi (the errors, the submodule imports) and one
<submodule>.pyi each.  The directory holds no __init__.py: Python imports the
extension module beside it, type checkers read the stubs.

The stub describes motorbus's own module.  A build with MOTORBUS_EXTRA_VENDOR_DIRS (the
tests build compiles tests/plugin_kind's `toy` kind in) also holds what those out-of-tree
vendors bind; that is left out, whoever the vendor is: the generator reads the dirs from
the build's CMakeCache.txt and drops every name their bindings register (a vendor
submodule ``_core.<vendor>``, or top-level names in a flat module).
"""
from __future__ import annotations

import ast
import os
import pathlib
import re
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "python" / "motorbus"
STUB_DIR = PACKAGE / "_core"            # the stub package of the extension's submodules
FLAT_STUB = PACKAGE / "_core.pyi"       # the stub of a flat _core (no submodules)
BUILD = pathlib.Path(os.environ.get("MOTORBUS_BUILD_DIR", ROOT / "build" / "dev"))

# What a bindings file registers on the module it is given (conventionally `m`):
# py::class_<...>(m, "Name" / py::enum_<...>(m, "Name" / register_exception<...>(m, "Name"
# and m.def("name" / m.attr("NAME").
_REGISTERED = (re.compile(r"\(\s*m\s*,\s*\"(\w+)\""), re.compile(r"\bm\s*\.\s*(?:def|attr)\s*\(\s*\"(\w+)\""))


def extra_vendors(build: pathlib.Path = BUILD) -> dict[str, pathlib.Path]:
    """{vendor: its bindings file} for the out-of-tree vendors the build compiled in
    (MOTORBUS_EXTRA_VENDOR_DIRS: roots holding cpp/<vendor>/ and bindings/<vendor>.cpp)."""
    cache = build / "CMakeCache.txt"
    if not cache.exists():
        return {}
    roots = ""
    for line in cache.read_text().splitlines():
        if line.startswith("MOTORBUS_EXTRA_VENDOR_DIRS:"):
            roots = line.split("=", 1)[1]
    vendors = {}
    for root in filter(None, roots.split(";")):
        root_path = pathlib.Path(root) if os.path.isabs(root) else ROOT / root
        for d in sorted((root_path / "cpp").glob("*")):
            if d.is_dir():
                vendors[d.name] = root_path / "bindings" / f"{d.name}.cpp"
    return vendors


def registered_names(bindings: pathlib.Path) -> set[str]:
    """The names a vendor's bindings file registers on its module."""
    text = bindings.read_text() if bindings.exists() else ""
    return {name for pattern in _REGISTERED for name in pattern.findall(text)}


def drop_names(text: str, names: set[str]) -> str:
    """The stub without the top-level definitions (classes, functions with their
    overloads, assignments) of ``names``, and without them in ``__all__``."""
    if not names:
        return text
    tree = ast.parse(text)
    lines = text.splitlines(keepends=True)
    cut: set[int] = set()                      # 0-based line numbers to drop
    all_node = None
    for node in tree.body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            name = node.name
        elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
            name = node.target.id
        elif isinstance(node, ast.Assign) and len(node.targets) == 1 and isinstance(node.targets[0], ast.Name):
            name = node.targets[0].id
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            # a vendor submodule's import (`from . import toy`)
            kept = [a for a in node.names if (a.asname or a.name).split(".")[-1] not in names]
            if kept:
                continue
            name = None
        else:
            continue
        if name == "__all__":
            all_node = node
            continue
        if name is None or name in names:
            first = min([node.lineno] + [d.lineno for d in getattr(node, "decorator_list", [])])
            cut.update(range(first - 1, node.end_lineno))
    if all_node is not None and isinstance(all_node.value, ast.List):
        kept = [e.value for e in all_node.value.elts if isinstance(e, ast.Constant) and e.value not in names]
        head = lines[all_node.lineno - 1][:all_node.col_offset]
        annotation = ": list[str]" if isinstance(all_node, ast.AnnAssign) else ""
        lines[all_node.lineno - 1] = f"{head}__all__{annotation} = {kept!r}\n"
        cut.update(range(all_node.lineno, all_node.end_lineno))
    return "".join(line for i, line in enumerate(lines) if i not in cut)


def generate() -> dict[pathlib.Path, str]:
    """{stub file: its text} for motorbus's own _core, without the out-of-tree vendors."""
    extra = extra_vendors()
    with tempfile.TemporaryDirectory() as out:
        subprocess.run(
            [sys.executable, "-m", "pybind11_stubgen", "motorbus._core", "-o", out,
             "--numpy-array-remove-parameters", "--ignore-all-errors"],
            check=True, capture_output=True, text=True,
        )
        flat = list(pathlib.Path(out).rglob("_core.pyi"))
        init = list(pathlib.Path(out).rglob("_core/__init__.pyi"))
        if not flat and not init:
            raise SystemExit("pybind11-stubgen produced no _core stub")
        if flat:
            # A flat module: drop the names the extra vendors' bindings files register.
            names: set[str] = set()
            for bindings in extra.values():
                names |= registered_names(bindings)
            return {FLAT_STUB: drop_names(flat[0].read_text(), names)}
        # A vendor bound into its own submodule is that submodule: its `from . import <vendor>`
        # in __init__.pyi and its <vendor>.pyi go.
        stubs = {STUB_DIR / "__init__.pyi": drop_names(init[0].read_text(), set(extra))}
        for f in sorted(init[0].parent.glob("*.pyi")):
            if f.name != "__init__.pyi" and f.stem not in extra:
                stubs[STUB_DIR / f.name] = f.read_text()
        return stubs


def committed() -> set[pathlib.Path]:
    """The stub files in the tree now."""
    return set(STUB_DIR.glob("*.pyi")) | ({FLAT_STUB} if FLAT_STUB.exists() else set())


def main() -> int:
    mode = sys.argv[1] if len(sys.argv) > 1 else "check"
    stubs = generate()
    if mode == "write":
        for stale in committed() - set(stubs):
            stale.unlink()
        for path, text in stubs.items():
            path.parent.mkdir(exist_ok=True)
            path.write_text(text)
        print(f"wrote {len(stubs)} stub files: {', '.join(str(p.relative_to(ROOT)) for p in stubs)}")
        return 0
    stale = sorted(str(p.relative_to(ROOT)) for p in committed() ^ set(stubs)) + sorted(
        str(p.relative_to(ROOT)) for p, text in stubs.items() if p.exists() and p.read_text() != text)
    if stale:
        print(f"stale _core stubs ({', '.join(stale)}): run `make stubs` and commit them", file=sys.stderr)
        return 1
    print(f"stubs: {len(stubs)} _core stub files are in sync with the extension")
    return 0


if __name__ == "__main__":
    sys.exit(main())
