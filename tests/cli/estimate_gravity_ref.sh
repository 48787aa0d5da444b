#!/usr/bin/env bash
# No accel columns but ref_q (stop-27 finding F33, issue 13 item 1): --selfcal drives the
# g-sensitivity states with gravity from ref_q, M_i^T C^T (0, 0, g), and says so
# (self_calibration.gravity_source: "ref_q"). Logs from the outsider's generator
# (tests/estimator/navgen.py, written from docs/log-format.md apart from twin/) with --no-accel:
# a static box (seed 5: every bias within 3 sigma of the truth, sensor 2's G column along
# gravity - the one platform 2's flips observe - within 3 sigma of the planted G) and a car (seed
# 271, every bias within 3 sigma). Before: z up to 21 and the fix "--selfcal", the option in use.
# Without ref_q either: gravity_source "none" and the text says to log them, not "--selfcal".
set -euo pipefail
bin=$1; src=$2
source "$src/tests/cli/lib/outsider_log.sh"
gen=$src/tests/estimator/navgen.py

"$py" "$gen" --out "$t/static.csv" --sensor bmi088 --bias 2 --scale 0.03 --misalign 1 --gsens 0.1 --no-accel --seed 5 \
  --truth-out "$t/static.json" > /dev/null 2>&1
"$py" "$gen" --out "$t/car.csv" --sensor bmi088 --gsens 0.1 --scale 0.01 --misalign 0.3 --no-accel --motion car \
  --seed 271 > /dev/null 2>&1
"$py" "$gen" --out "$t/bare.csv" --sensor bmi088 --bias 2 --gsens 0.1 --no-accel --no-ref --duration 300 --seed 7 \
  > /dev/null 2>&1

# |z| of the final biases against the log's last true_bias row
zmax() {
  local log=$1 out=$2
  "$py" - "$log" "$out/summary.json" <<'PY'
import json, sys
rows = [l for l in open(sys.argv[1]) if not l.startswith("#")]
hdr = rows[0].strip().split(","); last = dict(zip(hdr, rows[-1].strip().split(",")))
s = json.load(open(sys.argv[2]))
tb = [float(last[f"true_bias{i}_{c}"]) for i in (1, 2) for c in "xyz"]
print(max(abs(b - t) / sd for b, t, sd in zip(s["final_bias_dps"], tb, s["final_sigma_dps"])))
PY
}
# no finding and no warning advises the option the run used
no_advice() {
  local out=$1 opt=$2
  if jq -r '.health.findings[].text, .warnings[]' "$out/summary.json" | grep -F -- "$opt"; then
    fail "$out: a finding or warning names $opt, which the run used"
  fi
}

for case in static car; do
  "$bin" estimate --log "$t/$case.csv" --out "$t/o_$case" --selfcal > "$t/$case.txt" 2>&1 || { cat "$t/$case.txt"; fail "$case: exit"; }
  jq -e '.self_calibration.gravity_source == "ref_q"' "$t/o_$case/summary.json" > /dev/null || fail "$case: gravity_source"
  grep -q "gravity_source: ref_q" "$t/$case.txt" || { cat "$t/$case.txt"; fail "$case: the console does not say so"; }
  z=$(zmax "$t/$case.csv" "$t/o_$case")
  echo "$case: largest bias |z| = $z"
  awk -v z="$z" 'BEGIN{exit !(z < 3)}' || fail "$case: a bias $z sigma off the truth"
  no_advice "$t/o_$case" "--selfcal"
done

# the static box: sensor 2's G column y (gravity along sensor 2's +-y at platform 2's stops) recovered
"$py" - "$t/static.json" "$t/o_static/summary.json" <<'PY' || fail "static: G not recovered"
import json, sys
truth = json.load(open(sys.argv[1]))["G"][1]
sc = json.load(open(sys.argv[2]))["self_calibration"]
G, S = sc["g_sensitivity_dps_per_g"][1], sc["g_sensitivity_sigma_dps_per_g"][1]
for r in range(3):
    z = (G[r][1] - truth[r][1]) / S[r][1]
    print(f"G2[{r}][y] {G[r][1]:+.5f} +- {S[r][1]:.5f} against {truth[r][1]:+.5f}: z {z:+.2f}")
    assert S[r][1] < 0.01 and abs(z) < 3.0, "outside 3 sigma or not observed"
PY

# neither accel columns nor ref_q
"$bin" estimate --log "$t/bare.csv" --out "$t/o_bare" --selfcal > "$t/bare.txt" 2>&1 || true
jq -e '.self_calibration.gravity_source == "none"' "$t/o_bare/summary.json" > /dev/null || fail "bare: gravity_source"
grep -q "g-sensitivity cannot be estimated without accel columns or ref_q: log them" "$t/bare.txt" ||
  { cat "$t/bare.txt"; fail "bare: not told to log them"; }
no_advice "$t/o_bare" "--selfcal"
echo "ok"
