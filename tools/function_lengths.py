#!/usr/bin/env python3
"""Report C++ functions longer than a limit: ``file:line name length``.

No C++ parser is needed for this tree: the scanner blanks comments, string and
character literals (raw strings too) and preprocessor lines, then matches
braces.  A ``{`` met at namespace or class scope opens a namespace, a class, a
function body, a lambda body (``auto f = [..](..) {``) or a data initializer;
the text since the last ``;``/``{``/``}`` of that scope (nested braces folded
to ``{}``) tells which.  Function and lambda bodies count from the line their
declaration starts on to their closing brace; lambdas and local classes inside
a function count as part of it.  Lambdas inside a namespace-scope initializer
(a handler table) are measured one by one.

    python tools/function_lengths.py [--max N] [paths...]    # exit 1 if any is over
"""
from __future__ import annotations

import argparse
import re
import sys
from dataclasses import dataclass
from pathlib import Path

SUFFIXES = {".cpp", ".hpp", ".cc", ".h", ".hh", ".cxx", ".hxx", ".ipp"}
DEFAULT_MAX = 150


@dataclass(frozen=True)
class Span:
    path: str
    line: int  # 1-based line where the declaration starts
    name: str
    length: int  # lines, declaration line to closing brace, inclusive


def blank(src: str) -> str:
    """Comments, literals and preprocessor lines replaced by spaces (newlines kept)."""
    out: list[str] = []
    i, n = 0, len(src)
    line_start = True

    def keep_newlines(text: str) -> str:
        return "".join(c if c == "\n" else " " for c in text)

    while i < n:
        c = src[i]
        if line_start and c == "#":  # preprocessor line, with backslash continuations
            j = i
            while j < n:
                k = src.find("\n", j)
                if k == -1:
                    k = n
                    break
                if src[k - 1] == "\\":
                    j = k + 1
                    continue
                break
            out.append(keep_newlines(src[i:k]))
            i = k
            continue
        if c in " \t":
            out.append(c)
            i += 1
            continue
        if c == "\n":
            out.append(c)
            line_start = True
            i += 1
            continue
        line_start = False
        if src.startswith("//", i):
            k = src.find("\n", i)
            k = n if k == -1 else k
            out.append(" " * (k - i))
            i = k
            continue
        if src.startswith("/*", i):
            k = src.find("*/", i + 2)
            k = n if k == -1 else k + 2
            out.append(keep_newlines(src[i:k]))
            i = k
            continue
        m = re.match(r'(?:u8|[uUL])?R"([^()\\\s]{0,16})\(', src[i:i + 24])
        if m and (i == 0 or not (src[i - 1].isalnum() or src[i - 1] == "_")):
            close = ")" + m.group(1) + '"'
            k = src.find(close, i + m.end())
            k = n if k == -1 else k + len(close)
            out.append('""' + keep_newlines(src[i + 2:k]))
            i = k
            continue
        if c in "\"'":
            # A quote after a digit is a digit separator (1'000'000), not a literal.
            if c == "'" and i > 0 and src[i - 1].isalnum():
                out.append(" ")
                i += 1
                continue
            j = i + 1
            while j < n and src[j] != c and src[j] != "\n":
                j += 2 if src[j] == "\\" else 1
            j = min(j + 1, n)
            out.append(c + " " * (j - i - 2) + c if j - i >= 2 else c)
            i = j
            continue
        out.append(c)
        i += 1
    return "".join(out)


_TEMPLATE = re.compile(r"^\s*template\s*<")
_KEYWORD_HEADS = re.compile(
    r"^\s*(if|for|while|switch|catch|do|else|try|return|case|default)\b")


def _strip_template(head: str) -> str:
    """Drops leading ``template <...>`` clauses (angle brackets matched)."""
    while _TEMPLATE.match(head):
        i = head.index("<")
        depth = 0
        for j in range(i, len(head)):
            if head[j] == "<":
                depth += 1
            elif head[j] == ">":
                depth -= 1
                if depth == 0:
                    head = head[j + 1:]
                    break
        else:
            return head
    return head


def _top_level(head: str, chars: str) -> list[int]:
    """Positions of ``chars`` in ``head`` outside (), [] and {}."""
    depth = 0
    found = []
    for i, c in enumerate(head):
        if c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif depth == 0 and c in chars:
            found.append(i)
    return found


def _is_assignment(head: str, pos: int) -> bool:
    before = head[max(0, pos - 9):pos]
    after = head[pos + 1:pos + 2]
    if after == "=" or (pos > 0 and head[pos - 1] in "=!<>"):
        return False
    return not re.search(r"operator\s*[-+*/%^&|<>!=]*$", before)


def classify(head: str) -> tuple[str, str]:
    """(kind, name) of the brace that ends ``head``: kind is namespace, class,
    function, lambda, data or block."""
    h = " ".join(head.split())
    if not h:
        return "block", ""
    if re.match(r"^(inline\s+)?namespace\b", h) or re.match(r'^extern\s*""$', h):
        return "namespace", ""
    body = re.sub(r"^(\[\[.*?\]\]\s*)+", "", _strip_template(h).strip())  # [[noreturn]] etc.
    assigns = [p for p in _top_level(body, "=") if _is_assignment(body, p)]
    if assigns:
        rhs = body[assigns[0] + 1:].strip()
        lhs = body[:assigns[0]].split()
        var = lhs[-1] if lhs else "?"
        if re.match(r"^\[[^\]]*\]\s*(\(.*\))?[^()]*$", rhs):
            return "lambda", f"{var} (lambda)"
        return "data", var
    if re.match(r"^(typedef\s+)?(class|struct|union)\b", body):
        return "class", body.split()[1] if len(body.split()) > 1 else "?"
    if re.match(r"^enum\b", body):
        return "data", ""
    if re.match(r"^\[[^\]]*\]", body):  # a lambda as a statement of its own
        return "lambda", "(lambda)"
    # A function: a name, a parameter list, then qualifiers, a trailing return
    # type or a constructor's initializer list.
    # Template argument lists go first (std::function<void(int)> is no call).
    bare = body
    while True:
        b2 = re.sub(r"(?<!operator)(?<!operator )<[^<>;{}]*>", "", bare)
        if b2 == bare:
            break
        bare = b2
    op = r"operator\s*(?:\(\)|[^\s(]+)"
    m = re.search(rf"((?:{op}|[A-Za-z_~]\w*)(?:\s*::\s*(?:{op}|[A-Za-z_~]\w*))*)\s*\(", bare)
    if m and not _KEYWORD_HEADS.match(bare) and ")" in bare[m.end():]:
        return "function", re.sub(r"\s+", "", m.group(1))
    return "data", ""


def member_init(head: str) -> bool:
    """True when ``head`` is a constructor declaration whose initializer list
    ends in a member name, so the ``{`` that follows brace-initializes it."""
    h = " ".join(head.split())
    m = re.search(r"\)\s*(?:noexcept\s*)?:(?!:)(.*)$", h)
    return bool(m) and bool(re.search(r"[\w>]\s*$", m.group(1))) and not re.search(r"\btry\s*$", m.group(1))


def scan(path: Path, text: str | None = None) -> list[Span]:
    src = blank(path.read_text() if text is None else text)
    spans: list[Span] = []
    # Each open brace: (kind, name, decl_line)
    stack: list[tuple[str, str, int]] = []
    head: list[str] = []  # text of the current declaration at an outer scope
    head_line = 0
    line = 1
    # Depth inside a function/lambda body being measured: while > 0 we only match braces.
    inner = 0
    # Depth inside braces that belong to a declaration's head (a lambda or a
    # braced value in a constructor's initializer list): folded to "{}".
    fold = 0
    parens = 0  # ( and [ open in the head

    def outer_scope() -> bool:
        return not stack or stack[-1][0] in ("namespace", "class", "data")

    for c in src:
        if c == "\n":
            line += 1
            if inner == 0 and head:
                head.append(" ")
            continue
        if inner > 0:
            if c == "{":
                inner += 1
            elif c == "}":
                inner -= 1
                if inner == 0:
                    kind, name, start = stack.pop()
                    spans.append(Span(str(path), start, name, line - start + 1))
                    head, head_line, parens = [], 0, 0
            continue
        if fold > 0:
            if c == "{":
                fold += 1
            elif c == "}":
                fold -= 1
                if fold == 0:
                    head.append("{}")
            continue
        if c in "([":
            parens += 1
        elif c in ")]":
            parens = max(0, parens - 1)
        if c == "{" and outer_scope() and (parens > 0 or member_init("".join(head))):
            fold = 1
            continue
        if c == "{":
            kind, name = classify("".join(head)) if outer_scope() else ("block", "")
            if stack and stack[-1][0] == "data":
                # Inside an initializer only lambdas are bodies; other braces are data.
                text = " ".join("".join(head).split())
                if kind == "lambda" or re.search(r"\[[^\]]*\]\s*(\([^{}]*\))?[^(){}\[\]]*$", text):
                    owner = next((n for k, n, _ in reversed(stack) if k == "data" and n), "?")
                    kind, name = "lambda", f"{owner} (lambda)"
                else:
                    kind = "data"
            start = head_line or line
            if kind in ("function", "lambda"):
                stack.append((kind, name, start))
                inner = 1
                continue
            stack.append((kind, name, start))
            head, head_line, parens = [], 0, 0
            continue
        if c == "}":
            if stack:
                stack.pop()
            head, head_line, parens = [], 0, 0
            continue
        if c == ";" or (c == "," and stack and stack[-1][0] == "data"):
            head, head_line, parens = [], 0, 0
            continue
        if c == ":" and stack and stack[-1][0] == "class" and re.fullmatch(
                r"\s*(public|private|protected)\s*", "".join(head)):
            head, head_line, parens = [], 0, 0
            continue
        if not c.isspace() and not head_line:
            head_line = line
        head.append(c)
    return spans


def files_under(paths: list[Path]) -> list[Path]:
    out: list[Path] = []
    for p in paths:
        if p.is_dir():
            out += sorted(f for f in p.rglob("*") if f.suffix in SUFFIXES and f.is_file())
        elif p.suffix in SUFFIXES:
            out.append(p)
    return out


def long_functions(paths: list[Path], limit: int = DEFAULT_MAX) -> list[Span]:
    found = [s for f in files_under(paths) for s in scan(f) if s.length > limit]
    return sorted(found, key=lambda s: -s.length)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--max", type=int, default=DEFAULT_MAX, help="longest allowed, in lines")
    ap.add_argument("--all", action="store_true", help="list every function, not only long ones")
    ap.add_argument("paths", nargs="*", default=["cpp", "bindings"])
    a = ap.parse_args(argv)
    paths = [Path(p) for p in a.paths]
    spans = ([s for f in files_under(paths) for s in scan(f)] if a.all
             else long_functions(paths, a.max))
    for s in spans:
        print(f"{s.path}:{s.line} {s.name} {s.length}")
    return 1 if (spans and not a.all) else 0


if __name__ == "__main__":
    sys.exit(main())
