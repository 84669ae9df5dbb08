#!/usr/bin/env bash
# Runs every benchmark: the C++ ones built into build/dev (bench_*) and the
# Python ones in bench/*.py, each of which runs its reference library in the
# same process and prints ratios.  Output: one JSON line per measurement.
# Usage: tools/bench.sh PYTHON [filter]
set -uo pipefail
PY=${1:-python3}
FILTER=${2:-}
cd "$(dirname "$0")/.."
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
