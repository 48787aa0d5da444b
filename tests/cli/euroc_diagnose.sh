#!/usr/bin/env bash
# Someone else's recording end to end: an EuRoC-layout folder (imu0/data.csv and
# state_groundtruth_estimate0/data.csv, written by tests/cli/euroc_layout.py apart from the twin)
# through `convert --ref` into a single-sensor log, then `diagnose`: the planted 2 % scale error
# on x is found, with what the generator really is (no low-pass, no quantization, its white
# noise); a clean recording of the same kind gets no physical effect.
set -euo pipefail
bin=$1; src=$2
command -v python3 > /dev/null || { echo "no python3: skipped"; exit 77; }
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# one recording: OUT SEED SCALE_X_PCT; leaves OUT/diag/diagnosis.json
run() {
  python3 "$src/tests/cli/euroc_layout.py" "$1/mav0" "$2" "$3" 90
  "$bin" convert --in "$1/mav0/imu0/data.csv" --ref "$1/mav0/state_groundtruth_estimate0/data.csv" \
    --out "$1/log.csv" > "$1/convert.txt" || { cat "$1/convert.txt"; fail "convert --ref of $1"; }
  grep -q "101 rows trimmed before the ground truth's first stamp, 101 after its last" "$1/convert.txt" ||
    fail "trimming to the ground truth's span: $(grep 'ref:' "$1/convert.txt")"
  "$bin" diagnose --log "$1/log.csv" --out "$1/diag" > "$1/diagnose.txt" || { cat "$1/diagnose.txt"; fail "diagnose of $1"; }
}
sel() { jq -r "$2" "$1/diag/diagnosis.json"; }

# GIVEN an IMU whose x gyro reads 2 % high, WHEN converted and diagnosed
run "$t/scaled" 3 2.0
# THEN the scale error is selected on sensor 1, x only, at 2 % within 0.3 % (its sigma is ~0.07 %)
[[ $(sel "$t/scaled" .verdict) == missing_effect ]] || fail "verdict: $(sel "$t/scaled" .statement)"
[[ $(sel "$t/scaled" .sensors) == 1 ]] || fail "not read as a single-sensor log"
scale=$(sel "$t/scaled" '[.selected[] | select(.effect == "scale_factor")] | map(.axis + ":" + (.params[0].value | tostring)) | join(" ")')
[[ $scale == x:* && $scale != *" "* ]] || fail "scale factor selected: '$scale' (expected x only)"
awk -v v="${scale#x:}" 'BEGIN { exit !(v > 1.7 && v < 2.3) }' || fail "scale x = $scale %, planted 2 %"
# AND nothing else physical; the generator's own signal chain is seen as it is: no low-pass, no
# quantization (continuous values)
others=$(sel "$t/scaled" '[.selected[] | select(.effect != "scale_factor" and (.family == "physical" or .family == "box")) | .effect] | join(",")')
[[ -z $others ]] || fail "other effects selected: $others"
grep -q "sensor 1: no low-pass" "$t/scaled/diagnose.txt" || fail "the missing low-pass is not said: $(cat "$t/scaled/diagnose.txt")"
[[ $(sel "$t/scaled" '[.selected[] | select(.effect == "quantization") | .params[].value] | unique | join(",")') == 0 ]] ||
  fail "quantization: $(sel "$t/scaled" '[.selected[] | select(.effect == "quantization")]')"
# AND the white noise is the generator's: 0.05 deg/s per sample at 200 Hz is 0.05 / sqrt(200) =
# 0.00354 deg/s/rtHz in the Allan convention (sigma = N sqrt(fs)), within 10 %
for d in $(sel "$t/scaled" '.noise_model[] | select(.effect == "white_noise") | .params[].value'); do
  awk -v d="$d" 'BEGIN { r = d / (0.05 / sqrt(200)); exit !(r > 0.9 && r < 1.1) }' || fail "white noise density $d deg/s/rtHz"
done

# GIVEN the same kind of recording without a scale error, THEN no physical effect is selected
run "$t/clean" 4 0
physical=$(sel "$t/clean" '[.selected[] | select(.family == "physical" or .family == "box") | .effect] | join(",")')
[[ $(sel "$t/clean" '[.selected[] | select(.effect == "lowpass_latency")] | length') == 1 ]] || fail "clean recording: no low-pass not found"
[[ -z $physical ]] || fail "clean recording: $physical selected ($(sel "$t/clean" .statement))"
echo "ok: scale $scale %"
