#!/usr/bin/env bash
# Runs the C++ suites and the threaded Python tests under AddressSanitizer +
# UndefinedBehaviorSanitizer (clang; this build also holds the fuzz targets),
# then the C++ suites under ThreadSanitizer.  Usage: tools/sanitize.sh PYTHON
# Debug info: -gline-tables-only, the file:line of every frame of a sanitizer's report at a
# fraction of full -g's compile and link time (the stage's build is most of its minutes).
set -euo pipefail
PY=${1:-python3}
cd "$(dirname "$0")/.."
JOBS=${JOBS:-$(nproc)}
PYBIND11_DIR=$("$PY" -m pybind11 --cmakedir)
LAUNCHER=(); command -v ccache >/dev/null && LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)

echo "== ASan+UBSan build (clang)"
CC=clang CXX=clang++ cmake -S . -B build/asan -G Ninja "${LAUNCHER[@]}" \
  -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" \
  -DMOTORBUS_TESTS=ON -DMOTORBUS_FUZZ=ON -DMOTORBUS_PYTHON=ON \
  -Dpybind11_DIR="$PYBIND11_DIR" -DPython_EXECUTABLE="$(command -v "$PY")" >/dev/null
cmake --build build/asan -j"$JOBS"
echo "== C++ suites under ASan+UBSan"
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build/asan --output-on-failure -j"$JOBS"

echo "== threaded Python tests under ASan+UBSan"
# A throw-away package dir: the pure-Python sources plus the sanitized _core.
# python -S skips site .pth files, so the editable install cannot shadow it.
stage=build/asan/pystage
rm -rf "$stage" && mkdir -p "$stage"
cp -r python/motorbus "$stage/"
rm -f "$stage"/motorbus/_core*.so
# The sanitized _core and the vendors' data files (motorbus/drives/<vendor>/*.eds...),
# placed by CMake's own install rules exactly where a wheel has them.
cmake --install build/asan --prefix "$stage" >/dev/null
SITE=$("$PY" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')
ASAN_RT=$(clang -print-file-name=libclang_rt.asan-x86_64.so)
[ -f "$ASAN_RT" ] || ASAN_RT=$(find /usr/lib/llvm-*/lib/clang -name 'libclang_rt.asan-x86_64.so' | head -1)
# Three pytest-xdist workers (they mostly wait, as in `make py-test`), each started with -S too (a wrapper: xdist's own workers
# would load the site .pth files and import the editable, unsanitized package).
PY_ABS="$(cd "$(dirname "$(command -v "$PY")")" && pwd)/$(basename "$PY")"   # the venv's, not resolved
printf '#!/bin/sh\nexec %s -S "$@"\n' "$PY_ABS" > "$stage/python-S"
chmod +x "$stage/python-S"
LD_PRELOAD="$ASAN_RT" ASAN_OPTIONS=detect_leaks=0:abort_on_error=1 \
  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 PYTHONPATH="$stage:$SITE" \
  "$PY" -S -m pytest -q -p no:cacheprovider -m threaded --dist loadfile \
  --tx "${PYTEST_WORKERS:-3}*popen//python=$stage/python-S" tests/python tests/interop

echo "== C++ suites under TSan (clang)"
LAUNCHER=(); command -v ccache >/dev/null && LAUNCHER=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
# clang: g++ 12 reports false -Wstringop-overflow/-Warray-bounds under -fsanitize at -O1.
CC=clang CXX=clang++ cmake -S . -B build/tsan -G Ninja "${LAUNCHER[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" -DMOTORBUS_TESTS=ON -DMOTORBUS_PYTHON=OFF \
  -DMOTORBUS_SANITIZE=thread >/dev/null
cmake --build build/tsan -j"$JOBS"
TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1 ctest --test-dir build/tsan --output-on-failure -j"$JOBS"
