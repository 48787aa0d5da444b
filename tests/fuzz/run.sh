#!/usr/bin/env bash
# Builds the libFuzzer harnesses (clang, ASan, UBSan: the main project configured with
# -DDRIFTLESS_SANITIZE=ON -DDRIFTLESS_FUZZ=ON, tests/fuzz/CMakeLists.txt) and runs each for a
# bounded time on a copy of its corpus (tests/fuzz/corpus/<name>). Any crash, sanitizer report,
# timeout or out-of-memory is a finding: the script prints it and exits 1.
# Usage: tests/fuzz/run.sh [BUILD_DIR] [SECONDS_PER_HARNESS] [all|build|run]
#   all (default): build, then run; build: only configure and build the harnesses and the
#   libraries they link; run: only run the harnesses already built in BUILD_DIR (BUILD_DIR/fuzz/).
#   CI builds them in its sanitizer build folder (.ci/run), with the sanitizer suite's programs.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-"$root/build-fuzz"}
seconds=${2:-15}
step=${3:-all}
case $step in
  all|build|run) ;;
  *) echo "fuzz: step '$step': expected all, build or run" >&2; exit 2 ;;
esac
if [[ $step != run ]]; then
  command -v clang++ >/dev/null || { echo "fuzz: clang++ not found (scripts/setup.sh installs clang)"; exit 1; }
  # the flags of CI's instrumented build (.ci/run), so the objects are shared through ccache
  # a folder configured by the harnesses' former project of their own (tests/fuzz alone) is rebuilt
  if grep -qs "^CMAKE_HOME_DIRECTORY:INTERNAL=$root/tests/fuzz\$" "$build/CMakeCache.txt"; then
    echo "fuzz: $build was configured from tests/fuzz alone (before the harnesses joined the main project): starting it afresh"
    rm -rf "$build"
  fi
  CC=clang CXX=clang++ BUILD_TYPE=Debug BUILD_TARGET=fuzzers bash "$root/scripts/build.sh" "$build" \
    -DDRIFTLESS_SANITIZE=ON -DDRIFTLESS_FUZZ=ON -DBUILD_SHARED_LIBS=ON -DDRIFTLESS_BUILD_BENCHMARKS=OFF \
    -DDRIFTLESS_BUILD_TESTS=OFF
fi
[[ $step == build ]] && exit 0
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# one harness per core at a time: each runs single-threaded for its bounded time, so the stage takes
# about ceil(harnesses / cores) x SECONDS instead of harnesses x SECONDS. DRIFTLESS_FUZZ_JOBS sets
# how many at once (CI: 1, beside the sanitizer suite, which keeps the other core)
fuzz_one() {
  local name=$1 corpus=$2
  local work="$build/fuzz/work/$name" log="$build/fuzz/$name.log"
  mkdir -p "$work"
  # new inputs go to the work folder; the committed corpus is read, never written
  if "$build/fuzz/fuzz_$name" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
       -artifact_prefix="$build/fuzz/$name-" "$work" "$corpus" > "$log" 2>&1; then
    echo "fuzz $name: $(grep -m1 'stat::number_of_executed_units' "$log" | awk '{print $2}') runs, no finding"
    # the inputs it made are not kept (CI's disk is shared; the committed corpus is what a run reads)
    rm -rf "$work"
  else
    echo "fuzz $name: FINDING (full log: $log)"; tail -40 "$log"; return 1
  fi
}
cores=${DRIFTLESS_FUZZ_JOBS:-$(nproc 2>/dev/null || echo 2)}
[[ $cores =~ ^[1-9][0-9]*$ ]] || { echo "fuzz: DRIFTLESS_FUZZ_JOBS='$cores': expected a positive whole number" >&2; exit 2; }
status=0
pids=()
for corpus in "$root"/tests/fuzz/corpus/*/; do
  while (( $(jobs -rp | wc -l) >= cores )); do wait -n || status=1; done
  fuzz_one "$(basename "$corpus")" "$corpus" &
  pids+=($!)
done
# wait for each remaining harness by pid: 'wait -n' above already reaped some, and waiting on a
# reaped pid returns its saved status in bash
for pid in "${pids[@]}"; do wait "$pid" || status=1; done
exit $status
