#!/usr/bin/env bash
# End-to-end: driftless simulate writes a loadable resolved scenario and a complete log; the same
# seed gives the same bytes; bad input exits non-zero with a message naming file, line and key;
# SIGINT leaves a valid log marked complete: false.
set -uo pipefail
bin=$1
src=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# a short run of each shipped scenario; resolved yaml loads again
"$bin" simulate --scenario "$src/models/scenarios/pan_tilt.yaml" --out "$tmp/a" --duration 3 --seed 5 >/dev/null || fail "simulate pan_tilt"
grep -q "^# complete: true" "$tmp/a/log.csv" || fail "log not complete"
"$bin" check --log "$tmp/a/log.csv" >/dev/null || fail "check rejects the log"
"$bin" simulate --scenario "$tmp/a/scenario.resolved.yaml" --out "$tmp/b" >/dev/null || fail "resolved scenario does not load"
cmp -s "$tmp/a/log.csv" "$tmp/b/log.csv" || fail "resolved scenario gives another log"
"$bin" simulate --scenario pan_tilt --out "$tmp/c" --duration 3 --seed 5 >/dev/null || fail "built-in by name"
cmp -s "$tmp/a/log.csv" "$tmp/c/log.csv" || fail "same seed, different bytes"
"$bin" simulate --out "$tmp/d" --duration 2 >/dev/null || fail "default scenario"

# bad input: non-zero exit and a message naming what is wrong
expect_error() {  # name, pattern, yaml
  printf '%s' "$3" > "$tmp/$1.yaml"
  out=$("$bin" simulate --scenario "$tmp/$1.yaml" --out "$tmp/x" 2>&1) && fail "$1: exit code 0"
  grep -q -- "$2" <<< "$out" || fail "$1: message '$out' lacks '$2'"
}
expect_error unknown_key "unknown_key.yaml:3: flip_schedule.standstil_s: unknown key" $'duration_s: 5\nflip_schedule:\n  standstil_s: 4\n'
expect_error units2 "units2.yaml:3: motion.max_rate_deg: inconsistent units" $'motion:\n  type: pan_tilt\n  max_rate_deg: 50\n'
expect_error duplicate "duplicate.yaml:3: duration_s: key given twice (lines 1 and 3)" $'duration_s: 5\nseed: 2\nduration_s: 6\n'
expect_error broken "broken.yaml:.*broken YAML" $'duration_s: 5\nmotion: [static\n'
expect_error badtype "badtype.yaml:2: motion.type: expected one of static, pan_tilt" $'motion:\n  type: rocket\n'
# a duration no disk holds: refused before anything is written
out=$("$bin" simulate --out "$tmp/long" --duration 1e12 2>&1) && fail "duration 1e12: exit 0"
grep -q "duration_s = .* must be in (0, 1e7\] s" <<< "$out" || fail "duration 1e12: message '$out'"
[ ! -e "$tmp/long/log.csv" ] || fail "duration 1e12: a log was started"
out=$("$bin" simulate --scenario "$tmp/missing.yaml" --out "$tmp/x" 2>&1) && fail "missing file: exit 0"
grep -q "missing.yaml" <<< "$out" || fail "missing file: '$out'"

# Ctrl-C: a valid log marked complete: false
"$bin" simulate --scenario vehicle --out "$tmp/int" --duration 36000 >/dev/null 2>&1 &
pid=$!
sleep 1.5
kill -INT $pid
wait $pid
code=$?
[ $code -ne 0 ] || fail "interrupted run exited 0"
grep -q "^# complete: false" "$tmp/int/log.csv" || fail "interrupted log not marked complete: false"
"$bin" check --log "$tmp/int/log.csv" >/dev/null || fail "interrupted log is not valid"
echo "cli simulate: ok"
