"""Keeps python/motorbus/_core.pyi in sync with the compiled extension.

    python tools/gen_stubs.py write   # regenerate after changing bindings/
    python tools/gen_stubs.py check   # fail (exit 1) if the committed stub is stale
"""
from __future__ import annotations

import pathlib
import subprocess
import sys
import tempfile

ROOT = pathlib.Path(__file__).resolve().parents[1]
STUB = ROOT / "python" / "motorbus" / "_core.pyi"


def generate() -> str:
    with tempfile.TemporaryDirectory() as out:
        subprocess.run(
            [sys.executable, "-m", "pybind11_stubgen", "motorbus._core", "-o", out,
             "--numpy-array-remove-parameters", "--ignore-all-errors"],
            check=True, capture_output=True, text=True,
        )
        files = list(pathlib.Path(out).rglob("_core.pyi"))
        if not files:
            raise SystemExit("pybind11-stubgen produced no _core.pyi")
        return files[0].read_text()


def main() -> int:
    mode = sys.argv[1] if len(sys.argv) > 1 else "check"
    text = generate()
    if mode == "write":
        STUB.write_text(text)
        print(f"wrote {STUB.relative_to(ROOT)}")
        return 0
    if not STUB.exists() or STUB.read_text() != text:
        print("python/motorbus/_core.pyi is stale: run `make stubs` and commit it", file=sys.stderr)
        return 1
    print("stubs: _core.pyi is in sync with the extension")
    return 0


if __name__ == "__main__":
    sys.exit(main())
