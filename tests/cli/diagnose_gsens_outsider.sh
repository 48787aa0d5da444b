#!/usr/bin/env bash
# diagnose names the g-sensitivity an outsider's log carries (tests/estimator/navgen.py, written
# apart from twin/: a full 3x3 matrix per sensor, elements sigma 0.05 deg/s/g). On a static box
# only sensor 2's hinge is horizontal (box x), so only gravity's column there (sensor y) swings at
# the flips; the Earth rate in sensor 2's y and z axes changes sign with it, so a cross-axis term
# fits the same residual, at 200-2200 %. Before: "misalignment on sensor 2 [IMPLAUSIBLE]",
# exit 1, on 7 of seeds 30-37. GIVEN such logs (seeds 30, 32, 33, 300 s) WHEN diagnosed THEN the
# one effect is g_sensitivity on sensor 2, every element within 3 sigma of the planted one, and
# its note says the cross-axis alternative is implausible; on a car (turns and bumps: every
# column excited) g_sensitivity on both sensors, nothing implausible; a log with only a 0.3 deg
# misalignment (not excited at rest) names nothing.
set -euo pipefail
bin=$1; src=$2
source "$src/tests/cli/lib/outsider_log.sh"
gen=$src/tests/estimator/navgen.py

# seed, tag, extra navgen options; leaves $t/$tag.csv, $t/$tag.json (truth) and $t/d_$tag/
run() {
  local seed=$1 tag=$2 rc=0
  shift 2
  "$py" "$gen" --out "$t/$tag.csv" --sensor mpu6050 --duration 300 --seed "$seed" --truth-out "$t/$tag.json" "$@" \
    > /dev/null 2>&1
  "$bin" diagnose --log "$t/$tag.csv" --out "$t/d_$tag" > "$t/$tag.txt" 2>&1 || rc=$?
  [[ $rc -eq 0 ]] || { cat "$t/$tag.txt"; fail "$tag: exit $rc"; }
}
# every selected g-sensitivity element of $tag within 3 sigma of navgen's G (sensor, row, column)
planted_within() {
  jq -e --slurpfile truth "$t/$1.json" '
    [.selected[] | select(.effect == "g_sensitivity") | .params[]
     | (.name | capture("s(?<s>[12]).matrix_dps_per_g\\[(?<r>[xyz])\\]\\[(?<k>[xyz])\\]")) as $m
     | {v: .value, sig: .sigma,
        g: $truth[0].G[($m.s | tonumber) - 1][{"x":0,"y":1,"z":2}[$m.r]][{"x":0,"y":1,"z":2}[$m.k]]}
     | ((.v - .g) | fabs) <= 3 * .sig] | length > 0 and all' "$t/d_$1/diagnosis.json" > /dev/null ||
    { jq -c '.selected[].params[] | [.name, .value, .sigma]' "$t/d_$1/diagnosis.json"; jq -c .G "$t/$1.json";
      fail "$1: g-sensitivity not within 3 sigma of the planted"; }
}

for seed in 30 32 33; do
  tag=static$seed
  run "$seed" "$tag" --gsens 0.05
  jq -e '.verdict == "missing_effect" and ([.selected[] | select(.family == "physical")] | length == 1)
         and .selected[0].effect == "g_sensitivity" and .selected[0].sensor == "2" and (.selected[0].absurd | not)
         and ([.selected[0].params[].name | test("\\]\\[y\\]$")] | all)' "$t/d_$tag/diagnosis.json" > /dev/null ||
    { jq -c '.selected[] | [.effect, .sensor, .absurd, .evidence]' "$t/d_$tag/diagnosis.json"; fail "$tag: not g_sensitivity on sensor 2"; }
  jq -r '.selected[0].note' "$t/d_$tag/diagnosis.json" | grep -q "^misalignment fits the same residual .* implausible values" ||
    fail "$tag: the note does not name the implausible alternative"
  planted_within "$tag"
done

run 31 car --gsens 0.05 --motion car
jq -e '([.selected[] | select(.family == "physical") | .effect] == ["g_sensitivity"])
       and ([.selected[] | select(.effect == "g_sensitivity") | .sensor == "both" and (.absurd | not)] | all)' \
  "$t/d_car/diagnosis.json" > /dev/null ||
  { jq -c '.selected[] | [.effect, .sensor, .absurd, .evidence]' "$t/d_car/diagnosis.json"; fail "car: not g_sensitivity on both sensors"; }
planted_within car

run 30 misalign --misalign 0.3
jq -e '.verdict == "consistent_with_noise"' "$t/d_misalign/diagnosis.json" > /dev/null ||
  { jq -c '.selected[] | [.effect, .sensor, .evidence]' "$t/d_misalign/diagnosis.json"; fail "misalign: something named"; }
echo "ok"
