#!/usr/bin/env bash
# Accel columns in another unit, or empty (stop-27 finding F19): the median |f| over the
# standstills against gravity in each acceleration unit of the one unit table. On the outsider's
# static log (tests/estimator/navgen.py, seed 5, written apart from twin/) in m/s^2 nothing is
# said; divided by 9.80665 (g), times 1000/9.80665 on sensor 1 (mg) or sensor 2's columns zeroed,
# --selfcal fails with the finding first, naming the sensor, the unit and the factor (or "empty"),
# and no finding advises --selfcal; without it (--box-at-rest uses the up direction) the same
# finding is degraded. Before: `failed`, "estimate it with --selfcal" (the option in use).
set -euo pipefail
bin=$1; src=$2
source "$src/tests/cli/lib/outsider_log.sh"
gen=$src/tests/estimator/navgen.py

"$py" "$gen" --out "$t/ms2.csv" --sensor bmi088 --bias 2 --scale 0.03 --misalign 1 --gsens 0.1 --seed 5 > /dev/null 2>&1
# scale the columns matching $2 by $3 (printf format $4)
scale() {
  awk -F, -v pat="$2" -v k="$3" -v fmt="$4" 'BEGIN{OFS=","} /^#/{print;next}
    !h{h=1;for(i=1;i<=NF;i++) if($i ~ pat) a[i]=1; print;next} {for(i in a) $i=sprintf(fmt,$i*k); print}' "$1"
}
scale "$t/ms2.csv" '^accel' "$(awk 'BEGIN{print 1/9.80665}')" '%.6f' > "$t/g.csv"
scale "$t/ms2.csv" '^accel1' "$(awk 'BEGIN{print 1000/9.80665}')" '%.3f' > "$t/mg.csv"
scale "$t/ms2.csv" '^accel2' 0 '%.5f' > "$t/zero.csv"

"$bin" estimate --log "$t/ms2.csv" --out "$t/o_ms2" --selfcal > /dev/null 2>&1 || fail "m/s^2: exit"
jq -e '[.health.findings[] | select(.cause == "accel_unit" or .cause == "accel_empty")] | length == 0' \
  "$t/o_ms2/summary.json" > /dev/null || fail "m/s^2: an accel finding on the right unit"

# case, the first finding's cause, and text it must hold
check() {
  local case=$1 cause=$2 text=$3 rc=0
  "$bin" estimate --log "$t/$case.csv" --out "$t/o_$case" --selfcal > "$t/$case.txt" 2>&1 || rc=$?
  [[ $rc -ne 0 ]] || fail "$case: exit 0 on a failed self-calibration"
  jq -e --arg c "$cause" '.health.verdict == "failed" and .health.findings[0].cause == $c
                          and .health.findings[0].severity == "failed"' "$t/o_$case/summary.json" > /dev/null ||
    { jq .health "$t/o_$case/summary.json"; fail "$case: $cause not first"; }
  jq -r '.health.findings[0].text' "$t/o_$case/summary.json" | grep -qF -- "$text" ||
    { jq -r '.health.findings[0].text' "$t/o_$case/summary.json"; fail "$case: no '$text'"; }
  if jq -r '.health.findings[].text' "$t/o_$case/summary.json" | grep -F -- "--selfcal"; then
    fail "$case: a finding advises --selfcal, which the run used"
  fi
}
check g accel_unit "the columns are in g (multiply them by 9.80665 to get m/s^2)"
jq -e '[.health.findings[] | select(.cause == "accel_unit")] | length == 2' "$t/o_g/summary.json" > /dev/null ||
  fail "g: not both sensors named"
check mg accel_unit "accel1_x/y/z read |f| = 1"
grep -qF "the columns are in mg (multiply them by 0.00980665 to get m/s^2)" "$t/mg.txt" || fail "mg: unit or factor"
check zero accel_empty "accel2_x/y/z read |f| = 0 at the standstills"

# the accel used, no self-calibration: degraded
"$bin" estimate --log "$t/g.csv" --out "$t/o_rest" --box-at-rest > /dev/null 2>&1 || true
jq -e '.health.findings[0].cause == "accel_unit" and .health.findings[0].severity == "degraded"' \
  "$t/o_rest/summary.json" > /dev/null || { jq .health "$t/o_rest/summary.json"; fail "--box-at-rest: not degraded first"; }
echo "ok"
