#!/usr/bin/env bash
# Runs every libFuzzer target in fuzz/ for SECONDS each (built by tools/sanitize.sh
# into build/asan, or built here).  Usage: tools/fuzz.sh run SECONDS
# FUZZ_TARGETS="sdo_server slcan_decoder" runs only those targets (names without fuzz_).
# Prints libFuzzer's final stats per target: executions, and executions/s.
set -euo pipefail
cd "$(dirname "$0")/.."
SECS=${2:-5}
JOBS=${JOBS:-$(nproc)}
if ! ls build/asan/fuzz_* >/dev/null 2>&1; then
  CC=clang CXX=clang++ cmake -S . -B build/asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
    -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -g" -DMOTORBUS_FUZZ=ON -DMOTORBUS_PYTHON=OFF >/dev/null
fi
cmake --build build/asan -j"$JOBS" >/dev/null
n=0
for f in build/asan/fuzz_*; do
  [ -x "$f" ] || continue
  name=$(basename "$f")
  if [ -n "${FUZZ_TARGETS:-}" ] && ! [[ " $FUZZ_TARGETS " == *" ${name#fuzz_} "* ]]; then continue; fi
  corpus=fuzz/corpus-$name; mkdir -p "$corpus"
  seeds=(); [ -d "fuzz/seeds/${name#fuzz_}" ] && seeds=("fuzz/seeds/${name#fuzz_}")
  echo "== $name (${SECS}s)"
  out=$(ASAN_OPTIONS=detect_leaks=1 "$f" -max_total_time="$SECS" -rss_limit_mb=2048 -timeout=10 \
    -print_final_stats=1 "$corpus" "${seeds[@]}" 2>&1) || { echo "$out" | tail -40; exit 1; }
  echo "$out" | grep -E '^(#[0-9]+ +DONE|Done )' | tail -1
  execs=$(echo "$out" | sed -n 's/^stat::number_of_executed_units: *//p')
  rate=$(echo "$out" | sed -n 's/^stat::average_exec_per_sec: *//p')
  echo "fuzz-stats $name executions=${execs:-?} exec/s=${rate:-?} seconds=$SECS"
  n=$((n+1))
done
echo "fuzz: $n targets ran ${SECS}s each without a crash"
