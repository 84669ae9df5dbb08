"""tools/gen_stubs.py: the committed _core stub describes motorbus's own module, not the
out-of-tree vendors a build compiles in (MOTORBUS_EXTRA_VENDOR_DIRS: the tests build's toy)."""
import ast
import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
import gen_stubs  # noqa: E402

TOY_BINDINGS = ROOT / "tests" / "plugin_kind" / "bindings" / "toy.cpp"


def _top_level_names(text):
    names = set()
    for node in ast.parse(text).body:
        if isinstance(node, (ast.ClassDef, ast.FunctionDef)):
            names.add(node.name)
        elif isinstance(node, ast.ImportFrom):
            names |= {a.asname or a.name for a in node.names}
    return names


def test_what_a_vendor_bindings_file_registers():
    names = gen_stubs.registered_names(TOY_BINDINGS)
    # the toy's classes and enum (py::class_/py::enum_ on the module it is given)
    assert {"Sim", "Client", "Status", "LastStop"} <= names
    assert "set_fault_input" not in names      # a method of a class (ToySim) is not a name of the module


def test_drop_names_removes_classes_overloads_and_all_entries():
    stub = ('from __future__ import annotations\n'
            'from . import can\n'
            'from . import toy\n'
            "__all__: list[str] = ['Keep', 'ToySim', 'can', 'f', 'toy']\n"
            'class Keep:\n'
            '    def a(self) -> None:\n'
            '        ...\n'
            'class ToySim(Keep):\n'
            '    """\n'
            '    doc\n'
            '    """\n'
            '    def b(self) -> int:\n'
            '        ...\n'
            '@typing.overload\n'
            'def f(x: int) -> int:\n'
            '    ...\n'
            'X: int = 3\n')
    out = gen_stubs.drop_names(stub, {"ToySim", "toy", "f"})
    assert out == ('from __future__ import annotations\n'
                   'from . import can\n'
                   "__all__: list[str] = ['Keep', 'can']\n"
                   'class Keep:\n'
                   '    def a(self) -> None:\n'
                   '        ...\n'
                   'X: int = 3\n')


def test_the_committed_stub_names_nothing_the_toy_registers():
    stubs = ROOT / "python" / "motorbus" / "_core"      # one stub per submodule of _core
    assert (stubs / "__init__.pyi").exists() and (stubs / "can.pyi").exists()
    assert not (stubs / "toy.pyi").exists()             # the toy kind's submodule is not motorbus's
    text = (stubs / "__init__.pyi").read_text()
    leaked = (gen_stubs.registered_names(TOY_BINDINGS) | {"toy"}) & _top_level_names(text)
    assert not leaked
    for f in stubs.glob("*.pyi"):
        assert "Toy" not in f.read_text() and "motorbus._core.toy" not in f.read_text(), f.name
