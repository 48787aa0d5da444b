#!/usr/bin/env bash
# Inputs that are not the twin's, from the outsider's generator (tests/diagnose/probe_log.py,
# written apart from twin/), each named with its cause (stop-25 findings):
#   P16 a dead gyro axis (empty, or stuck at one value) is named, not "the platforms never rested";
#   P13 --selfcal without accel columns makes flip updates and says G cannot be observed;
#   P6  both platforms flipping together: "never locked" names the positions that occurred;
#   P3  two unlike gyros described by gyro1_/gyro2_full_scale_dps;
#   P8  a repeated time stamp is refused with the way out.
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
# warning says G cannot be observed
"$py" "$gen" --out "$t/noaccel.csv" --motion turn --sensor bmi088 --duration 300 > /dev/null || fail "generator"
"$bin" estimate --selfcal --log "$t/noaccel.csv" --out "$t/noaccel" > "$t/noaccel.out" 2>&1 || fail "selfcal: $(cat "$t/noaccel.out")"
[[ $(json "$t/noaccel" "d['flips']['updates'] >= 5 and d['flips']['rejected'] == 0") == True ]] ||
  fail "selfcal without accel: flips $(json "$t/noaccel" "d['flips']")"
grep -q "no accel columns: the g-sensitivity states (--selfcal) cannot be observed" "$t/noaccel.out" ||
  fail "selfcal without accel: no word: $(cat "$t/noaccel.out")"

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
echo "ok"
