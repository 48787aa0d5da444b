#!/usr/bin/env bash
# Builds the libFuzzer harnesses with clang (only the sources each needs) and runs each for a
# bounded time on a copy of its corpus (tests/fuzz/corpus/<name>). Any crash, sanitizer report,
# timeout or out-of-memory is a finding: the script prints it and exits 1.
# Usage: tests/fuzz/run.sh [BUILD_DIR] [SECONDS_PER_HARNESS] [all|build|run]
#   all (default): build, then run; build: only configure and build (CI builds the harnesses beside
#   the Release pass); run: only run the harnesses already built in BUILD_DIR
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
  export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$root} CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-1}
  export CCACHE_MAXSIZE=${CCACHE_MAXSIZE:-1G}   # bounded, as in scripts/build.sh
  export CCACHE_DEPEND=${CCACHE_DEPEND:-1}       # no second preprocessor run on a miss (scripts/build.sh)
  CC=clang CXX=clang++ cmake -S "$root/tests/fuzz" -B "$build" -DCMAKE_BUILD_TYPE=None >/dev/null
  cmake --build "$build" -j "$(nproc 2>/dev/null || echo 2)"
fi
[[ $step == build ]] && exit 0
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
# one harness per core at a time: each runs single-threaded for its bounded time, so the stage takes
# about ceil(harnesses / cores) x SECONDS instead of harnesses x SECONDS. DRIFTLESS_FUZZ_JOBS sets
# how many at once (CI: 1, beside the sanitizer suite, which keeps the other core)
fuzz_one() {
  local name=$1 corpus=$2
  local work="$build/work/$name" log="$build/$name.log"
  mkdir -p "$work"
  # new inputs go to the work folder; the committed corpus is read, never written
  if "$build/fuzz_$name" -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -print_final_stats=1 \
       -artifact_prefix="$build/$name-" "$work" "$corpus" > "$log" 2>&1; then
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
