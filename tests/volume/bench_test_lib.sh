# Sourced by the rtfact-bench volume tests: their arguments (RTFACT_BENCH DATASETS_DIR OUT_DIR),
# failing with a message, running the benchmark into a log, and reading figures from it.
set -uo pipefail
bench="$1" data="$2" out="$3"
mkdir -p "$out"
fail() {
  echo "FAIL: $*"
  exit 1
}
# run_bench LOG ARGS...: rtfact-bench ARGS without DISPLAY (with BENCH_PATH as its PATH when
# set), its output in LOG and printed; a non-zero exit fails the test.
run_bench() {
  local log="$1"
  shift
  /usr/bin/env -u DISPLAY ${BENCH_PATH:+PATH="$BENCH_PATH"} "$bench" "$@" >"$log" 2>&1
  local rc=$?
  cat "$log"
  [ "$rc" -eq 0 ] || fail "rtfact-bench $* exited with $rc"
}
# value LOG KEY: the first KEY=number in LOG.
value() { grep -o "$2=[0-9.]*" "$1" | head -1 | cut -d= -f2; }
# at_least V MIN WHAT: V >= MIN, else the test fails naming WHAT.
at_least() { awk -v v="$1" -v m="$2" 'BEGIN { exit !(v >= m) }' || fail "$3: $1 < $2"; }
