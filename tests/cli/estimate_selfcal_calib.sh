#!/usr/bin/env bash
# calib.yaml from the self-calibrating mode (docs/calibration.md "calib.yaml from a
# self-calibration"): --selfcal --box-at-rest on one static log of a pair of MPU6050s writes their
# g-sensitivity and temperature coefficients with sigma; `estimate --calib` on a second log of the
# same sensors (other seed: other turn-on bias and noise) then locks without --selfcal, where the
# plain estimate fails; the twin accepts the same file as a model prior.
# usage: estimate_selfcal_calib.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
verdict() { jq -r .health.verdict "$1/summary.json"; }

# GIVEN the static scenario with one pair of sensors: G (deg/s per g) and the bias temperature
# coefficients (deg/s per degC) planted with no run-to-run draw, so two seeds are two logs of the
# same sensors
cat > "$t/pair.yaml" <<'EOF'
name: static_pair
description: static box, the same two MPU6050s in every run (planted g-sensitivity and tempco)
duration_s: 600
seed: 4
latitude_deg: 52.0
sample_rate_hz: 100
platform_readback: end_stops
model:
  box:
    stop1_error_deg: [0.12, -0.08]
    stop2_error_deg: [-0.05, 0.15]
  sensor1:
    preset: mpu6050
    effects:
      g_sensitivity: {matrix_dps_per_g: [[0.03, -0.02, 0.05], [0.04, 0.02, -0.03], [-0.05, 0.06, 0.02]], sigma_dps_per_g: 0}
      temperature: {bias_tc_dps_per_degc: [0.03, -0.05, 0.04], bias_tc_sigma_dps_per_degc: [0, 0, 0]}
  sensor2:
    preset: mpu6050
    effects:
      g_sensitivity: {matrix_dps_per_g: [[-0.04, 0.03, 0.02], [0.05, -0.03, 0.04], [0.02, -0.06, 0.03]], sigma_dps_per_g: 0}
      temperature: {bias_tc_dps_per_degc: [-0.02, 0.06, -0.04], bias_tc_sigma_dps_per_degc: [0, 0, 0]}
motion:
  type: static
  attitude_ypr_deg: [30, 0, 0]
flip_schedule:
  standstill_s: 30
  flip_angle_deg: 90
EOF
"$bin" simulate --scenario "$t/pair.yaml" --seed 4 --out "$t/a" > /dev/null 2>&1 || fail "simulate seed 4"
"$bin" simulate --scenario "$t/pair.yaml" --seed 5 --out "$t/b" > /dev/null 2>&1 || fail "simulate seed 5"

# WHEN the first log is self-calibrated with --calib-out
"$bin" estimate --log "$t/a/log.csv" --out "$t/sc" --selfcal --box-at-rest --calib-out "$t/calib.yaml" \
  --prior-out "$t/prior.yaml" > "$t/sc.out" 2> "$t/sc.err" || fail "selfcal: exit $?: $(cat "$t/sc.out" "$t/sc.err")"
# THEN calib.yaml holds G with its sigma, the temperature coefficients, nominal matrices
for key in "format: driftless-calib 1" "method: selfcal" "matrices: nominal" G_dps_per_g G_sigma \
           scale_misalignment E_frac E_sigma_frac bias_tc_dps_per_degc bias_tc_sigma_dps_per_degc \
           end_stops platform1 platform2 minus90_deg minus90_sigma_deg plus90_deg plus90_sigma_deg; do
  grep -q "$key" "$t/calib.yaml" || fail "calib.yaml lacks '$key'"
done
# AND the G it holds is the planted one where the flips observe it: sensor 2's y column (platform 2
# turns about box x, so gravity lies along sensor 2's +-y) within 4 sigma of the planted
# (0.03, -0.03, -0.06) deg/s per g, sigma well below the prior 0.0577; the other columns keep it
python3 - "$t/calib.yaml" <<'EOF' || fail "calib.yaml G against the planted G"
import sys, re
text = open(sys.argv[1]).read()
s2 = text[text.index("sensor2:"):]
def mat(key):
    m = re.search(key + r":\s*\n((?:\s*- \[.*\]\n){3})", s2)
    return [[float(v) for v in row.strip()[3:-1].split(",")] for row in m.group(1).strip().splitlines()]
G, S = mat("G_dps_per_g"), mat("G_sigma")
ok = True
for r, want in enumerate([0.03, -0.03, -0.06]):
    print(f"sensor 2 G[{r}][y] {G[r][1]:.4f} sigma {S[r][1]:.4f} (planted {want})")
    ok = ok and 0 < S[r][1] < 0.01 and abs(G[r][1] - want) < 4 * S[r][1]
    ok = ok and abs(S[r][0] - 0.0577) < 0.001  # the x column: gravity never along sensor x
sys.exit(0 if ok else 1)
EOF

# WHEN the second log is estimated without self-calibration
"$bin" estimate --log "$t/b/log.csv" --out "$t/plain" --no-selfcal > /dev/null 2>&1
[[ $(verdict "$t/plain") == failed ]] || fail "second log without --calib: verdict $(verdict "$t/plain"), expected failed"
# AND with --calib calib.yaml (no --selfcal)
"$bin" estimate --log "$t/b/log.csv" --out "$t/cal" --calib "$t/calib.yaml" > "$t/cal.out" 2> "$t/cal.err"
rc=$?
# THEN it locks, with few rejections, and exits 0
[[ $rc -eq 0 ]] || fail "second log with --calib: exit $rc: $(cat "$t/cal.out" "$t/cal.err")"
jq -e '.health.locked and .health.rejected_fraction < 0.05 and .self_calibration.enabled == false' \
  "$t/cal/summary.json" > /dev/null || fail "second log with --calib: $(jq -c .health "$t/cal/summary.json")"

# AND with --calib calib.yaml --selfcal the G and E states start at the file (docs/estimator.md 1e):
# the second run's sigma of every G and E element is at most the file's (it only learns more), its
# sensor 2 G y column stays within 4 sigma of the planted one, and it exits 0
"$bin" estimate --log "$t/b/log.csv" --out "$t/calsc" --calib "$t/calib.yaml" --selfcal --box-at-rest \
  > "$t/calsc.out" 2> "$t/calsc.err" || fail "second log with --calib --selfcal: exit $?: $(cat "$t/calsc.out" "$t/calsc.err")"
python3 - "$t/calsc/summary.json" "$t/sc/summary.json" <<'EOF' || fail "--calib --selfcal: sigma grew or G lost"
import json, sys
b, a = (json.load(open(p))["self_calibration"] for p in sys.argv[1:3])
ok = True
for key in ("g_sensitivity_sigma_dps_per_g", "scale_misalign_sigma_frac"):
    for i in range(2):
        for r in range(3):
            for c in range(3):
                if b[key][i][r][c] > a[key][i][r][c] * (1 + 1e-9) + 1e-15:
                    print(f"{key} sensor {i+1} [{r}][{c}]: {b[key][i][r][c]} > {a[key][i][r][c]}"); ok = False
# the end stops start at the file too: no sigma grew, none moved by more than 3 sigma
for k in range(4):
    if b["end_stop_sigma_deg"][k] > a["end_stop_sigma_deg"][k] * (1 + 1e-9) + 1e-15:
        print(f"end stop {k}: sigma {b['end_stop_sigma_deg'][k]} > {a['end_stop_sigma_deg'][k]}"); ok = False
    if abs(b["end_stop_deg"][k] - a["end_stop_deg"][k]) > 3 * a["end_stop_sigma_deg"][k]:
        print(f"end stop {k}: {b['end_stop_deg'][k]} moved from {a['end_stop_deg'][k]}"); ok = False
G, S = b["g_sensitivity_dps_per_g"][1], b["g_sensitivity_sigma_dps_per_g"][1]
for r, want in enumerate([0.03, -0.03, -0.06]):
    print(f"second run: sensor 2 G[{r}][y] {G[r][1]:.4f} sigma {S[r][1]:.4f} (first {a['g_sensitivity_sigma_dps_per_g'][1][r][1]:.4f}, planted {want})")
    ok = ok and abs(G[r][1] - want) < 4 * S[r][1] and S[r][1] < a["g_sensitivity_sigma_dps_per_g"][1][r][1]
sys.exit(0 if ok else 1)
EOF

# AND the twin accepts the model prior (a scenario whose model: block is the prior): the run plants
# the self-calibrated G of sensor 2
{ printf 'name: from_prior\nduration_s: 5\nseed: 5\n'; grep -v '^#' "$t/prior.yaml"; printf 'motion: {type: static}\n'; } > "$t/twin.yaml"
"$bin" simulate --scenario "$t/twin.yaml" --out "$t/twin" > /dev/null 2> "$t/twin.err" || fail "simulate with the prior: $(cat "$t/twin.err")"
g=$(grep -o 'matrix_dps_per_g: \[\[[^]]*\], \[[^]]*\]' "$t/twin/scenario.resolved.yaml" | sed -n 2p)
# the self-calibrated sensor 2 G[0][y] (summary.json), cut after 4 decimals
want=$(jq -r '.self_calibration.g_sensitivity_dps_per_g[1][0][1]' "$t/sc/summary.json" | awk '{printf "%.4f", int($1 * 10000) / 10000}')
[[ $g == *"$want"* ]] || fail "the prior's sensor 2 G (G[0][y] $want) is not in the resolved scenario: $g"
# AND the box's stop errors are the file's end stops, [-90, +90] per platform (the file's own
# values, not the planted 0.12 / -0.08 and -0.05 / 0.15: a static box does not observe them)
python3 - "$t/calib.yaml" "$t/twin/scenario.resolved.yaml" <<'EOF' || fail "the prior's stop errors are not the file's end stops"
import re, sys
calib, resolved = open(sys.argv[1]).read(), open(sys.argv[2]).read()
stops = calib[calib.index("\nend_stops:"):]
for p in (1, 2):
    block = stops[stops.index(f"platform{p}:"):]
    want = [float(re.search(rf"\b{k}_deg: (\S+)", block).group(1)) for k in ("minus90", "plus90")]
    got = [float(v) for v in re.search(rf"stop{p}_error_deg: \[([^]]*)\]", resolved).group(1).split(",")]
    print(f"platform {p}: stop errors {got}, calib.yaml {want}")
    assert all(abs(g - w) < 1e-9 for g, w in zip(got, want)), (got, want)
EOF
# a calib.yaml whose end stop has a negative sigma is refused: file, line, key, what was expected, exit 1
awk '/^  platform2:/ { p = 1 } p && /plus90_sigma_deg:/ && !done { sub(/: .*/, ": -0.01"); done = 1 } { print }' \
  "$t/calib.yaml" > "$t/bad.yaml"
line=$(grep -n 'plus90_sigma_deg: -0.01' "$t/bad.yaml" | cut -d: -f1)
[[ -n $line ]] || fail "could not plant the negative sigma"
"$bin" estimate --log "$t/b/log.csv" --out "$t/bad" --calib "$t/bad.yaml" > /dev/null 2> "$t/bad.err"
rc=$?
[[ $rc -ne 0 ]] || fail "a negative end-stop sigma accepted (exit 0)"
grep -q "bad.yaml:$line: end_stops.platform2.plus90_sigma_deg: .*a sigma must be >= 0 deg" "$t/bad.err" \
  || fail "the error does not name file:line:key and what was expected (exit $rc): $(cat "$t/bad.err")"
# --calib-out without --selfcal is refused
"$bin" estimate --log "$t/b/log.csv" --out "$t/x" --calib-out "$t/x.yaml" > /dev/null 2> "$t/x.err"
[[ $? -ne 0 ]] && grep -q -- "--calib-out needs --selfcal" "$t/x.err" || fail "--calib-out without --selfcal accepted"
echo "ok"
