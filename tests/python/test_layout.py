"""Code layout rules checked on the tree itself (docs/architecture.md, "Rules that keep it livable": no function over 150 lines)."""
from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MAX_LINES = 150

# Functions allowed over the limit, each with its reason.  Keep it empty: a
# long function is split (a handler table, one function per service, a piece
# of its own) rather than listed here.
EXCEPTIONS: dict[str, str] = {}


def _checker():
    spec = importlib.util.spec_from_file_location("function_lengths", ROOT / "tools" / "function_lengths.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules.setdefault("function_lengths", mod)  # dataclasses look their module up
    spec.loader.exec_module(sys.modules["function_lengths"])
    mod = sys.modules["function_lengths"]
    return mod


def test_no_function_over_150_lines():
    fl = _checker()
    found = fl.long_functions([ROOT / "cpp", ROOT / "bindings"], MAX_LINES)
    over = [f"{Path(s.path).relative_to(ROOT)}:{s.line} {s.name} {s.length}" for s in found
            if f"{Path(s.path).relative_to(ROOT)}::{s.name}" not in EXCEPTIONS]
    assert not over, "functions over %d lines (split them):\n  %s" % (MAX_LINES, "\n  ".join(over))


# The scanner itself, on the C++ shapes this tree uses: a checker that misses a
# body would pass everything.
SAMPLE = r'''
#include "x.hpp"
#define BODY { {
namespace a::b {
namespace {
constexpr std::pair<int, int> kTable[] = {
    {1, 2}, {3, 4}};
int helper(int x) {
    // a comment with { braces
    const char* s = "} {";
    auto raw = R"js({"a": {}})js";
    char c = '{';
    int n = 1'000;
    return x + n;
}
}  // namespace

struct Point {
    int x{0};
    std::function<void(int)> cb{};
    int get() const { return x; }
};

Foo::Foo(int n)
    : n_(n), motor_(clock, [&] {
          Config c;
          return c;
      }()), v_{n} {
    if (n) {
        n_ = 2;
    }
}

[[noreturn]] void fail() {
    throw 1;
}

const std::map<std::string, int (*)(int)> kHandlers = {
    {"A", [](int v) {
         return v;
     }},
};

void Foo::operator()(int) const {
}
}  // namespace a::b
'''


def test_scanner_finds_bodies_and_their_lengths(tmp_path):
    fl = _checker()
    f = tmp_path / "sample.cpp"
    f.write_text(SAMPLE)
    got = {(s.name, s.line, s.length) for s in fl.scan(f)}
    assert got == {
        ("helper", 8, 8),
        ("get", 21, 1),
        ("Foo::Foo", 24, 9),
        ("fail", 34, 3),
        ("kHandlers (lambda)", 39, 3),
        ("Foo::operator()", 44, 2),
    }
    assert [s.name for s in fl.long_functions([f], 7)] == ["Foo::Foo", "helper"]
