#!/usr/bin/env bash
# CI's second pass: the sanitizer build (ASan+UBSan), the fuzz harnesses' build, then the suite
# under the sanitizers with the fuzzers running beside it. .ci/run starts it at once, beside the
# README's test command, in a session of its own at the lowest CPU and I/O priority: its builds take
# only what the Release pass leaves idle. Its suite runs at the normal priority: with a warm cache
# the builds finish in seconds and the suite shares the machine with the Release suite (whose
# real-time and signal tests mostly wait) instead of starting after it.
# usage: .ci/second_pass.sh ROOT CI_START_SECONDS   (output: ROOT/build-asan/pass.log, from .ci/run)
set -euo pipefail
root=$1
ci_start=$2
cd "$root"
# where the kernel shares the CPU between sessions first (sched_autogroup, Debian's default), a
# nice value only ranks a process inside its session's group: the group's nice is set too
echo 19 > /proc/self/autogroup 2> /dev/null || true
at() { echo "== second pass: $1 at CI second $(( $(date +%s) - ci_start ))"; }
# drop_intermediates BUILD_DIR: .ci/run's, exported to this script (with CI=true a build drops its
# objects once its programs are linked; ccache keeps them)

# The sanitizer build links our libraries as shared libraries: each of its test programs then holds
# its own code only, not a copy of the libraries under ASan (build-asan took 4.0 GB of disk,
# 2026-11-24). It compiles only what its suite runs: no benchmarks, and not the programs of the
# tests labelled 'slow', which its suite skips (below); they run in the Release pass.
BUILD_TYPE=Debug bash scripts/build.sh "$root/build-asan" -DDRIFTLESS_SANITIZE=ON -DDRIFTLESS_BUILD_BENCHMARKS=OFF \
  -DBUILD_SHARED_LIBS=ON -DDRIFTLESS_BUILD_SLOW_TESTS=OFF
drop_intermediates "$root/build-asan"
bash tests/fuzz/run.sh "$root/build-fuzz" 0 build
drop_intermediates "$root/build-fuzz"
at "sanitizer and fuzz builds done"
# the suite runs at the normal priority, beside the Release suite if that still runs (with a warm
# cache): a test at the lowest priority beside a busy pass would get ~1.5 % of a core and its
# real-time waits could time out. Raising a priority needs root or CAP_SYS_NICE; without them the
# suite waits for .ci/run to do it when the Release pass is over (which needs them too).
echo 0 > /proc/self/autogroup 2> /dev/null || true
renice -n 0 -p $$ > /dev/null 2>&1 || true
ionice -c 2 -n 4 -p $$ > /dev/null 2>&1 || true

# The fuzz harnesses run beside the sanitizer suite, one at a time (libFuzzer + ASan + UBSan,
# clang), each for a bounded time: the suite keeps the other core plus what the fuzzer leaves.
fuzz_log="$root/build-fuzz/runs.log"
DRIFTLESS_FUZZ_JOBS=1 bash tests/fuzz/run.sh "$root/build-fuzz" "${DRIFTLESS_FUZZ_SECONDS:-8}" run > "$fuzz_log" 2>&1 &
fuzz_runs=$!

export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1:halt_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export LSAN_OPTIONS=suppressions=$root/.ci/lsan.supp:print_suppressions=0
export DRIFTLESS_TEST_CPU_LOG="$root/build-asan/test-cpu.log"
rm -f "$DRIFTLESS_TEST_CPU_LOG"
# The sanitizer run skips the tests labelled 'slow' (they pass in the Release pass at full speed) and
# these, which the Release pass runs too: Monte-Carlo repeats and statistical claims that
# rerun, many times over or at length, code that other tests drive under the sanitizer (the
# calibration fit and its evaluation: CalibEvaluate.*; the FDI detector; the sweep runner and Open
# MPI launch; the auto-tuner: TuneTest.RecoversNoiseDensityAndRandomWalk and six more TuneTest.*
# (TuneTest.TheRandomWalkIsUnbiasedOverSeeds repeats that tuning over seeds: 10.2 s of the
# sanitizer suite's CPU in the cold CI of 2026-12-02, its costliest GoogleTest); the Allan fit's rate of
# false low-pass findings over 60 white-noise records (AllanFit.WhiteNoiseIsRarelyCalledLowPassed: 5.9 s
# of the suite's CPU, 0.5 s in Release, 2026-12-02; the fit: the other AllanFit.*); the filter over a
# twin run: FilterTest.*, PipelineTest.*), and the look test, whose time is Chromium, ffmpeg and awk
# reading pixels (its demo and render commands run under the sanitizer in cli.demo_checks and
# cli.render). Under the sanitizers these took 34 s of the pass's 266 s (CI log, 2026-11-24).
# Two end-to-end scripts whose commands, options and code other tests drive under the sanitizer
# (17 s of the pass's 263 s, CI log of 2026-11-24 19:07): cli.euroc_diagnose (convert --ref of an
# EuRoC layout: cli.convert; diagnose of a single-sensor log: SingleImu.*, and the diagnose command
# in cli.compare and cli.full_disk) and cli.estimate_selfcal (estimate --selfcal --box-at-rest:
# cli.estimate_selfcal_calib; the self-calibration at rest, from dwells and without them:
# SelfCalTest.*, CalibSelfcal.*).
monte_carlo='^(Calibration\.ReportedSigmaMatchesMonteCarloSpread|Fdi\.NoFalseAlarmOverManySeeds|cli\.sweep|cli\.sweep_mpi'
monte_carlo+='|CalibEvaluate\.CalibrationCutsTheDynamicBiasErrorFiveFold|TuneTest\.AutoTunedFilterIsConsistentOnTenTimesTheNoise'
monte_carlo+='|TuneTest\.TheRandomWalkIsUnbiasedOverSeeds'
monte_carlo+='|AllanFit\.WhiteNoiseIsRarelyCalledLowPassed'
monte_carlo+='|FilterConsistencyTest\.DefaultScenarioNisAndNeesInTheirBands|PipelineTest\.AWanderingBiasMakesTheFixedBiasDriftButNotDriftLess'
monte_carlo+='|cli\.look|cli\.euroc_diagnose|cli\.estimate_selfcal)$'
echo "== sanitizer suite, and fuzzing beside it"
suite_status=0
# one test more than cores: the pass's real-time and signal tests mostly wait, and a waiting test
# would hold a core's slot
(cd "$root/build-asan" && ctest --output-on-failure -j "$(( $(nproc 2>/dev/null || echo 2) + 1 ))" --timeout 900 \
   -LE slow -E "$monte_carlo") || suite_status=$?
at "sanitizer suite done"
fuzz_status=0
wait "$fuzz_runs" || fuzz_status=$?
cat "$fuzz_log"
at "fuzzing done"
(( suite_status == 0 )) || { echo "== the sanitizer suite failed (above)"; exit 1; }
(( fuzz_status == 0 )) || { echo "== fuzzing found something (above; logs in $root/build-fuzz)"; exit 1; }
