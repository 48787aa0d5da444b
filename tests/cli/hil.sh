#!/usr/bin/env bash
# driftless hil end to end: emulated I2C run, a switch-over from a replayed log to emulated I2C,
# the emulated serial link over a pty, one clear error for a missing device, options no source uses
# refused, and a switch-over that never happened reported as a failure.
# usage: bash hil.sh <path-to-driftless> <source-dir>
set -euo pipefail
bin=$1
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# GIVEN emulated sensors, WHEN hil runs 120 s as fast as possible, THEN a complete valid log
"$bin" hil --source emu-i2c --out "$out/a" --duration 120 --print-every 60 > "$out/a.txt"
"$bin" check --log "$out/a/log.csv" > "$out/a.check"
grep -q "12000 rows" "$out/a.check" || fail "emu-i2c: expected 12000 rows: $(head -1 "$out/a.check")"
grep -q "complete: true" "$out/a/log.csv" || fail "emu-i2c: log not complete"
# the emulated box's biases are b1 = (0.5, -0.3, 0.8), b2 = (-0.6, 0.4, 0.2) deg/s
awk '/^bias 1/ { ok = ($4 - 0.5)^2 < 4e-4 && ($5 + 0.3)^2 < 4e-4 && ($6 - 0.8)^2 < 4e-4 }
     END { exit !ok }' "$out/a.txt" || fail "emu-i2c: bias 1 did not converge: $(grep '^bias 1' "$out/a.txt")"
awk '/^bias 2/ { ok = ($4 + 0.6)^2 < 4e-4 && ($5 - 0.4)^2 < 4e-4 && ($6 - 0.2)^2 < 4e-4 }
     END { exit !ok }' "$out/a.txt" || fail "emu-i2c: bias 2 did not converge: $(grep '^bias 2' "$out/a.txt")"
# the same seed gives a byte-identical log
"$bin" hil --source emu-i2c --out "$out/a2" --duration 120 > /dev/null
cmp -s "$out/a/log.csv" "$out/a2/log.csv" || fail "emu-i2c: same seed, different log"

# switch-over: replay the first log, then emulated hardware from t = 50 s
"$bin" hil --source "replay:$out/a/log.csv" --switch-to emu-i2c --at 50 --duration 100 --out "$out/b" > "$out/b.txt"
"$bin" check --log "$out/b/log.csv" > "$out/b.check"
grep -q "10000 rows" "$out/b.check" || fail "switch: expected 10000 rows: $(head -1 "$out/b.check")"
grep -q "sample interval: 0.010000 .. 0.010000 s" "$out/b.check" || fail "switch: a sample was lost or duplicated"
[ "$(grep -c '^# event: t=49.990000 switch: replay:.* -> emu-i2c' "$out/b/log.csv")" = 1 ] || fail "switch: no event line"
grep -q "^50.000000," "$out/b/log.csv" || fail "switch: no row at t = 50 s"

# a replayed log with a damaged row: the session stops there, exits non-zero naming file:line, and
# its log keeps the rows before and says it is incomplete
awk -F, '$1 == "30.000000" { $2 = "x" } 1' OFS=, "$out/a/log.csv" > "$out/damaged.csv"
line=$(grep -n '^30.000000,' "$out/damaged.csv" | cut -d: -f1)
if "$bin" hil --source "replay:$out/damaged.csv" --out "$out/dmg" > "$out/dmg.txt" 2> "$out/dmg.err"; then
  fail "damaged replay: exit 0"
fi
grep -q "damaged.csv:$line: column 'gyro1_x'" "$out/dmg.err" || fail "damaged replay: cause not named: $(cat "$out/dmg.err")"
grep -q "^# incomplete: replay:.*damaged.csv:$line" "$out/dmg/log.csv" || fail "damaged replay: log does not say it is incomplete"
[ "$(grep -c '^[0-9]' "$out/dmg/log.csv")" = 3000 ] || fail "damaged replay: the 3000 rows before the damage are not all kept"

# the twin, then emulated hardware from t = 20 s; and emu-i2c driven by the twin's sensor model
"$bin" hil --source twin --switch-to emu-i2c --at 20 --duration 40 --out "$out/t" > "$out/t.txt"
"$bin" check --log "$out/t/log.csv" > "$out/t.check"
grep -q "4000 rows" "$out/t.check" || fail "twin switch: expected 4000 rows: $(head -1 "$out/t.check")"
grep -q "sample interval: 0.010000 .. 0.010000 s" "$out/t.check" || fail "twin switch: a sample was lost or duplicated"
grep -q "^# event: t=19.990000 switch: twin:default -> emu-i2c" "$out/t/log.csv" || fail "twin switch: no event line"
"$bin" hil --source emu-i2c --emu-sensor mpu6050 --duration 30 --out "$out/m" > /dev/null
grep -q "complete: true" "$out/m/log.csv" || fail "emu-i2c with the mpu6050 sensor model: log not complete"

# the serial link against the emulated microcontroller on a pty, 1.5 s in real time
"$bin" hil --source emu-serial --out "$out/c" --duration 1.5 > "$out/c.txt"
"$bin" check --log "$out/c/log.csv" > "$out/c.check"
grep -q "150 rows" "$out/c.check" || fail "emu-serial: expected 150 rows: $(head -1 "$out/c.check")"

# emu-serial with the twin's sensor model: the ideal preset reads only the Earth rate
"$bin" hil --source emu-serial --emu-sensor ideal --out "$out/s" --duration 1 > /dev/null
awk -F, '!/^#/ && $1 != "t" && NF > 6 { for (i = 2; i <= 7; ++i) if (($i)^2 > 0.01^2) bad = 1; n++ }
         END { exit (bad || n < 90) }' "$out/s/log.csv" \
  || fail "emu-serial --emu-sensor ideal: gyros not at the Earth rate (the built-in generator's 0.5 deg/s biases?)"
if "$bin" hil --source emu-serial --emu-sensor nosuchchip --out "$out/s2" --duration 1 2> "$out/s2.err"; then
  fail "emu-serial: unknown --emu-sensor accepted"
fi

# the twin with its servos commanded by the bridge's flip schedule, in eq. (5)'s order (platform 2 first)
"$bin" hil --source twin --twin-flips bridge --standstill 5 --duration 30 --out "$out/tb" > /dev/null
grep -q "^# flip_control: bridge" "$out/tb/log.csv" || fail "twin bridge flips: metadata"
# the positions the platforms rested at, in order (columns 8, 9: plat1_deg, plat2_deg)
order=$(awk -F, '!/^#/ && $1 != "t" && $8 != "" && $9 != "" { p = ($8 + 0) "," ($9 + 0); if (p != last) { printf "%s ", p; last = p } }' "$out/tb/log.csv")
[[ $order == "90,90 90,-90 -90,-90 -90,90 "* ]] || fail "twin bridge flips: positions '$order', expected eq. (5)'s cycle 90,90 90,-90 -90,-90 -90,90"
"$bin" check --log "$out/tb/log.csv" > "$out/tb.check" || fail "twin bridge flips: check"

# a run killed mid-way (SIGKILL: no chance to finish) leaves a valid log that says so
"$bin" hil --source emu-i2c --realtime --out "$out/k" --duration 60 > /dev/null 2>&1 &
pid=$!
for _ in $(seq 100); do  # until at least 1 s of rows reached the disk (at most 20 s)
  [[ -f "$out/k/log.csv" && $(grep -vc '^#' "$out/k/log.csv") -gt 101 ]] && break
  sleep 0.2
done
kill -KILL "$pid"
wait "$pid" 2> /dev/null || true
grep -q "^# complete: false" "$out/k/log.csv" || fail "killed run: the log does not say complete: false"
"$bin" check --log "$out/k/log.csv" > "$out/k.check" 2> "$out/k.err" || { cat "$out/k.err"; fail "killed run: check refuses the log"; }
rows=$(grep -o "[0-9]* rows" "$out/k.check" | head -1 | cut -d' ' -f1)
[[ ${rows:-0} -ge 100 ]] || fail "killed run: only '${rows:-0}' rows in the log"
# estimate reads it (a second of rows holds no standstill: health 'failed' exits 1 with every output)
rc=0
"$bin" estimate --log "$out/k/log.csv" --out "$out/k_est" > /dev/null 2> "$out/k_est.err" || rc=$?
[[ $rc -eq 0 ]] || { [[ $rc -eq 1 ]] && grep -q '"verdict": "failed"' "$out/k_est/summary.json"; } \
  || { cat "$out/k_est.err"; fail "killed run: estimate refuses the log"; }

# a missing device: one clear error, non-zero exit, no log
for src in i2c:/dev/i2c-77 serial:/dev/ttyNoSuchPort; do
  if "$bin" hil --source "$src" --out "$out/d" > "$out/d.txt" 2> "$out/d.err"; then fail "$src: exit 0"; fi
  [ "$(wc -l < "$out/d.err")" = 1 ] || fail "$src: expected one error line, got: $(cat "$out/d.err")"
  grep -q "${src#*:}" "$out/d.err" || fail "$src: error does not name the device: $(cat "$out/d.err")"
  [ ! -e "$out/d/log.csv" ] || fail "$src: a log was written"
done
# --twin-flips bridge without the twin is refused
if "$bin" hil --source emu-i2c --twin-flips bridge --out "$out/g" --duration 1 2> "$out/g.err"; then fail "--twin-flips without twin accepted"; fi
grep -q "needs the twin source" "$out/g.err" || fail "--twin-flips without twin: $(cat "$out/g.err")"
# a bad switch request is refused before anything runs
if "$bin" hil --source emu-i2c --switch-to emu-serial --out "$out/e" --duration 1 2> "$out/e.err"; then fail "--switch-to without --at accepted"; fi
# --fdi: a stuck axis planted into the emulated chips is isolated, logged, in fdi.json, and exit 1
rc=0
"$bin" hil --source emu-i2c --fdi --emu-fault stuck:2:y@45 --out "$out/f" --duration 60 > "$out/f.txt" 2> "$out/f.err" || rc=$?
[[ $rc -eq 1 ]] || { cat "$out/f.err"; fail "--fdi with a stuck axis: exit $rc, expected 1"; }
grep -q "sensor 2 is faulty" "$out/f.err" || fail "--fdi: no verdict line: $(cat "$out/f.err")"
grep -q "^# event: t=45\.[0-9]* fdi: fault isolated: stuck on sensor 2 axis y" "$out/f/log.csv" || fail "--fdi: no event line in the log"
grep -q '"verdict": "fault"' "$out/f/fdi.json" || fail "--fdi: fdi.json verdict: $(cat "$out/f/fdi.json")"
grep -q '"axis": "y"' "$out/f/fdi.json" || fail "--fdi: fdi.json axis"
grep -q "^# emu_fault: stuck on sensor 2 axis y from t=45 s" "$out/f/log.csv" || fail "--fdi: the log's metadata does not say the planted fault"
# fault-free: healthy, exit 0; too short to learn the residual noise: not monitored, exit 1
"$bin" hil --source emu-i2c --fdi --out "$out/h" --duration 90 > "$out/h.txt" || fail "--fdi fault-free: exit $?"
grep -q '"verdict": "healthy"' "$out/h/fdi.json" || fail "--fdi fault-free: $(cat "$out/h/fdi.json")"
if "$bin" hil --source emu-i2c --fdi --out "$out/s" --duration 5 > /dev/null 2> "$out/s.err"; then fail "--fdi on 5 s: exit 0"; fi
grep -q "fdi: not monitored" "$out/s.err" || fail "--fdi on 5 s: $(cat "$out/s.err")"
# a planted fault needs an emulated source, and a readable spelling
if "$bin" hil --source twin --emu-fault stuck:1:x@1 --out "$out/t" --duration 1 2> "$out/t.err"; then fail "--emu-fault on the twin accepted"; fi
grep -q "needs --source (or --switch-to) emu-i2c" "$out/t.err" || fail "--emu-fault on the twin: $(cat "$out/t.err")"
if "$bin" hil --source emu-i2c --emu-fault stuck:3:x@1 --out "$out/u" --duration 1 2> "$out/u.err"; then fail "--emu-fault sensor 3 accepted"; fi
grep -q "sensor '3' is not 1 or 2" "$out/u.err" || fail "--emu-fault sensor 3: $(cat "$out/u.err")"
# options the chosen sources do not use are refused (usage error, exit 2), not silently ignored
rc=0; "$bin" hil --source "replay:$out/a/log.csv" --rate 1000 --out "$out/r" 2> "$out/r.err" || rc=$?
[[ $rc -eq 2 ]] || fail "--rate with a replay: exit $rc, expected 2"
grep -q -- "--rate is for i2c:.*replay:.*would ignore it" "$out/r.err" || fail "--rate with a replay: $(cat "$out/r.err")"
rc=0; "$bin" hil --source "replay:$out/a/log.csv" --switch-to emu-i2c --at 60 --seed 4 --duration 70 --out "$out/r2" > /dev/null || rc=$?
[[ $rc -eq 0 ]] || fail "--seed for the emulated second source refused: exit $rc"
rc=0; "$bin" hil --source emu-i2c --duration -5 --out "$out/r3" 2> "$out/r3.err" || rc=$?
[[ $rc -eq 2 ]] || fail "--duration -5: exit $rc, expected 2"
# a switch to a source of another rate is refused before anything runs: the log states one rate
rc=0; "$bin" hil --source "replay:$out/a/log.csv" --switch-to emu-i2c --rate 200 --at 60 --duration 70 --out "$out/r4" 2> "$out/r4.err" || rc=$?
[[ $rc -ne 0 ]] || fail "a switch from 100 Hz to 200 Hz accepted"
grep -q "switch-to emu-i2c samples at 200 Hz but --source replay:.* at 100 Hz" "$out/r4.err" || fail "rate switch: $(cat "$out/r4.err")"
[ ! -e "$out/r4/log.csv" ] || fail "rate switch: a log was written"
# a switch-over that never happens (the replay ends first) is not a success
rc=0; "$bin" hil --source "replay:$out/a/log.csv" --switch-to emu-i2c --at 200 --duration 300 --out "$out/w" > /dev/null 2> "$out/w.err" || rc=$?
[[ $rc -eq 1 ]] || fail "a switch after the replay's end: exit $rc, expected 1"
grep -q "switch to emu-i2c at t=200 s did not happen: replay:.* ended at t=119.990 s" "$out/w.err" || fail "missed switch: $(cat "$out/w.err")"
grep -q "^# event: t=119.990000 switch: to emu-i2c at t=200 s did not happen" "$out/w/log.csv" || fail "missed switch: no event line"
# a replayed log without sample_rate_hz: refused, saying what to add
grep -v '^# sample_rate_hz:' "$out/a/log.csv" > "$out/norate.csv"
if "$bin" hil --source "replay:$out/norate.csv" --out "$out/nr" > /dev/null 2> "$out/nr.err"; then fail "a replay without a rate accepted"; fi
grep -q "norate.csv has no sample_rate_hz in its metadata: add a line '# sample_rate_hz: <Hz>'" "$out/nr.err" ||
  fail "replay without a rate: $(cat "$out/nr.err")"
# a replay whose gyro2_z is empty in every row (a dead axis) never locks: said, with the reason
awk -F, 'BEGIN { OFS = "," } /^#/ { print; next } /^t,/ { for (i = 1; i <= NF; ++i) if ($i == "gyro2_z") c = i; print; next }
  { $c = ""; print }' "$out/a/log.csv" > "$out/dead.csv"
"$bin" hil --source "replay:$out/dead.csv" --out "$out/d" > /dev/null 2> "$out/d.err" || fail "dead axis: exit $?"
grep -q "warning: the filter never locked (largest sigma 20 deg/s.*12000 of 12000 samples lacked a gyro value" "$out/d.err" ||
  fail "dead axis: $(cat "$out/d.err")"
"$bin" hil --source "replay:$out/a/log.csv" --out "$out/d2" > /dev/null 2> "$out/d2.err"
if grep -q "never locked" "$out/d2.err"; then fail "a locked replay warns: $(cat "$out/d2.err")"; fi
echo "hil: ok"
