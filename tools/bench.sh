#!/usr/bin/env bash
# Runs every benchmark: the C++ ones built into build/dev (bench_*) and the
# Python ones in bench/*.py, each of which runs its reference library in the
# same process and prints ratios.  Output: one JSON line per measurement.
# Helpers that are not benchmarks (peers the benchmarks spawn) live in
# bench/helpers/, which this runner does not look into.
# Usage: tools/bench.sh PYTHON [filter]
set -uo pipefail
PY=${1:-python3}
FILTER=${2:-}
# A relative PYTHON (.venv/bin/python) is made absolute before the cd below.
# Not realpath: resolving the venv's symlink would leave the venv.
[[ "$PY" == */* && "$PY" != /* ]] && PY="$(cd "$(dirname "$PY")" && pwd)/$(basename "$PY")"
cd "$(dirname "$0")/.."
# The C++ benchmarks run their reference side (pyserial, python-can, canopen)
# with this interpreter (bench/cpp/bench_python.hpp); the system python3 lacks
# those packages and every C++ ratio would read "reference unavailable".
export MOTORBUS_BENCH_PYTHON="$PY"
echo "# $(date -u +%F) $(uname -m) $(nproc) cores; $(g++ --version | head -1); $($PY --version)"
for b in build/dev/bench_*; do
  [ -x "$b" ] || continue
  [[ -n "$FILTER" && "$b" != *"$FILTER"* ]] && continue
  echo "## $b"
  timeout 600 "$b" || echo "{\"bench\": \"$b\", \"error\": $?}"
done
for b in bench/*.py; do
  [[ -n "$FILTER" && "$b" != *"$FILTER"* ]] && continue
  echo "## $PY $b"
  timeout 900 "$PY" "$b" || echo "{\"bench\": \"$b\", \"error\": $?}"
done
