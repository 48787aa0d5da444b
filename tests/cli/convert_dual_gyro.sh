#!/usr/bin/env bash
# A dual-gyro box recorded by another tool (outsider F23): estimate refused it and sent the user to
# convert, which kept one IMU and dropped the second triad and the encoders without a word, and
# estimate then refused the single-IMU log. Now convert names the columns it did not use (and, for a
# second gyro triad, the log form that holds it) and estimate's refusal names that form too.
# Data: tests/diagnose/independent_log.py (written apart from twin/), its columns renamed as a
# foreign logger would.
# usage: convert_dual_gyro.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1; src=$2
py=/usr/bin/python3
"$py" -c 'import numpy' 2>/dev/null || { echo "no numpy for $py: skipped"; exit 77; }
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$py" "$src/tests/diagnose/independent_log.py" --out "$t/log.csv" --seed 9 --duration 60 > /dev/null || fail "generator"
# GIVEN the recording with a foreign header: no format line, its own column names
awk -F, 'BEGIN { OFS = ","; print "time_s,gyro_x,gyro_y,gyro_z,gyro2_x_dps,gyro2_y_dps,gyro2_z_dps,enc1_deg,enc2_deg" }
         /^#/ { next } !h { h = 1; next } { print $1, $2, $3, $4, $5, $6, $7, $8, $9 }' "$t/log.csv" > "$t/dual.csv"
# WHEN estimate reads it THEN it refuses and names both ways: convert for one IMU, the log form for two
"$bin" estimate --log "$t/dual.csv" --out "$t/e" > /dev/null 2> "$t/e.err" && fail "estimate accepted a foreign header"
grep -q "a dual-gyro box's: rename its columns to t, gyro1_x..gyro2_z" "$t/e.err" || fail "no dual-gyro way out: $(cat "$t/e.err")"
# WHEN convert makes a log of it THEN it says which columns it did not use, and that a second triad needs the log form
"$bin" convert --in "$t/dual.csv" --out "$t/cv.csv" > "$t/cv.out" 2>&1 || fail "convert: exit $?: $(cat "$t/cv.out")"
grep -q "columns not used: gyro2_x_dps, gyro2_y_dps, gyro2_z_dps, enc1_deg, enc2_deg" "$t/cv.out" ||
  fail "the dropped columns are not named: $(cat "$t/cv.out")"
grep -q "a second gyro triad?" "$t/cv.out" || fail "the second triad is not called one"
# AND a recording whose columns are all used gets no such line
awk -F, 'BEGIN { OFS = ","; print "time_s,gyro_x,gyro_y,gyro_z" } /^#/ { next } !h { h = 1; next } { print $1, $2, $3, $4 }' \
  "$t/log.csv" > "$t/one.csv"
"$bin" convert --in "$t/one.csv" --out "$t/one_cv.csv" > "$t/one.out" 2>&1 || fail "convert one IMU: exit $?"
if grep -q "columns not used" "$t/one.out"; then fail "unused columns named where every column was used: $(cat "$t/one.out")"; fi
echo "ok"
