#!/usr/bin/env bash
# allan on a log whose platforms flip (docs/allan.md, "A record that moves"): every axis of a flipping
# sensor turns with it, so the Earth rate along each changes at every flip, a square wave of up to
# 0.0042 deg/s that the B and K of all three axes hold. The motion check names only the hinge axis
# (it reads the flip itself); the outsider's FOG log read B = 1.4e-3 deg/s on gyro1_x, 100x the
# sensor's, with no caveat (F9). Now each flipping sensor's channels are named, and --strict exits 1.
# Logs from tests/diagnose/independent_log.py (written apart from twin/).
# usage: allan_flipping.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1; src=$2
py=/usr/bin/python3
gen=$src/tests/diagnose/independent_log.py
"$py" -c 'import numpy' 2>/dev/null || { echo "no numpy for $py: skipped"; exit 77; }
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# GIVEN a static box whose platforms flip between +-90 deg, and a single IMU that never flips
"$py" "$gen" --out "$t/flip.csv" --seed 5 --duration 300 --motion static > /dev/null || fail "generator"
"$py" "$gen" --out "$t/single.csv" --seed 5 --duration 300 --motion static --single > /dev/null || fail "generator"
# WHEN allan analyses the flipping log THEN both sensors' channels are named with the flips as the cause
"$bin" allan --log "$t/flip.csv" --out "$t/a" > "$t/a.out" 2> "$t/a.err" || fail "allan: exit $?: $(cat "$t/a.err")"
for p in 1 2; do
  grep -q "platform $p flips (plat${p}_deg spans 180 deg)" "$t/a.err" || fail "platform $p's flips not named: $(cat "$t/a.err")"
  grep -q "B and K of gyro${p}_x, gyro${p}_y, gyro${p}_z hold" "$t/a.err" || fail "sensor $p's channels not all named"
done
grep -q "driftless estimate --tune auto" "$t/a.err" || fail "no way out named"
# AND --strict makes it an exit 1
"$bin" allan --log "$t/flip.csv" --out "$t/s" --strict > /dev/null 2>&1 && fail "--strict on a flipping log exited 0"
# AND a record that does not flip gets no such warning
"$bin" allan --log "$t/single.csv" --out "$t/n" > /dev/null 2> "$t/n.err" || fail "allan on the single IMU: exit $?"
if grep -q "flips (plat" "$t/n.err"; then fail "a flip warning on a log without platforms: $(cat "$t/n.err")"; fi
echo "ok"
