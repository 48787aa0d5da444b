#!/usr/bin/env bash
# driftless allan on the real MPU6050 recordings: plausible N and B, identical on reruns.
set -euo pipefail
bin=$1; src=$2
real=$src/../shared/realdata
[[ -d $real ]] || { echo "no real data at $real: skipped"; exit 0; }
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# tomisuarez2: raw counts at 131 LSB/(deg/s), 'Fs,100' preamble, no timestamps
"$bin" allan --csv "$real/mpu6050-tomisuarez2/example_data_tinit_calc.csv" --columns gx,gy,gz \
  --units lsb:131 --out "$t/a" --imu-yaml > /dev/null
# sunsided: deg/s with bursty timestamps (~99.3 Hz)
"$bin" allan --csv "$real/mpu6050-sunsided/unmoved-with-x-pointing-forward-10min/mpu6050.csv" \
  --columns gyro_x,gyro_y,gyro_z --units deg/s --out "$t/b" > /dev/null
jq -e '.sample_rate_hz == 100' "$t/a/allan_fit.json" > /dev/null || fail "Fs preamble not used"
jq -e '.sample_rate_hz > 99.0 and .sample_rate_hz < 99.6' "$t/b/allan_fit.json" > /dev/null || fail "rate of bursty file"
for d in a b; do
  # MPU6050: noise density 0.005 deg/s/rtHz typical (data sheet); real parts 0.003..0.03.
  # bias instability of a few deg/h: 1e-4..2e-2 deg/s, with its minimum at tens to hundreds of s
  jq -e '[.channels[] | .N.valid and .N.value > 0.003 and .N.value < 0.03 and .N.sigma < 0.1 * .N.value] | all' \
    "$t/$d/allan_fit.json" > /dev/null || { cat "$t/$d/allan_fit.json"; fail "$d: N implausible"; }
  jq -e '[.channels[] | .B.valid and .B.value > 1e-4 and .B.value < 2e-2 and .B.tau_s > 5] | all' \
    "$t/$d/allan_fit.json" > /dev/null || { cat "$t/$d/allan_fit.json"; fail "$d: B implausible"; }
done
grep -q "gyroscope_noise_density" "$t/a/imu.yaml" || fail "imu.yaml"
# reruns are identical
"$bin" allan --csv "$real/mpu6050-tomisuarez2/example_data_tinit_calc.csv" --columns gx,gy,gz \
  --units lsb:131 --out "$t/a2" > /dev/null
cmp -s "$t/a/allan_fit.json" "$t/a2/allan_fit.json" || fail "rerun differs"
cmp -s "$t/a/allan.csv" "$t/a2/allan.csv" || fail "rerun differs (allan.csv)"
# a file without timestamps or Fs needs --rate, and says so
printf 'gx,gy,gz\n1,2,3\n1,2,3\n1,2,3\n1,2,3\n' > "$t/norate.csv"
"$bin" allan --csv "$t/norate.csv" --columns gx,gy,gz --out "$t/c" > /dev/null 2> "$t/c.err" && fail "no rate accepted"
grep -q -- "--rate" "$t/c.err" || fail "no-rate message"
"$bin" allan --csv "$t/norate.csv" --columns gx,gy,gz --rate 50 --out "$t/c" > /dev/null || fail "--rate"
# a log: raw and corrected side by side
"$bin" allan --log "$src/tests/data/estimator_golden/log.csv" --corrected --columns gyro1_x,gyro2_y --out "$t/d" > /dev/null
jq -e '.channels | has("corrected_gyro1_x") and has("corrected_gyro2_y")' "$t/d/allan_fit.json" > /dev/null \
  || fail "corrected channels"
echo "ok"
