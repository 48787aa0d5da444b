#!/usr/bin/env bash
# No finding's fix names an option the run already uses (issue 13; stop-27 findings F10, F19, F22):
# one run per option on logs from the outsider's generator (tests/estimator/navgen.py, apart from
# twin/), each made to raise a finding whose fix used to name that option:
# --tune auto (F10: a noisy sensor's uncalibrated errors on a rocking box, noise_understated),
# --selfcal (a static box whose accel columns are in g), --box-at-rest (a static uncalibrated box
# without --selfcal, rejections_at_position), --calib (F22: a self-calibration's calib.yaml from a
# car, applied as exact to a rocking box of the same sensors: calib_uncertain first, naming the
# elements and their sigma, with the fix "use it with --selfcal"; with --selfcal it is not raised).
# Dropping an option in use ("Drop --box-at-rest") is the one way a fix may name it.
set -euo pipefail
bin=$1; src=$2
source "$src/tests/cli/lib/outsider_log.sh"
gen=$src/tests/estimator/navgen.py

# the findings' texts name the option $2 nowhere (but "Drop <option>")
no_advice() {
  local out=$1 opt=$2
  if jq -r '.health.findings[].text' "$out/summary.json" | sed "s/Drop $opt//g" | grep -F -- "$opt"; then
    fail "$out: a finding names $opt, which the run used"
  fi
}
# the run raised finding $2
has() { jq -e --arg c "$2" 'any(.health.findings[]; .cause == $c)' "$1/summary.json" > /dev/null ||
          { jq .health "$1/summary.json"; fail "$1: no $2"; }; }

"$py" "$gen" --out "$t/noisy.csv" --sensor noisy --bias 5 --scale 0.03 --misalign 1 --gsens 0.1 --motion rock --seed 112 \
  > /dev/null 2>&1
"$bin" estimate --log "$t/noisy.csv" --out "$t/o_tune" --tune auto > /dev/null 2>&1 || true
has "$t/o_tune" noise_understated
no_advice "$t/o_tune" "--tune auto"

"$py" "$gen" --out "$t/static.csv" --sensor bmi088 --bias 2 --scale 0.03 --misalign 1 --gsens 0.1 --seed 5 > /dev/null 2>&1
awk -F, 'BEGIN{OFS=","} /^#/{print;next} !h{h=1;for(i=1;i<=NF;i++) if($i ~ /^accel/) a[i]=1; print;next}
         {for(i in a) $i=sprintf("%.6f",$i/9.80665); print}' "$t/static.csv" > "$t/static_g.csv"
"$bin" estimate --log "$t/static_g.csv" --out "$t/o_selfcal" --selfcal > /dev/null 2>&1 || true
has "$t/o_selfcal" accel_unit
no_advice "$t/o_selfcal" "--selfcal"

"$bin" estimate --log "$t/static.csv" --out "$t/o_rest" --box-at-rest > /dev/null 2>&1 || true
has "$t/o_rest" rejections_at_position
no_advice "$t/o_rest" "--box-at-rest"

"$py" "$gen" --out "$t/car.csv" --sensor bmi088 --bias 2 --scale 0.03 --misalign 1 --gsens 0.1 --motion car --seed 6 \
  > /dev/null 2>&1
"$py" "$gen" --out "$t/rock.csv" --sensor bmi088 --bias 2 --scale 0.03 --misalign 1 --gsens 0.1 --motion rock --seed 6 \
  > /dev/null 2>&1
"$bin" estimate --log "$t/car.csv" --out "$t/o_car" --selfcal --calib-out "$t/calib.yaml" > /dev/null 2>&1 ||
  fail "car: the self-calibration failed"
rc=0
"$bin" estimate --log "$t/rock.csv" --out "$t/o_calib" --calib "$t/calib.yaml" --strict > "$t/calib.txt" 2>&1 || rc=$?
[[ $rc -ne 0 ]] || fail "--calib: --strict exited 0"
jq -e '.health.findings[0].cause == "calib_uncertain" and .health.findings[0].severity == "degraded"' \
  "$t/o_calib/summary.json" > /dev/null || { jq .health "$t/o_calib/summary.json"; fail "--calib: calib_uncertain not first"; }
jq -r '.health.findings[0].text' "$t/o_calib/summary.json" | grep -qE "sensor [12] [GE]\[[xyz]\]\[[xyz]\] -?[0-9.]+ \+- [0-9.]+" ||
  fail "--calib: the elements and their sigma are not named"
jq -r '.health.findings[0].text' "$t/o_calib/summary.json" | grep -qF "use it with --selfcal" || fail "--calib: no fix"
no_advice "$t/o_calib" "--calib"
"$bin" estimate --log "$t/rock.csv" --out "$t/o_calib_sc" --calib "$t/calib.yaml" --selfcal > /dev/null 2>&1 || true
jq -e 'all(.health.findings[]; .cause != "calib_uncertain")' "$t/o_calib_sc/summary.json" > /dev/null ||
  fail "--calib --selfcal: calib_uncertain raised"
echo "ok"
