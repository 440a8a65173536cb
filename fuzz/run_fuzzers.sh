#!/usr/bin/env bash
# Runs each libFuzzer target for a fixed time and summarises executions and crashes.
#   fuzz/run_fuzzers.sh BUILD_DIR SECONDS [NAME...]     (names: json svg mesh slice pipeline)
# BUILD_DIR is a build configured with -DSTRATA_FUZZ=ON (clang). Each fuzzer starts from its
# seeds (fuzz/corpus/NAME) and the regressions (fuzz/regressions/NAME), grows a working corpus
# in BUILD_DIR/fuzz-work/NAME/corpus (the seeds in the repository are not touched), and saves
# any crashing input there as crash-* / leak-* / timeout-* / oom-*. Exit status: 0 when no
# fuzzer found anything. FUZZ_KEEP_GOING=1: libFuzzer's fork mode (one worker), which goes on
# past a crash and saves every one (for long runs). FUZZ_SEED=N: libFuzzer's -seed (CI uses a
# fixed one, so that a short run repeats the same mutations; 0, the default, a random one).
# STRATA_FUZZ_ROUNDS=N: fuzz_pipeline cancels an untangling after N rounds (default 30 here;
# see fuzz_pipeline.cpp), so that a short run gets past its slow seeds.
set -uo pipefail
export STRATA_FUZZ_ROUNDS="${STRATA_FUZZ_ROUNDS:-30}"
here="$(cd "$(dirname "$0")" && pwd)"
build="$(cd "$1" && pwd)"
seconds="$2"
shift 2
names=("$@")
((${#names[@]})) || names=(json svg mesh slice pipeline)

export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
export LSAN_OPTIONS="${LSAN_OPTIONS:-suppressions=$here/../.ci/lsan.supp}"
status=0
for name in "${names[@]}"; do
  bin="$build/fuzz/fuzz_$name"
  [ -x "$bin" ] || { echo "run_fuzzers: $bin is missing (build target fuzz_$name)" >&2; exit 2; }
  work="$build/fuzz-work/$name"
  mkdir -p "$work/corpus"
  seeds=("$here/corpus/$name")
  [ -d "$here/regressions/$name" ] && seeds+=("$here/regressions/$name")
  # The pipeline's inputs run untanglings: allow each a minute.
  timeout=30
  [ "$name" = pipeline ] && timeout=120
  keep_going=()
  [ "${FUZZ_KEEP_GOING:-0}" = 1 ] && keep_going=(-fork=1 -ignore_crashes=1 -ignore_timeouts=1 -ignore_ooms=1)
  "$bin" "${keep_going[@]}" -seed="${FUZZ_SEED:-0}" -max_total_time="$seconds" -timeout="$timeout" -rss_limit_mb=2560 -max_len=4096 \
    -print_final_stats=1 -artifact_prefix="$work/" "$work/corpus" "${seeds[@]}" \
    >"$work/log.txt" 2>&1
  rc=$?
  execs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$work/log.txt" | grep -o '[0-9]*$' | tail -1)
  # Fork mode prints no final stats: its last "#N: cov: ..." line counts the executions.
  [ -n "$execs" ] || execs=$(grep -o '^#[0-9]*: cov' "$work/log.txt" | tail -1 | tr -dc '0-9')
  cov=$(grep -o 'cov: [0-9]*' "$work/log.txt" | tail -1)
  crashes=$(find "$work" -maxdepth 1 -name 'crash-*' -o -maxdepth 1 -name 'leak-*' \
    -o -maxdepth 1 -name 'timeout-*' -o -maxdepth 1 -name 'oom-*' | wc -l)
  corpus=$(find "$work/corpus" -type f | wc -l)
  echo "fuzz_$name: ${seconds} s, exit $rc, ${execs:-?} executions, ${cov:-cov ?}, corpus $corpus, artifacts $crashes (log $work/log.txt)"
  if [ "$rc" -ne 0 ] || [ "$crashes" -ne 0 ]; then
    status=1
    grep -m3 -E 'ERROR|fuzz invariant|runtime error|Test unit written' "$work/log.txt" | sed 's/^/  /'
  fi
done
exit $status
