#!/usr/bin/env bash
# Inputs that are not the twin's, from the outsider's generator (tests/diagnose/probe_log.py,
# written apart from twin/), each named with its cause (stop-25 findings):
#   P16 a dead gyro axis (empty, or stuck at one value) is named, not "the platforms never rested";
#   P13 --selfcal without accel columns makes flip updates and says G cannot be observed;
#   P6  both platforms flipping together: "never locked" names the positions that occurred;
#   P3  two unlike gyros described by gyro1_/gyro2_full_scale_dps;
#   P8  a repeated time stamp is refused with the way out;
# and (stop-27 findings):
#   F5  a time gap during a turn: the attitude is withheld from the gap, the gap is a warning;
#   F16 sample_rate_hz unlike the stamps (or ms stamps) is named first, with the fix;
#   F3  parallel hinge axes and F24 platforms that never moved are named as such, not "record more flips".
# usage: estimate_foreign_inputs.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1; src=$2
# shellcheck source=lib/outsider_log.sh
source "$src/tests/cli/lib/outsider_log.sh"
json() { "$py" -c "import json,sys; d=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$1/summary.json" "$2"; }
# column $2 (1-based) of every data row replaced by $3
set_column() { awk -F, -v c="$2" -v v="$3" 'BEGIN{OFS=","} /^#/ || $1=="t" {print; next} {$c=v; print}' "$1"; }

"$py" "$gen" --out "$t/base.csv" --sensor bmi088 --seed 2 --duration 200 > /dev/null || fail "generator"

# P16 GIVEN gyro2_z (column 7) empty in every row THEN failed, exit 1, the column named
set_column "$t/base.csv" 7 "" > "$t/dead.csv"
"$bin" estimate --log "$t/dead.csv" --out "$t/dead" > "$t/dead.out" 2>&1
[[ $? -eq 1 ]] || fail "dead axis: expected exit 1: $(cat "$t/dead.out")"
grep -q "failed: gyro2_z is empty (no value) in all 20000 rows" "$t/dead.out" || fail "dead axis not named: $(cat "$t/dead.out")"
grep -q "100.0 % of the rows lack a gyro value" "$t/dead.out" || fail "no_update does not say why: $(cat "$t/dead.out")"
! grep -q "the platforms never rested" "$t/dead.out" || fail "dead axis blamed on the platforms"
# ... and gyro1_y (column 3) stuck at one reading: it was health ok with biases 0.15 deg/s wrong
set_column "$t/base.csv" 3 "0.1220703" > "$t/stuck.csv"
"$bin" estimate --log "$t/stuck.csv" --out "$t/stuck" > "$t/stuck.out" 2>&1
[[ $? -eq 1 ]] || fail "stuck axis: expected exit 1: $(cat "$t/stuck.out")"
[[ $(json "$t/stuck" "d['health']['findings'][0]['cause']") == dead_axis ]] || fail "stuck axis: $(cat "$t/stuck.out")"
grep -q "gyro1_y reads 0.1220703 deg/s in every one" "$t/stuck.out" || fail "stuck axis not named: $(cat "$t/stuck.out")"
"$bin" check --log "$t/stuck.csv" | grep -q "gyro1_y reads 0.1220703 deg/s in all 20000 rows" || fail "check: stuck axis"
# the untouched log has no such finding
"$bin" estimate --log "$t/base.csv" --out "$t/base" > "$t/base.out" 2>&1 || fail "base log: $(cat "$t/base.out")"
! grep -q "dead_axis" "$t/base/summary.json" || fail "base log: a dead axis found"

# P13 GIVEN a turning box without accel columns WHEN --selfcal THEN flip updates are made and the
# warning says what drove G: this log has ref_q, so gravity from it (stop-27 F33; before: "cannot
# be observed")
"$py" "$gen" --out "$t/noaccel.csv" --motion turn --sensor bmi088 --duration 300 > /dev/null || fail "generator"
"$bin" estimate --selfcal --log "$t/noaccel.csv" --out "$t/noaccel" > "$t/noaccel.out" 2>&1 || fail "selfcal: $(cat "$t/noaccel.out")"
[[ $(json "$t/noaccel" "d['flips']['updates'] >= 5 and d['flips']['rejected'] == 0") == True ]] ||
  fail "selfcal without accel: flips $(json "$t/noaccel" "d['flips']")"
grep -q "gravity_source: ref_q: no accel columns, so the g-sensitivity states took gravity from ref_q" "$t/noaccel.out" ||
  fail "selfcal without accel: no word: $(cat "$t/noaccel.out")"
[[ $(json "$t/noaccel" "d['self_calibration']['gravity_source']") == ref_q ]] || fail "selfcal without accel: gravity_source"

# P6 GIVEN both platforms always flipping together THEN never locked, naming the positions that occurred
"$py" "$gen" --out "$t/both.csv" --schedule both --duration 200 > /dev/null || fail "generator"
"$bin" estimate --log "$t/both.csv" --out "$t/both" > "$t/both.out" 2>&1
[[ $? -eq 1 ]] || fail "both together: expected exit 1"
grep -q "the platforms only rested at (-90, -90) and (90, 90) deg" "$t/both.out" || fail "both together: $(cat "$t/both.out")"
grep -q "flip one platform at a time" "$t/both.out" || fail "both together: no fix"

# P3 GIVEN a sensor 1 of +-250 deg/s and a sensor 2 of +-2000 on a box spinning to 600 deg/s
"$py" "$gen" --out "$t/unlike.csv" --motion fast --fs1 250 --sensor bmi088 --seed 12 --duration 100 > /dev/null || fail "generator"
sed 's/^# source:/# gyro_full_scale_dps: 250\n# source:/' "$t/unlike.csv" > "$t/shared.csv"
sed 's/^# source:/# gyro1_full_scale_dps: 250\n# gyro2_full_scale_dps: 2000\n# source:/' "$t/unlike.csv" > "$t/own.csv"
"$bin" check --log "$t/shared.csv" > "$t/shared.out" 2>&1
[[ $? -ne 0 ]] && grep -q "column 'gyro2_.*stated in gyro_full_scale_dps.*gyro2_full_scale_dps" "$t/shared.out" ||
  fail "one shared full scale: $(cat "$t/shared.out")"
"$bin" check --log "$t/own.csv" > "$t/own.out" 2>&1 || fail "own full scales refused: $(cat "$t/own.out")"
grep -q "stated full scale of 250 / 2000 deg/s" "$t/own.out" || fail "own full scales: $(cat "$t/own.out")"

# P8 GIVEN a stamp repeated THEN refused with its line and the way out
"$py" "$gen" --out "$t/dup.csv" --dup 1 --duration 60 > /dev/null || fail "generator"
"$bin" estimate --log "$t/dup.csv" --out "$t/dup" > "$t/dup.out" 2>&1
[[ $? -eq 1 ]] || fail "repeated stamp accepted"
grep -q "dup.csv:[0-9]*: t = .*time must increase strictly.*drop the repeated row, or re-stamp it" "$t/dup.out" ||
  fail "repeated stamp: $(cat "$t/dup.out")"

# F5 GIVEN a 10 s gap while the box turns THEN the attitude is withheld from the gap (it was 89 deg off
# with 'ok'), the gap is a warning, and --strict exits 1
"$py" "$gen" --out "$t/gapturn.csv" --gap 118:10 --motion turn --sensor bmi088 --seed 8 --duration 300 > /dev/null ||
  fail "generator"
"$bin" estimate --strict --log "$t/gapturn.csv" --out "$t/gapturn" > "$t/gapturn.out" 2>&1
[[ $? -eq 1 ]] || fail "gap in a turn: expected exit 1 under --strict: $(cat "$t/gapturn.out")"
grep -q "attitude withheld from t = 117.99 s: the log has no rows for 10[.0-9]* s there" "$t/gapturn.out" ||
  fail "gap in a turn: not withheld: $(cat "$t/gapturn.out")"
grep -q "1 time gap(s) longer than 1.0* s in the log, the longest 10.0[0-9]* s after t = 117.99" "$t/gapturn.out" ||
  fail "gap in a turn: no warning: $(cat "$t/gapturn.out")"
[[ $(json "$t/gapturn" "d['attitude_drift_deg_per_h']['with_driftless']") == None ]] || fail "gap in a turn: a drift was given"

# F16 GIVEN a 100 Hz log stated as 400 Hz, and the same log stamped in milliseconds THEN each is named
# first (failed: a factor 4 and 1000), with the fix; check warns too
sed 's/^# sample_rate_hz: 100$/# sample_rate_hz: 400/' "$t/base.csv" > "$t/rate400.csv"
"$bin" estimate --log "$t/rate400.csv" --out "$t/rate400" > "$t/rate400.out" 2>&1
[[ $? -eq 1 ]] || fail "rate 4x off: expected exit 1: $(cat "$t/rate400.out")"
[[ $(json "$t/rate400" "d['health']['findings'][0]['cause']") == stamp_rate ]] || fail "rate 4x off: $(cat "$t/rate400.out")"
grep -q "sample_rate_hz says 400 Hz, but the stamps step 0.01 s (100 Hz" "$t/rate400.out" || fail "rate 4x off: $(cat "$t/rate400.out")"
"$bin" check --log "$t/rate400.csv" | grep -q "warning: sample_rate_hz says 400 Hz" || fail "check: rate 4x off"
awk -F, 'BEGIN{OFS=","} /^#/ || $1=="t" {print; next} {$1=sprintf("%.3f", $1*1000); print}' "$t/base.csv" > "$t/ms.csv"
"$bin" estimate --log "$t/ms.csv" --out "$t/ms" > "$t/ms.out" 2>&1
[[ $? -eq 1 ]] || fail "ms stamps: expected exit 1"
grep -q "stamps in milliseconds?" "$t/ms.out" || fail "ms stamps: $(cat "$t/ms.out")"
! grep -q "stamp_rate" "$t/base/summary.json" || fail "base log: a stamp-rate finding"

# F3 GIVEN both hinges about box z THEN the parallel hinges are named first, not "record more flips"
"$py" "$gen" --out "$t/parallel.csv" --hinge1 0,0,1 --hinge2 0,0,1 --sensor bmi088 --seed 33 --duration 200 > /dev/null ||
  fail "generator"
"$bin" estimate --log "$t/parallel.csv" --out "$t/parallel" > "$t/parallel.out" 2>&1
[[ $? -eq 1 ]] || fail "parallel hinges: expected exit 1"
[[ $(json "$t/parallel" "d['health']['findings'][0]['cause']") == parallel_hinges ]] || fail "parallel hinges: $(cat "$t/parallel.out")"
grep -q "hinge1_axis and hinge2_axis are 0.0 deg from parallel" "$t/parallel.out" || fail "parallel: $(cat "$t/parallel.out")"

# F24 GIVEN platforms that never flip THEN that is named, with the one position pair
"$py" "$gen" --out "$t/still.csv" --period 1000 --sensor bmi088 --seed 201 --duration 200 > /dev/null || fail "generator"
"$bin" estimate --log "$t/still.csv" --out "$t/still" > "$t/still.out" 2>&1
[[ $? -eq 1 ]] || fail "never flipped: expected exit 1"
grep -q "the platforms never moved: all 1 standstill(s) were at (90, 90) deg" "$t/still.out" || fail "never flipped: $(cat "$t/still.out")"
echo "ok"
