#!/usr/bin/env bash
# Runs the libFuzzer targets of a `fuzz` preset build one after the other, each for SECONDS in
# one niced process, and prints executions, coverage and crashes per target.
# Usage: scripts/fuzz.sh BUILD_DIR SECONDS [TARGET...]   (default: every fuzz/fuzz_* of BUILD_DIR)
#   New inputs go to BUILD_DIR/corpus/<target> (the seed corpus fuzz/corpus/<target> is only
#   read), crash, timeout and out-of-memory inputs to BUILD_DIR/crashes/<target>-*, the full
#   logs to BUILD_DIR/logs/<target>.log. Exits 1 when any target found something.
#   FUZZ_RUNS=N also stops a target after N executions (issue-style budgets: "10^6 executions
#   or an hour, whichever first" is FUZZ_RUNS=1000000 with SECONDS=3600).
#   The targets write each input to a scratch file ($TMPDIR); FUZZ_TMPDIR (default /dev/shm when
#   writable, else BUILD_DIR/tmp) keeps those writes off the disk.
set -euo pipefail
build=$(cd "${1:?usage: scripts/fuzz.sh BUILD_DIR SECONDS [TARGET...]}" && pwd)
seconds=${2:-60}
shift 2 || shift $#
source_dir=$(cd "$(dirname "$0")/.." && pwd)
targets=("$@")
if [[ ${#targets[@]} -eq 0 ]]; then
  for binary in "$build"/fuzz/fuzz_*; do targets+=("$(basename "$binary" | sed 's/^fuzz_//')"); done
fi
mkdir -p "$build/crashes" "$build/logs" "$build/tmp"
scratch=${FUZZ_TMPDIR:-$build/tmp}
[[ -z "${FUZZ_TMPDIR:-}" && -w /dev/shm ]] && scratch=/dev/shm
printf '%-14s %12s %8s %8s %8s %s\n' target executions exec/s cov ft result
found=0
for name in "${targets[@]}"; do
  work="$build/corpus/$name"
  log="$build/logs/$name.log"
  mkdir -p "$work"
  # -timeout: an input running longer is reported as a hang; -rss_limit_mb also bounds single
  # allocations (malloc_limit_mb defaults to it), so an unbounded size read from a file is a
  # finding rather than a swapping machine.
  status=0
  TMPDIR="$scratch" nice -n 10 "$build/fuzz/fuzz_$name" -max_total_time="$seconds" \
    -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 -runs="${FUZZ_RUNS:--1}" \
    -artifact_prefix="$build/crashes/$name-" "$work" "$source_dir/fuzz/corpus/$name" \
    >"$log" 2>&1 || status=$?
  executions=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  last=$(grep -E '^#[0-9]+' "$log" | tail -1 || true)
  cov=$(sed -n 's/.* cov: \([0-9]*\).*/\1/p' <<<"$last")
  ft=$(sed -n 's/.* ft: \([0-9]*\).*/\1/p' <<<"$last")
  result=ok
  if [[ $status -ne 0 ]]; then
    found=1
    result="FOUND ($(grep -m1 -oE 'ERROR: [A-Za-z]+: [^ ]+( [^ ]+)?|deadly signal|timeout|out-of-memory' "$log" || echo "exit $status")); see $log"
  fi
  printf '%-14s %12s %8s %8s %8s %s\n' "$name" "${executions:-?}" "${rate:-?}" "${cov:-?}" "${ft:-?}" "$result"
done
exit $found
