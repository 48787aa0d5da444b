#!/usr/bin/env bash
# driftless convert: other people's recordings into the single-sensor log, which check and allan
# then read. Real MPU6050 files (bursty stamps; raw counts without time), a regular-stamp EuRoC
# file, and the refusals: two triads without --columns, stamps that step back with --time stamps,
# a repeated stamp in a recording with a gap (a uniform time would move the rows after it), and a
# --full-scale the readings exceed.
set -euo pipefail
bin=$1; src=$2
real=$src/../shared/realdata/mpu6050-sunsided/unmoved-with-x-pointing-forward/mpu6050.csv
raw=$src/../shared/realdata/mpu6050-tomisuarez2/imu_90_x_rot.csv
[[ -f $real && -f $raw ]] || { echo "no real data under $src/../shared/realdata: skipped"; exit 77; }
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
meta() { grep -m1 "^# $2:" "$1" | sed "s/^# $2: *//; s/ *$//"; }

# 1. bursty arrival stamps (median step 2 ms, mean 10 ms): t = first stamp + k / mean rate
"$bin" convert --in "$real" --columns gyro_x,gyro_y,gyro_z --accel-columns acc_x,acc_y,acc_z --temp-column temp \
  --out "$t/static.csv" > "$t/static.txt" || { cat "$t/static.txt"; fail "convert of the sunsided file"; }
grep -q "bursty" "$t/static.txt" || fail "the bursty stamps are not said: $(cat "$t/static.txt")"
[[ $(meta "$t/static.csv" sensors) == 1 ]] || fail "not the single-sensor form"
[[ $(meta "$t/static.csv" complete) == true ]] || fail "not complete"
grep -q "^t,gyro1_x,gyro1_y,gyro1_z,plat1_deg,accel1_x,accel1_y,accel1_z,temp1" "$t/static.csv" ||
  fail "columns: $(grep -m1 '^t,' "$t/static.csv")"
rows_in=$(($(wc -l < "$real") - 1))
rows_out=$(grep -vc '^#\|^t,' "$t/static.csv")
[[ $rows_in == "$rows_out" ]] || fail "rows: $rows_in in, $rows_out out"
# values: deg/s kept, g converted to m/s^2 (first row: gyro_x 4.557252 deg/s, acc_z -1.029541 g)
row=$(awk '!/^#/ && !/^t,/ { print; exit }' "$t/static.csv")
awk -F, -v r="$row" 'BEGIN { split(r, c, ","); exit !(c[2] - 4.557252 < 1e-6 && 4.557252 - c[2] < 1e-6 &&
  c[8] + 1.029541 * 9.80665 < 1e-4 && -1.029541 * 9.80665 - c[8] < 1e-4) }' || fail "values of the first row: $row"
"$bin" check --log "$t/static.csv" > "$t/check.txt" || { cat "$t/check.txt"; fail "check refuses the converted log"; }
"$bin" allan --log "$t/static.csv" --columns gyro1_x,gyro1_y,gyro1_z --out "$t/allan" > /dev/null || fail "allan on the converted log"
# the same white-noise density as allan on the original file (same samples, same rate)
"$bin" allan --in "$real" --columns gyro_x,gyro_y,gyro_z --out "$t/allan_in" > /dev/null
a=$(jq -r '.channels["gyro1_x"].N.value' "$t/allan/allan_fit.json"); b=$(jq -r '.channels["gyro_x"].N.value' "$t/allan_in/allan_fit.json")
awk -v a="$a" -v b="$b" 'BEGIN { d = (a - b) / b; if (d < 0) d = -d; exit !(d < 1e-6) }' || fail "N: converted $a, original $b"
# estimate needs two triads: refused, naming the file
out=$("$bin" estimate --log "$t/static.csv" --out "$t/est" 2>&1) && fail "estimate accepted a single-sensor log"
grep -q "static.csv" <<< "$out" || fail "estimate's refusal does not name the file: $out"

# 2. raw counts, no time column, 'Fs,100' line: t = k / 100 Hz, counts at 131 LSB per deg/s
"$bin" convert --in "$raw" --out "$t/raw.csv" > "$t/raw.txt" || { cat "$t/raw.txt"; fail "convert of raw counts"; }
[[ $(meta "$t/raw.csv" sample_rate_hz) == 100 ]] || fail "rate of the raw file: $(meta "$t/raw.csv" sample_rate_hz)"
row=$(awk '!/^#/ && !/^t,/ && ++n == 2 { print; exit }' "$t/raw.csv")
awk -F, -v r="$row" 'BEGIN { split(r, c, ","); exit !(c[1] == 0.01 && c[2] + 408 / 131 < 1e-6 && -408 / 131 - c[2] < 1e-6) }' ||
  fail "second row of the raw file: $row"

# 3. EuRoC: regular ns stamps are the log's time
awk -F, 'NR == 1 { print "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]"; next }
  NR < 2000 { ns = 758555392 + (NR - 2) * 5000000  # the 1.4e18 ns stamp written exactly (awk numbers are doubles)
    printf "%d%09d,%.17g,%.17g,%.17g,0,0,9.81\n", 1403636579 + int(ns / 1e9), ns % 1000000000, $5 / 57.29577951308232, $6 / 57.29577951308232, $7 / 57.29577951308232 }' \
  "$real" > "$t/data.csv"
"$bin" convert --in "$t/data.csv" --out "$t/euroc.csv" > "$t/euroc.txt" || { cat "$t/euroc.txt"; fail "EuRoC"; }
grep -q "t = the stamps" "$t/euroc.txt" || fail "EuRoC stamps not used: $(cat "$t/euroc.txt")"
# the epoch (first stamp floored to whole seconds) is subtracted in integer ns: the 5 ms steps stay
# exact (as double seconds, 1.4e9 s resolves only 2.4e-7 s), the rate is 200 Hz to 1e-9
grep -q "epoch 1403636579 s" "$t/euroc.txt" || fail "the epoch is not said: $(cat "$t/euroc.txt")"
grep -q "^# event: .*epoch 1403636579 s" "$t/euroc.csv" || fail "the epoch is not in the log's events"
awk -v r="$(meta "$t/euroc.csv" sample_rate_hz)" 'BEGIN { d = r - 200; exit !(d < 1e-7 && d > -1e-7) }' ||
  fail "EuRoC rate: $(meta "$t/euroc.csv" sample_rate_hz)"
awk -F, '!/^#/ && !/^t,/ { if (n++ > 0) { d = $1 - p - 0.005; if (d > 1e-9 || d < -1e-9) { print "step " $1 - p " at t " $1; exit 1 } } p = $1 }
' "$t/euroc.csv" || fail "EuRoC steps are not 5 ms"
[[ $(awk -F, '!/^#/ && !/^t,/ { print $1; exit }' "$t/euroc.csv") == 0.758555 ]] || fail "EuRoC first t is not stamp - epoch"

# 3b. --ref: a EuRoC ground truth (a rotation about z at 0.2 rad/s, stamps 2.5 ms off the IMU's)
# covering IMU rows 100..1500 of 0..1997: ref_q by slerp, the other rows trimmed, and both said
awk 'BEGIN { print "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], v_RS_R_x [m s^-1]"
  for (j = 0; j <= 1401; ++j) { ns = 758555392 + 500000000 - 2500000 + j * 5000000; a = 0.2 * ns / 1e9
    printf "%d%09d,%.9f,0,0,%.17g,0,0,%.17g,0\n", 1403636579 + int(ns / 1e9), ns % 1000000000, ns / 1e9, cos(a / 2), sin(a / 2) } }' \
  > "$t/gt.csv"
"$bin" convert --in "$t/data.csv" --ref "$t/gt.csv" --out "$t/euroc_ref.csv" > "$t/euroc_ref.txt" ||
  { cat "$t/euroc_ref.txt"; fail "convert --ref"; }
grep -q "100 rows trimmed before the ground truth's first stamp, 497 after its last" "$t/euroc_ref.txt" ||
  fail "the trimming is not said: $(cat "$t/euroc_ref.txt")"
grep -q "^# event: .*100 rows trimmed before" "$t/euroc_ref.csv" || fail "the trimming is not in the log's events"
[[ $(grep -vc '^#\|^t,' "$t/euroc_ref.csv") == 1401 ]] || fail "rows with a reference: $(grep -vc '^#\|^t,' "$t/euroc_ref.csv")"
grep -q "^t,gyro1_x,.*ref_qw,ref_qx,ref_qy,ref_qz,ref_px,ref_py,ref_pz" "$t/euroc_ref.csv" ||
  fail "ref columns: $(grep -m1 '^t,' "$t/euroc_ref.csv")"
# every row's ref_q is the closed form at its t (slerp is exact for a constant axis and rate)
awk -F, '/^t,/ { for (i = 1; i <= NF; ++i) c[$i] = i; next }
  !/^#/ && c["t"] { a = 0.2 * $c["t"]; e = $c["ref_qw"] - cos(a / 2); f = $c["ref_qz"] - sin(a / 2)
    if (e * e + f * f > 1e-12) { print "t " $1 ": " $c["ref_qw"] " " $c["ref_qz"]; bad = 1; exit } }
  END { exit bad }' "$t/euroc_ref.csv" || fail "ref_q is not the slerp of the ground truth"
"$bin" check --log "$t/euroc_ref.csv" > "$t/check_ref.txt" || { cat "$t/check_ref.txt"; fail "check refuses the log with ref_q"; }
# a ground truth that does not overlap the IMU rows is refused, naming both spans
awk 'NR <= 3 { sub(/^140363/, "140360"); print }' "$t/gt.csv" > "$t/gt_far.csv"
out=$("$bin" convert --in "$t/data.csv" --ref "$t/gt_far.csv" --out "$t/far.csv" 2>&1) && fail "a ground truth far away was joined"
grep -q "gt_far.csv.*do not overlap" <<< "$out" || fail "message for a ground truth that does not overlap: $out"

# 4. refusals: a stamp that steps back with --time stamps; two triads without --columns
printf 't,gx,gy,gz\n0.00,1,2,3\n0.01,1,2,3\n0.005,1,2,3\n0.02,1,2,3\n' > "$t/back.csv"
out=$("$bin" convert --in "$t/back.csv" --time stamps --out "$t/back.log" 2>&1) && fail "stamps stepping back accepted"
grep -q "back.csv.*--time uniform" <<< "$out" || fail "message for stamps stepping back: $out"
printf 't,g1x,g1y,g1z,g2x,g2y,g2z\n0.00,1,2,3,4,5,6\n0.01,1,2,3,4,5,6\n' > "$t/two.csv"
out=$("$bin" convert --in "$t/two.csv" --out "$t/two.log" 2>&1) && fail "two triads accepted without --columns"
grep -q "two.csv.*--columns" <<< "$out" || fail "message for two triads: $out"

# 5. a repeated stamp (--time auto then uses t0 + k / rate): right when every sample is there,
# refused when samples are missing too (a uniform time would move every row after the gap)
awk 'BEGIN { print "time,gx,gy,gz"; for (k = 0; k < 1000; ++k) { s = (k == 500 ? k - 1 : k)
  printf "%.2f,%.4f,0.5,-0.25\n", s / 100, sin(k / 10) } }' > "$t/twice.csv"   # row 500 stamped like row 499
"$bin" convert --in "$t/twice.csv" --out "$t/twice.log" > "$t/twice.txt" || { cat "$t/twice.txt"; fail "case 5: one repeated stamp"; }
[[ $(awk -F, '!/^#/ && !/^t,/ { l = $1 } END { print l }' "$t/twice.log") == 9.990000 ]] ||
  fail "case 5: the last row is not at its stamp 9.99 s: $(tail -1 "$t/twice.log")"
awk 'BEGIN { print "time,gx,gy,gz"; for (k = 0; k < 1000; ++k) { if (k >= 300 && k < 500) continue; s = (k == 700 ? k - 1 : k)
  printf "%.2f,%.4f,0.5,-0.25\n", s / 100, sin(k / 10) } }' > "$t/gap_twice.csv"   # 2 s missing, then a repeat
out=$("$bin" convert --in "$t/gap_twice.csv" --out "$t/gap_twice.log" 2>&1) && fail "case 5: a uniform time over a 2 s gap was accepted"
grep -q "gap_twice.csv: --time: .*would move the last row 2 s before its stamp.*--time uniform" <<< "$out" ||
  fail "case 5: message for a repeated stamp with a gap: $out"
[[ ! -e $t/gap_twice.log ]] || fail "case 5: a log was written although refused"
"$bin" convert --in "$t/gap_twice.csv" --time uniform --out "$t/gap_twice.log" > /dev/null || fail "case 5: --time uniform refused"
# 6. --full-scale below the readings: refused at the first row beyond 1.1 x FS (every reader would
# refuse the log), naming the input line; the log so far says complete: false and why
awk 'BEGIN { print "time,gx,gy,gz"; for (k = 0; k < 200; ++k) printf "%.2f,%.4f,0,0\n", k / 100, k / 2 }' > "$t/fast.csv"
out=$("$bin" convert --in "$t/fast.csv" --full-scale 50 --out "$t/fast.log" 2>&1) && fail "case 6: readings beyond --full-scale accepted"
grep -q "fast.csv:113: --full-scale: gyro x reads 55.5 deg/s, beyond 1.1 x the --full-scale 50 deg/s" <<< "$out" ||
  fail "case 6: message: $out"
[[ $(meta "$t/fast.log" complete) == false ]] || fail "case 6: the log does not say complete: false"
"$bin" check --log "$t/fast.log" > /dev/null 2>&1 || fail "case 6: the rows before the refusal are not a readable log"
"$bin" convert --in "$t/fast.csv" --full-scale 100 --out "$t/fast.log" > /dev/null || fail "case 6: --full-scale 100 refused"
echo "convert: ok"
