#!/usr/bin/env bash
# The self-calibrating mode (docs/estimator.md section 1b) on the built-in static scenario (MPU6050
# defaults, g-sensitivity not calibrated out): without it the estimate fails, exits 1 and names
# --selfcal; with --selfcal --box-at-rest, or --selfcal alone (box dwells), it locks, rejects nothing
# and reports G with its sigma.
# usage: estimate_selfcal.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
verdict() { grep -o '"verdict": "[a-z]*"' "$1/summary.json" | cut -d'"' -f4; }

# GIVEN 10 minutes of the static scenario
"$bin" simulate --scenario static --duration 600 --out "$t/sim" > /dev/null 2>&1 || fail "simulate: exit $?"
# WHEN estimated with the six-state model (--no-selfcal) THEN failed, exit 1, and the finding proposes --selfcal
"$bin" estimate --log "$t/sim/log.csv" --out "$t/plain" --no-selfcal > "$t/plain.out" 2> "$t/plain.err"
[[ $? -eq 1 ]] || fail "--no-selfcal: expected exit 1: $(cat "$t/plain.err")"
[[ $(verdict "$t/plain") == failed ]] || fail "--no-selfcal: verdict $(verdict "$t/plain")"
grep -q -- "--selfcal" "$t/plain.err" || fail "--no-selfcal: the fix is not named: $(cat "$t/plain.err")"
# AND the console says the attitude was not compared (no "nan deg/h" line)
grep -q "attitude: not compared (the filter never locked on" "$t/plain.out" || fail "--no-selfcal: $(cat "$t/plain.out")"
if grep -q "nan" "$t/plain.out"; then fail "--no-selfcal: a nan on the console: $(cat "$t/plain.out")"; fi
grep -q '"self_calibration_choice": {"mode": "off", "tried": false' "$t/plain/summary.json" ||
  fail "--no-selfcal: the choice is not recorded: $(grep -o '"self_calibration_choice": {[^}]*' "$t/plain/summary.json")"
# WHEN estimated with defaults THEN (docs/estimator.md section 1i) the six-state pass's rejections at
# one position call for the self-calibrating pass, which is kept: ok with --strict, the same estimates
# as --selfcal, the choice said on the console and in summary.json
"$bin" estimate --log "$t/sim/log.csv" --out "$t/auto" --strict > "$t/auto.out" 2> "$t/auto.err" ||
  fail "defaults: exit $?: $(cat "$t/auto.out" "$t/auto.err")"
[[ $(verdict "$t/auto") == ok ]] || fail "defaults: verdict $(verdict "$t/auto")"
grep -q "the six-state model does not fit this log (verdict failed, finding rejections_at_position" "$t/auto.err" ||
  fail "defaults: the switch is not said: $(cat "$t/auto.err")"
grep -q "self-calibration (auto): used; its verdict ok" "$t/auto.out" || fail "defaults: no choice line: $(cat "$t/auto.out")"
python3 - "$t/auto/summary.json" << 'EOF2' || fail "defaults: self_calibration_choice: $(grep -o '"self_calibration_choice": {.*}},' "$t/auto/summary.json")"
import json, sys
c = json.load(open(sys.argv[1]))["self_calibration_choice"]
ok = c["mode"] == "auto" and c["tried"] and c["used"] and not c["interrupted"]
ok = ok and c["called_for_by"] == "rejections_at_position"
ok = ok and c["six_state"]["health_verdict"] == "failed" and c["six_state"]["rejected_fraction"] > 0.3
ok = ok and c["self_calibrating"]["health_verdict"] == "ok" and c["self_calibrating"]["rejected_fraction"] == 0
sys.exit(0 if ok else 1)
EOF2
[[ ! -e "$t/auto/.selfcal-pass" ]] || fail "defaults: the self-calibrating pass's folder was left behind"
grep -q '^self_calibration: true' "$t/auto/config_used.txt" || fail "defaults: config_used.txt is not the kept pass's"
# WHEN estimated with --selfcal --box-at-rest THEN ok (exit 0 even with --strict), nothing rejected
"$bin" estimate --log "$t/sim/log.csv" --out "$t/sc" --selfcal --box-at-rest --strict > "$t/sc.out" 2> "$t/sc.err" ||
  fail "--selfcal --box-at-rest: exit $?: $(cat "$t/sc.out" "$t/sc.err")"
[[ $(verdict "$t/sc") == ok ]] || fail "--selfcal: verdict $(verdict "$t/sc")"
grep -q '"rejected": 0,' "$t/sc/summary.json" || fail "--selfcal: updates rejected"
grep -q '"self_calibration": {"enabled": true' "$t/sc/summary.json" || fail "no self_calibration block"
grep -q '"g_sensitivity_sigma_dps_per_g": \[\[\[' "$t/sc/summary.json" || fail "no G sigma in summary.json"
# AND when only the self-calibrating pass can refuse the log (an accel value that is no number: the
# six-state pass does not parse those columns) THEN the six-state results stand, the reason is said,
# and summary.json carries it; nothing of the second pass is left behind
awk -F, -v OFS=, '/^t,/ { for (i = 1; i <= NF; ++i) if ($i == "accel1_x") c = i; print; next }
  !/^#/ && ++n == 30000 { $c = "abc" } { print }' "$t/sim/log.csv" > "$t/bad_accel.csv"
"$bin" estimate --log "$t/bad_accel.csv" --out "$t/bad" > /dev/null 2> "$t/bad.err"
[[ $? -eq 1 ]] || fail "bad accel: expected exit 1 (the six-state verdict)"
grep -q "the self-calibrating pass could not read the log (.*bad_accel.csv:[0-9]*: column 'accel1_x': expected a number" "$t/bad.err" ||
  fail "bad accel: the reason is not said: $(cat "$t/bad.err")"
grep -q '"used": false, "interrupted": false, "error": ".*accel1_x' "$t/bad/summary.json" || fail "bad accel: no error in summary.json"
[[ ! -e "$t/bad/.selfcal-pass" ]] || fail "bad accel: the second pass's folder was left behind"
# AND the same log through a FIFO (read once: no second pass, so its accel columns are not read)
# THEN the six-state results as from the file, and the console says why no second pass
mkfifo "$t/bad.fifo" && { cat "$t/bad_accel.csv" > "$t/bad.fifo" & }
timeout 120 "$bin" estimate --log "$t/bad.fifo" --out "$t/badfifo" > /dev/null 2> "$t/badfifo.err"
status=$?
wait
[[ $status -eq 1 ]] || fail "bad accel through a FIFO: expected exit 1 (the six-state verdict), got $status: $(cat "$t/badfifo.err")"
grep -q "the log is not a regular file, so it cannot be read again" "$t/badfifo.err" ||
  fail "bad accel through a FIFO: $(cat "$t/badfifo.err")"
cmp -s "$t/bad/estimate.csv" "$t/badfifo/estimate.csv" || fail "bad accel through a FIFO: estimate.csv differs from the file's"
"$bin" estimate --log "$t/sim/log.csv" --out "$t/forced" --selfcal > /dev/null 2>&1 || fail "--selfcal: exit $?"
cmp -s "$t/auto/estimate.csv" "$t/forced/estimate.csv" || fail "defaults: estimate.csv differs from --selfcal's"
cmp -s "$t/auto/attitude.csv" "$t/forced/attitude.csv" || fail "defaults: attitude.csv differs from --selfcal's"
# AND with --selfcal alone the box dwells between flips (docs/estimator.md section 1d) measure the
# vertical: ok with --strict, dwell updates reported, none rejected
"$bin" estimate --log "$t/sim/log.csv" --out "$t/dw" --selfcal --strict > /dev/null 2> "$t/dw.err" ||
  fail "--selfcal (box dwells): exit $?: $(cat "$t/dw.err")"
[[ $(verdict "$t/dw") == ok ]] || fail "--selfcal (box dwells): verdict $(verdict "$t/dw")"
grep -Eq '"box_dwells": \{"updates": [1-9][0-9]*, "rejected": 0, "refused_moving": 0, "refused_turning": 0\}' "$t/dw/summary.json" ||
  fail "--selfcal: no box dwell updates: $(grep -o '"box_dwells": {[^}]*}' "$t/dw/summary.json")"
grep -Eq '"flips": \{"updates": [1-9][0-9]*, "rejected": 0, "nis_mean": [0-9.]+, "skipped_clipped": 0\}' "$t/dw/summary.json" ||
  fail "--selfcal: no flip updates: $(grep -o '"flips": {[^}]*}' "$t/dw/summary.json")"
# AND without box dwells (box_dwell_updates: false), flip updates (they see gravity at the
# platform's angles between the stops: a little of the vertical) nor --box-at-rest the lock
# failure names --box-at-rest
printf 'box_dwell_updates: false\nflip_updates: false\n' > "$t/nodw.yaml"
"$bin" estimate --log "$t/sim/log.csv" --out "$t/free" --selfcal --config "$t/nodw.yaml" > /dev/null 2> "$t/free.err"
[[ $? -eq 1 ]] || fail "--selfcal without dwells: expected exit 1"
grep -q -- "--box-at-rest" "$t/free.err" || fail "--selfcal alone: --box-at-rest not proposed: $(cat "$t/free.err")"
echo "ok"
