#!/usr/bin/env bash
# driftless allan on the real MPU6050 recordings of both folders: plausible N and B, honest
# warnings for what a 7-10 min record cannot show, identical reruns, and the legacy --csv path.
set -euo pipefail
bin=$1; src=$2
real=$src/../shared/realdata
[[ -d $real ]] || { echo "no real data at $real: skipped"; exit 0; }
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# tomisuarez2: raw counts at 131 LSB/(deg/s), 'Fs,100' preamble, no timestamps (--csv = --in --format text)
"$bin" allan --csv "$real/mpu6050-tomisuarez2/example_data_tinit_calc.csv" --columns gx,gy,gz \
  --units lsb:131 --out "$t/a" --kalibr > /dev/null
# sunsided: deg/s with bursty timestamps (~99.3 Hz); everything detected
"$bin" allan --in "$real/mpu6050-sunsided/unmoved-with-x-pointing-forward-10min/mpu6050.csv" --out "$t/b" > "$t/b.txt"
jq -e '.sample_rate_hz == 100' "$t/a/allan_fit.json" > /dev/null || fail "Fs preamble not used"
jq -e '.sample_rate_hz > 99.0 and .sample_rate_hz < 99.6 and .stamps.bursty' "$t/b/allan_fit.json" > /dev/null || fail "rate of bursty file"
grep -q "bursty" "$t/b.txt" || fail "bursty stamps not said"
for d in a b; do
  # MPU6050: noise density 0.005 deg/s/rtHz typical (data sheet); real parts 0.003..0.03, sigma below 10 %
  jq -e '[.channels[] | select(.quantity == "rate") | .N.valid and .N.value > 0.003 and .N.value < 0.03 and .N.sigma < 0.1 * .N.value] | all' \
    "$t/$d/allan_fit.json" > /dev/null || { cat "$t/$d/allan_fit.json"; fail "$d: N implausible"; }
  # bias instability of a few deg/h: the ADEV minimum (or its bound when the curve still falls) 1e-4..2e-2 deg/s
  jq -e '[.channels[] | select(.quantity == "rate") | (.B_min.value // .B_min.upper_95) as $b | $b > 1e-4 and $b < 2e-2] | all' \
    "$t/$d/allan_fit.json" > /dev/null || { cat "$t/$d/allan_fit.json"; fail "$d: B implausible"; }
  # 7-11 minutes cannot show a rate random walk: every rate channel says so
  jq -e '[.channels[] | select(.quantity == "rate") | .warnings | any(startswith("record too short for K"))] | all' \
    "$t/$d/allan_fit.json" > /dev/null || fail "$d: no short-record warning for K"
done
grep -q "^gyroscope_noise_density: .* # rad/s/sqrt(Hz)" "$t/a/imu.yaml" || fail "imu.yaml units"
# reruns are identical
"$bin" allan --csv "$real/mpu6050-tomisuarez2/example_data_tinit_calc.csv" --columns gx,gy,gz \
  --units lsb:131 --out "$t/a2" --kalibr > /dev/null
for f in allan_fit.json allan.csv allan_points.csv imu.yaml; do cmp -s "$t/a/$f" "$t/a2/$f" || fail "rerun differs ($f)"; done
# a file without timestamps or Fs needs --rate, and says so
printf 'gx,gy,gz\n1,2,3\n1,2,3\n1,2,3\n1,2,3\n1,2,3\n1,2,3\n' > "$t/norate.csv"
"$bin" allan --in "$t/norate.csv" --out "$t/c" > /dev/null 2> "$t/c.err" && fail "no rate accepted"
grep -q -- "--rate" "$t/c.err" || fail "no-rate message"
"$bin" allan --in "$t/norate.csv" --rate 50 --out "$t/c" > /dev/null || fail "--rate"
# a log: raw and corrected side by side
"$bin" allan --log "$src/tests/data/estimator_golden/log.csv" --corrected --columns gyro1_x,gyro2_y --out "$t/d" > /dev/null
jq -e '.channels | has("corrected_gyro1_x") and has("corrected_gyro2_y")' "$t/d/allan_fit.json" > /dev/null \
  || fail "corrected channels"
echo "ok"
