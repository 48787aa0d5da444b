#!/usr/bin/env bash
# hil replay of a log whose two gyros have unlike ranges (docs/log-format.md: gyro1_/gyro2_full_scale_dps
# override gyro_full_scale_dps): the session's log states each sensor's range as the replayed log
# does, so `estimate` reads it as it reads the original: the same rows counted saturated, and the
# wider gyro's good readings accepted. A log from the outsider's generator (tests/diagnose/probe_log.py),
# an MPU6050 (+-250 deg/s) that clips and a BMI088 (+-2000 deg/s) that does not, on a box spinning up
# to 600 deg/s.
# usage: hil_replay_full_scale.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1; src=$2
. "$src/tests/cli/lib/outsider_log.sh"

# GIVEN the log, stating the shared range 250 and sensor 2's own 2000
"$py" "$gen" --out "$t/raw.csv" --sensor mpu6050 --sensor2 bmi088 --fs1 250 --fs-key 250 --motion fast \
  --duration 120 --seed 3 > "$t/gen.out" || fail "probe_log.py"
sed 's/^# gyro_full_scale_dps: 250$/&\n# gyro2_full_scale_dps: 2000/' "$t/raw.csv" > "$t/probe.csv"
grep -q '^# gyro2_full_scale_dps: 2000$' "$t/probe.csv" || fail "could not state sensor 2's range"
sat1=$(sed -n 's/.*saturated rows s1 \([0-9]*\) s2 \([0-9]*\).*/\1/p' "$t/gen.out")
sat2=$(sed -n 's/.*saturated rows s1 \([0-9]*\) s2 \([0-9]*\).*/\2/p' "$t/gen.out")
[[ $sat1 -gt 100 && $sat2 -eq 0 ]] || fail "the generator should clip sensor 1 only: $(cat "$t/gen.out")"
# (the estimate's count: rows whose reading of either gyro is at its stated range)
"$bin" estimate --log "$t/probe.csv" --out "$t/e0" > "$t/e0.out" 2> "$t/e0.err"
grep -q "^driftless estimate: warning: $sat1 rows have a gyro value at the stated gyro_full_scale_dps (saturated)" \
  "$t/e0.err" || fail "estimate on the original: not $sat1 saturated rows: $(cat "$t/e0.err")"

# WHEN it is replayed through hil
"$bin" hil --source "replay:$t/probe.csv" --out "$t/hil" > "$t/hil.out" 2> "$t/hil.err" \
  || fail "hil replay: exit $?: $(tail -3 "$t/hil.out" "$t/hil.err")"
# THEN the session's log states both ranges as the original does
for key in "gyro_full_scale_dps: 250" "gyro2_full_scale_dps: 2000"; do
  grep -q "^# $key\$" "$t/hil/log.csv" || fail "the hil log lacks '# $key': $(grep '^#' "$t/hil/log.csv" | head -20)"
done
# AND estimate reads it as the original: sensor 2's 600 deg/s accepted, the same saturated rows
"$bin" estimate --log "$t/hil/log.csv" --out "$t/e1" > "$t/e1.out" 2> "$t/e1.err"
rc=$?
grep -q "beyond 1.1 x the gyro full scale" "$t/e1.err" && fail "estimate refuses the hil log: $(cat "$t/e1.err")"
grep -q "^driftless estimate: warning: $sat1 rows have a gyro value at the stated gyro_full_scale_dps (saturated)" \
  "$t/e1.err" || fail "estimate on the hil log (exit $rc): not $sat1 saturated rows: $(cat "$t/e1.err")"
echo "ok: $sat1 rows of sensor 1 at its 250 deg/s range, in the original and in the replayed session's log"
