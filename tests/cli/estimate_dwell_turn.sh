#!/usr/bin/env bash
# The box dwells' turn witness (docs/estimator.md section 1d), on logs from the outsider's generator
# (tests/estimator/navgen.py, written apart from twin/), each with ref_q: what biases a dwell update
# is the box's mean rate over the samples it averages (ref_q's slope over the dwell), set against
# what that update resolves (its sigma), not ref_q's peak turn in 1 s windows (stop 29's witness,
# which refused 191 of 248 real rests on Fig. 9: the window that held the end of a move).
# - a box holding its pose but shaking about up, 0.2 deg/s at 2 Hz (zero mean; ref_q swings
#   0.032 deg peak to peak, above the 0.01 deg that 1 s windows allowed): the dwells are used as on
#   a still box. Before: none used, vertical_unobserved, 91 deg/h against 3.7 on the still box.
# - a box yawing steadily at 0.02 deg/s: every dwell refused as turning, none used, the unobserved
#   vertical named.
# - at 0.005 deg/s, half the 1 s windows' limit: refused too (the slope is several times the dwell
#   row's sigma). Before: all 25 dwells used, the turn taken as g-sensitivity, 14.5 deg/h.
# - a car whose turns' ends fall inside its pauses: those ends are cut off, the pauses used.
# usage: estimate_dwell_turn.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1; src=$2
source "$src/tests/cli/lib/outsider_log.sh"
gen=$src/tests/estimator/navgen.py
json() { "$py" -c "import json,sys; d=json.load(open(sys.argv[1])); print($2)" "$1"; }
# an uncalibrated BMI088 pair (F28's), 600 s, flips every 20 s
log() { "$py" "$gen" --out "$t/$1.csv" --sensor bmi088 --scale 0.01 --misalign 0.3 --gsens 0.05 --duration 600 \
  --seed 231 "${@:2}" > /dev/null || fail "generator $1"; }
run() { "$bin" estimate --log "$t/$1.csv" --out "$t/$1" --selfcal > "$t/$1.out" 2>&1 || fail "$1: exit $?: $(cat "$t/$1.out")"; }
dwells() { json "$t/$1/summary.json" "d['box_dwells']"; }

# GIVEN a still box and the same box shaking about up
log still --motion static
log shake --motion shake --shake-dps 0.2 --shake-hz 2
run still
run shake
# THEN the shaking box's dwells are used as the still box's, none refused as turning, and its
# heading drifts no more than twice the still box's + 2 deg/h
n_still=$(json "$t/still/summary.json" "d['box_dwells']['updates']")
[ "$n_still" -ge 20 ] || fail "still box: $(dwells still)"
[ "$(json "$t/shake/summary.json" "d['box_dwells']['updates']")" = "$n_still" ] || fail "shake: $(dwells shake) against $n_still"
[ "$(json "$t/shake/summary.json" "d['box_dwells']['refused_turning']")" = 0 ] || fail "shake: $(dwells shake)"
[ "$(json "$t/shake/summary.json" "'vertical_unobserved' in [f['cause'] for f in d['health']['findings']]")" = False ] ||
  fail "shake: vertical_unobserved: $(cat "$t/shake.out")"
drift() { json "$t/$1/summary.json" "abs(d['attitude_drift_deg_per_h']['with_driftless'])"; }
awk -v s="$(drift shake)" -v r="$(drift still)" 'BEGIN {exit !(s <= 2 * r + 2)}' || fail "shake drifts $(drift shake) deg/h, still $(drift still)"

# GIVEN boxes yawing steadily at 0.02 and 0.005 deg/s THEN no dwell is used, every one is refused
# as turning, and the unobserved vertical is named
for rate in 0.02 0.005; do
  log "yaw$rate" --motion slowyaw --yaw-rate "$rate"
  run "yaw$rate"
  [ "$(json "$t/yaw$rate/summary.json" "d['box_dwells']['updates']")" = 0 ] || fail "yaw $rate: dwells used: $(dwells "yaw$rate")"
  [ "$(json "$t/yaw$rate/summary.json" "d['box_dwells']['refused_turning']")" -ge 20 ] || fail "yaw $rate: $(dwells "yaw$rate")"
  grep -q "vertical_unobserved\|Let the box pause" "$t/yaw$rate.out" || fail "yaw $rate: not named: $(cat "$t/yaw$rate.out")"
done
# GIVEN the outsider's car (uncalibrated MPU6050 pair, 90 deg turns every 40 s, 2 s flips): each
# turn is below the 2 deg/s quiet limit over its first and last 0.5 s, so its ends fall inside the
# pauses before and after it THEN they are cut off (the dwell's end pieces), not the pause: no dwell
# refused as turning or rejected, 25 or more used (refusing whole pauses left 9 of 29)
"$py" "$gen" --out "$t/car.csv" --sensor mpu6050 --bias 2 --scale 0.01 --misalign 0.3 --gsens 0.05 --motion car \
  --flip-s 2 --duration 600 > /dev/null || fail "generator car"
"$bin" estimate --log "$t/car.csv" --out "$t/car" --selfcal --tune auto > "$t/car.out" 2>&1 || fail "car: exit $?: $(cat "$t/car.out")"
[ "$(json "$t/car/summary.json" "d['box_dwells']['updates'] >= 25 and d['box_dwells']['refused_turning'] == 0 and d['box_dwells']['rejected'] == 0")" = True ] ||
  fail "car: $(dwells car)"
echo "ok"
