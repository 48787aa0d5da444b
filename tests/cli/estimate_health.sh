#!/usr/bin/env bash
# The health verdict of `driftless estimate` (docs/estimator.md section 6.1): a healthy log says ok
# and exits 0; a log with 6x the noise says degraded with its cause on stderr, exits 0, and 1 with
# --strict, and --tune auto makes it healthy; a log too short to lock exits 1 and says so.
# usage: estimate_health.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1; src=$2
golden=$src/tests/data/estimator_golden/log.csv
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
verdict() { grep -o '"verdict": "[a-z]*"' "$1/summary.json" | cut -d'"' -f4; }

# GIVEN the golden log (noise as configured) THEN ok, exit 0, verdict in summary.json
"$bin" estimate --log "$golden" --out "$t/ok" --strict > "$t/ok.out" 2> "$t/ok.err" || fail "healthy log: exit $?: $(cat "$t/ok.err")"
[[ $(verdict "$t/ok") == ok ]] || fail "healthy log: verdict $(verdict "$t/ok"): $(cat "$t/ok.out" "$t/ok.err")"
grep -q "health: ok: locked at t = " "$t/ok.out" || fail "healthy log: no health line: $(cat "$t/ok.out")"
grep -q '"nis_mean_band_95": \[' "$t/ok/summary.json" || fail "no nis_mean_band_95 in summary.json"

# GIVEN the same log with about 6x its noise added to every gyro column (a seeded awk generator; at 10x
# the windowed update of stop 27 rejects half the updates and ends above the lock level: failed)
awk -F, -v OFS=, 'BEGIN { srand(7) }
  /^#/ || /^t,/ { print; next }
  { for (i = 2; i <= 7; ++i) { u1 = rand(); u2 = rand(); if (u1 < 1e-12) u1 = 1e-12
      $i = sprintf("%.7f", $i + 0.10 * sqrt(-2 * log(u1)) * cos(6.283185307 * u2)) } print }' "$golden" > "$t/noisy.csv"
"$bin" estimate --log "$t/noisy.csv" --out "$t/noisy" > "$t/noisy.out" 2> "$t/noisy.err" || fail "noisy log: exit $? without --strict"
[[ $(verdict "$t/noisy") == degraded ]] || fail "noisy log: verdict $(verdict "$t/noisy"): $(cat "$t/noisy.err")"
grep -q "health: degraded" "$t/noisy.err" || fail "noisy log: no health line on stderr: $(cat "$t/noisy.err")"
grep -q "above its 95 % band" "$t/noisy.err" || fail "noisy log: the cause is not named: $(cat "$t/noisy.err")"
"$bin" estimate --log "$t/noisy.csv" --out "$t/strict" --strict > /dev/null 2> "$t/strict.err"
[[ $? -eq 1 ]] || fail "noisy log with --strict: expected exit 1"
grep -q -- "--strict" "$t/strict.err" || fail "--strict exit not explained"
# WHEN it is tuned from the data THEN the NIS fits again
"$bin" estimate --log "$t/noisy.csv" --out "$t/tuned" --tune auto --strict > "$t/tuned.out" 2> "$t/tuned.err" ||
  fail "noisy log with --tune auto: exit $?: $(cat "$t/tuned.out" "$t/tuned.err")"
grep -q "tune auto: noise density" "$t/tuned.out" || fail "--tune auto says nothing"
grep -q '"noise_estimated": true' "$t/tuned/summary.json" || fail "summary.json lacks the tune block"

# GIVEN the first 15 s only (one standstill: cannot lock) THEN failed, exit 1, named
head -160 "$golden" > "$t/short.csv"
"$bin" estimate --log "$t/short.csv" --out "$t/short" > "$t/short.out" 2> "$t/short.err"
[[ $? -eq 1 ]] || fail "short log: expected exit 1"
[[ $(verdict "$t/short") == failed ]] || fail "short log: verdict $(verdict "$t/short")"
grep -q "never locked" "$t/short.err" || fail "short log: 'never locked' not said: $(cat "$t/short.err")"
[ -s "$t/short/estimate.csv" ] || fail "short log: outputs not written before the exit"
echo "ok"
