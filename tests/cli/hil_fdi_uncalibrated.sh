#!/usr/bin/env bash
# hil --fdi on uncalibrated but healthy sensors (stop-27 finding F14), through the replay source, on
# logs from the outsider's generator (tests/estimator/navgen.py, written from docs/log-format.md
# apart from twin/): a BMI088 pair with constant biases, g-sensitivity 0.1 deg/s/g, scale +-3 % and
# misalignment +-1 deg, on a static box and on a car. The residual's offsets follow the platform
# positions, so the alarms are explained ("uncalibrated", exit 0, cause and fix named) and no fault
# is isolated; the noise is learned after the filter locked, on quiet rest samples, at the
# generator's level; and a 0.5 deg/s bias step planted into the same logs is still isolated to its
# sensor and axis with its size.
set -euo pipefail
bin=$1; src=$2
source "$src/tests/cli/lib/outsider_log.sh"
nav="$py $src/tests/estimator/navgen.py"
uncal="--sensor bmi088 --bias 2 --scale 0.03 --misalign 1 --gsens 0.1"

# the residual's per-sample sigma of white noise: 0.014 deg/s/sqrt(Hz) (the generator's bmi088) x
# sqrt(100 Hz) x sqrt(2) (two sensors) = 0.198 deg/s; its quantisation (1/16.384 deg/s) adds 1 %,
# the estimate's spread over 2000 samples ~3 %, and on the car the g-sensitivity under its 0.3 g
# accelerations (13 s period) up to ~10 % on one axis: within 15 %
sigma=$(awk 'BEGIN{printf "%.4f", 0.014*sqrt(100)*sqrt(2)}')
# a fault-free alarm is isolated as a step only if the best of six chi2(1) statistics exceeds the
# isolation margin (40): at most 6 P(chi2(1) > 40) = 6 erfc(sqrt(20)) per alarm; the design rate
# is 0.05 false faults per hour (docs/fdi.md)
p_alarm=$("$py" -c 'import math; print(6 * math.erfc(math.sqrt(20.0)))')

for case in "static 5" "car 6"; do
  set -- $case; m=$1; seed=$2
  $nav --out "$t/u.csv" $uncal --motion $m --seed $seed > /dev/null 2>&1 || fail "navgen $m"
  rc=0
  "$bin" hil --source replay:"$t/u.csv" --fdi --out "$t/o" > "$t/o.txt" 2> "$t/o.err" || rc=$?
  [[ $rc -eq 0 ]] || { cat "$t/o.err"; jq . "$t/o/fdi.json"; fail "$m: exit $rc on healthy uncalibrated sensors"; }
  jq -e '.verdict == "uncalibrated" and .fault == null and .uncalibrated.alarms_explained >= 1
         and .uncalibrated.step_chi2 < 40 and (.uncalibrated.fix | test("self_calibration"))' "$t/o/fdi.json" > /dev/null ||
    { jq . "$t/o/fdi.json"; fail "$m: not reported uncalibrated"; }
  grep -q "uncalibrated, no fault" "$t/o.err" || fail "$m: no verdict line: $(cat "$t/o.err")"
  grep -q "fdi: uncalibrated: .*run with self_calibration" "$t/o/log.csv" || fail "$m: no event line in the log"
  # learned after the lock, on quiet rest samples, at the noise level (not the car's turns: F14 read 0.32/0.63/0.22)
  jq -e --argjson s "$sigma" '.learning.started_s >= .learning.filter_locked_s and .learning.samples >= 1900
         and (.learning.on | test("quiet rest samples"))
         and all(.residual_sigma_longrun_dps[]; . > 0.85 * $s and . < 1.15 * $s)' "$t/o/fdi.json" > /dev/null ||
    { jq '.learning, .residual_sigma_longrun_dps' "$t/o/fdi.json"; fail "$m: noise not learned at $sigma deg/s after the lock"; }
  # the explained alarms, each a chance of 6 P(chi2(1) > 40) to be isolated: within the design rate
  jq -e --argjson p "$p_alarm" '.uncalibrated.alarms_explained * $p * 6 < 0.05' "$t/o/fdi.json" > /dev/null ||
    fail "$m: $(jq .uncalibrated.alarms_explained "$t/o/fdi.json") alarms in 10 min x $p_alarm: above 0.05 per hour"

  # the same sensors with a 0.5 deg/s step on sensor 2 axis y at 300 s: isolated, its size within 0.05
  $nav --out "$t/s.csv" $uncal --motion $m --seed $seed --step 300:2:1:0.5 > /dev/null 2>&1 || fail "navgen $m step"
  rc=0
  "$bin" hil --source replay:"$t/s.csv" --fdi --out "$t/f" > "$t/f.txt" 2> "$t/f.err" || rc=$?
  [[ $rc -eq 1 ]] || { cat "$t/f.err"; fail "$m: a planted step: exit $rc, expected 1"; }
  jq -e '.verdict == "fault" and .fault.kind == "bias_step" and .fault.sensor == 2 and .fault.axis == "y"
         and .fault.confident and (.fault.magnitude - 0.5 | fabs) < 0.05
         and .fault.t_alarm_s >= 299.5 and .fault.t_isolated_s - 300 < 50' "$t/f/fdi.json" > /dev/null ||
    { jq . "$t/f/fdi.json"; fail "$m: the planted step not isolated"; }
  rm -rf "$t/o" "$t/f" "$t/u.csv" "$t/s.csv"
done
echo "ok: uncalibrated sensors explained, planted steps isolated (static and car)"
