#!/usr/bin/env bash
# Runs every libFuzzer target in fuzz/ (built by tools/sanitize.sh into build/asan,
# or built here), each on its own corpus fuzz/corpus-<target> plus fuzz/seeds/<target>.
#   tools/fuzz.sh run SECONDS   each target for SECONDS        (make fuzz-smoke: 3)
#   tools/fuzz.sh runs N        each target for N executions   (make fuzz: 10 000 000)
# FUZZ_TARGETS="sdo_server slcan_decoder" runs only those targets, in that order (names without fuzz_);
# JOBS targets run at once (default: the number of cores).  FUZZ_BIN=DIR runs the
# fuzz_* executables found in DIR instead (copies, so a long run survives rebuilds).  Prints libFuzzer's final
# stats per target (`fuzz-stats NAME executions=N exec/s=R seconds=S`) and fails on
# the first crash, leak, timeout or out-of-memory, with the fuzzer's report.
set -euo pipefail
cd "$(dirname "$0")/.."
MODE=${1:-run}
AMOUNT=${2:-5}
case "$MODE" in
  run) LIMIT=(-max_total_time="$AMOUNT") ;;
  runs) LIMIT=(-runs="$AMOUNT") ;;
  *) echo "usage: tools/fuzz.sh run SECONDS | runs N" >&2; exit 2 ;;
esac
JOBS=${JOBS:-$(nproc)}
BIN=${FUZZ_BIN:-}
if [ -z "$BIN" ]; then
  BIN=build/asan
  if ! ls build/asan/fuzz_* >/dev/null 2>&1; then
    CC=clang CXX=clang++ cmake -S . -B build/asan -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O1 -gline-tables-only" -DMOTORBUS_FUZZ=ON -DMOTORBUS_PYTHON=OFF >/dev/null
  fi
  cmake --build build/asan -j"$JOBS" >/dev/null
fi
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT

one() {  # one target; its whole output goes to $logs/<name>, the verdict to stdout
  local f=$1 name; name=$(basename "$f")
  local corpus=fuzz/corpus-$name; mkdir -p "$corpus"
  local seeds=(); [ -d "fuzz/seeds/${name#fuzz_}" ] && seeds=("fuzz/seeds/${name#fuzz_}")
  local t0=$SECONDS
  if ! ASAN_OPTIONS=detect_leaks=1 "$f" "${LIMIT[@]}" -rss_limit_mb=2048 -timeout=10 \
      -print_final_stats=1 "$corpus" "${seeds[@]}" >"$logs/$name" 2>&1; then
    echo "== $name FAILED"; tail -40 "$logs/$name"; return 1
  fi
  local execs rate
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$logs/$name")
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$logs/$name")
  echo "fuzz-stats $name executions=${execs:-?} exec/s=${rate:-?} seconds=$((SECONDS - t0))"
}

targets=()
if [ -n "${FUZZ_TARGETS:-}" ]; then   # in the order given (e.g. fastest first in a long run)
  for t in $FUZZ_TARGETS; do
    [ -x "$BIN/fuzz_$t" ] || { echo "fuzz: no target fuzz_$t in $BIN" >&2; exit 2; }
    targets+=("$BIN/fuzz_$t")
  done
else
  for f in "$BIN"/fuzz_*; do
    [ -x "$f" ] && targets+=("$f")
  done
fi
echo "fuzz: ${#targets[@]} targets, $MODE $AMOUNT each, $JOBS at once ($(date -u '+%F %H:%M') UTC)"
failed=0
running=0
for f in "${targets[@]}"; do
  # A failing target does not stop the others: a long run reports every finding.
  if (( running >= JOBS )); then wait -n || failed=1; running=$((running - 1)); fi
  one "$f" & running=$((running + 1))
done
while (( running > 0 )); do wait -n || failed=1; running=$((running - 1)); done
(( failed )) && { echo "fuzz: a target failed (its report is above; the crashing input is in ./crash-*)"; exit 1; }
echo "fuzz: ${#targets[@]} targets ran ($MODE $AMOUNT each) without a crash"
