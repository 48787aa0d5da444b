#!/usr/bin/env bash
# The outsider's probe after stop 30 (docs/estimator.md sections 6.1 and 6.4, docs/log-format.md
# "Validation"), on logs from tests/estimator/navgen.py: each mistake that passed silently, or
# was blamed on the wrong cause, is now named with its own cause and fix.
#  1. an MPU6050 whose 1 s flips clip at +-250 deg/s, with a wrong hinge2_axis (axis or sign):
#     flip_axis failed, exit 1 (was ok, exit 0, 11-22 deg/h); the correct log has no flip finding
#  2. a BMI088 log with a wrong hinge axis or angle sign in all of platform 2's flips: failed
#     (was degraded: 14 of 28 flips over both platforms was not "most")
#  3. rests of 0.5 s, shorter than min_standstill_s: standstills_too_short names the rest length
#     (was "the platforms never moved")
#  4. stamps in ns or ms without sample_rate_hz: check exits 1 naming the unit, estimate fails with
#     stamp_unit (was check exit 0, estimate "record more flips")
#  5. a header without data rows: check exits 1, estimate fails with no_data_rows
# usage: estimate_health_probe.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1; src=$2
# shellcheck source=lib/outsider_log.sh
source "$src/tests/cli/lib/outsider_log.sh"
# shellcheck source=lib/navgen_runs.sh
source "$src/tests/cli/lib/navgen_runs.sh"
# the first health finding that is not a note (the clipping MPU6050's saturation notes lead)
skip_notes=1
# check_log NAME WANT_EXIT PATTERN: driftless check's exit code and a line of its output
check_log() {
  "$bin" check --log "$t/$1.csv" > "$t/check_$1.txt" 2>&1
  local rc=$?
  [ "$rc" = "$2" ] || { cat "$t/check_$1.txt"; fail "check $1: exit $rc, expected $2"; }
  grep -q -- "$3" "$t/check_$1.txt" || { cat "$t/check_$1.txt"; fail "check $1: no '$3'"; }
}

# 1. the clipping MPU6050: correct, hinge 2 along y, hinge 2 reversed
$nav --out "$t/mpu.csv" --sensor mpu6050 --seed 4 > /dev/null || fail "navgen mpu"
sed 's/^# hinge2_axis: 1 0 0$/# hinge2_axis: 0 1 0/' "$t/mpu.csv" > "$t/mpu_y.csv"
sed 's/^# hinge2_axis: 1 0 0$/# hinge2_axis: -1 0 0/' "$t/mpu.csv" > "$t/mpu_neg.csv"
grep -q "^# hinge2_axis: 0 1 0$" "$t/mpu_y.csv" || fail "the hinge2_axis edit did not apply"
run mpu 0
if grep -q '"cause": "flip' "$t/o_mpu/summary.json"; then cat "$t/mpu.txt"; fail "mpu: a flip finding on a clean log"; fi
run mpu_y 1; first_finding mpu_y flip_axis failed
run mpu_neg 1; first_finding mpu_neg flip_angle_sign failed

# 2. BMI088 (no clipping): the wrong hinge and the wrong sign in every flip of platform 2
$nav --out "$t/b.csv" --sensor bmi088 --seed 1 > /dev/null || fail "navgen bmi088"
sed 's/^# hinge2_axis: 1 0 0$/# hinge2_axis: 0 1 0/' "$t/b.csv" > "$t/b_axis.csv"
sed 's/^# hinge2_axis: 1 0 0$/# hinge2_axis: -1 0 0/' "$t/b.csv" > "$t/b_sign.csv"
run b_axis 1; first_finding b_axis flip_axis failed
run b_sign 1; first_finding b_sign flip_angle_sign failed

# 3. rests of 0.5 s (flips every 1.5 s)
$nav --out "$t/r.csv" --sensor mpu6050 --rest 0.5 --seed 30 > /dev/null || fail "navgen rests"
run r 1; first_finding r standstills_too_short failed
grep -q "min_standstill_s 1 s" "$t/r.txt" || fail "r: min_standstill_s not named"
grep -q "0.5 s" "$t/r.txt" || fail "r: the rest length not named"
if grep -q "never moved" "$t/r.txt"; then fail "r: still says the platforms never moved"; fi
# AND never_locked, which follows, points at the rests, not at more flips
grep -q "never locked: .*the rests between flips are too short to use" "$t/r.txt" || fail "r: never_locked: $(cat "$t/r.txt")"
if grep -q "record more flips" "$t/r.txt"; then fail "r: never_locked still asks for more flips"; fi

# 4. stamps in ns and in ms, no rate key; ms with the rate key
$nav --out "$t/ns.csv" --sensor mpu6050 --tunit ns --no-rate-key --seed 25 > /dev/null || fail "navgen ns"
$nav --out "$t/ms.csv" --sensor mpu6050 --tunit ms --no-rate-key --seed 25 > /dev/null || fail "navgen ms"
$nav --out "$t/msr.csv" --sensor mpu6050 --tunit ms --seed 25 > /dev/null || fail "navgen ms rate"
check_log ns 1 "t is in nanoseconds"
check_log ms 1 "t is in milliseconds"
check_log msr 1 "t is in milliseconds"
run ns 1; first_finding ns stamp_unit failed
grep -q "divide t by 1e+09" "$t/ns.txt" || fail "ns: the fix is not named"
run ms 1
grep -q '"cause": "stamp_unit"\|"cause": "flip_time_unit"' "$t/o_ms/summary.json" || fail "ms: no unit finding"
run msr 1; first_finding msr stamp_rate failed
# the same log in seconds passes check
check_log mpu 0 "sample interval: 0.010000"

# 5. a header without data rows
grep "^#\|^t," "$t/mpu.csv" > "$t/empty.csv"
check_log empty 1 "no data rows"
run empty 1; first_finding empty no_data_rows failed
grep -q "the log has no data rows" "$t/empty.txt" || fail "empty: not said plainly"
echo "ok"
