#!/usr/bin/env bash
# Data nobody here made: the tool gets it right, or fails loudly (a non-zero exit and the cause on
# stderr). The serious cases a new user met (docs/import.md, docs/allan.md, docs/log-format.md):
#  1. a text recording in deg/s beside an accelerometer in m/s^2 (no units written): not read as
#     rad/s (that made N 57x too large, exit 0);
#  2. a recording cut off mid-write (last line without its end): the rows before it are analysed;
#  3. `check`/`estimate` on a recording from another tool: refused, and told to `convert`;
#  4. a record that moves (real hand-turned MPU6050, the independent generator's pan/tilt box):
#     `allan` warns that the figures are the motion's, and `--strict` exits 1; a static real record
#     stays quiet;
#  5. a log that says complete: true but was cut mid-row: refused, saying it is the cut last line;
#  6. an Arduino log (millis() stamps that jitter by 1 ms): its time column found, its true rate;
#  7. rows stamped with the date and time (phone apps, Python loggers): read;
#  8. a ground truth with its quaternion scalar last (the header says so): joined in that order.
set -uo pipefail
bin=$1; src=$2
py=/usr/bin/python3
real=$src/../shared/realdata/mpu6050-sunsided
[[ -f $real/rotate-ccw-around-z-pointing-up/mpu6050.csv ]] || { echo "no real data under $src/../shared/realdata: skipped"; exit 77; }
[[ -x $py ]] || { echo "no $py: skipped"; exit 77; }
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }  # every case runs: each bug is named
n_of() { jq -r ".channels[\"$2\"].N.value" "$1/allan_fit.json"; }
within() { awk -v a="$1" -v b="$2" -v r="$3" 'BEGIN { d = (a - b) / b; if (d < 0) d = -d; exit !(d <= r) }'; }

# a foreign text file: columns in another order, gyro deg/s (bias 0.5, -0.3, 0.2; white noise
# N = 0.01 deg/s/sqrt(Hz), so sigma = N sqrt(100 Hz) = 0.1 deg/s), accelerometer m/s^2, 100 Hz, 120 s
$py - "$t/reorder.csv" <<'EOF'
import random, sys
random.seed(11)
with open(sys.argv[1], "w") as f:
    f.write("gz,temp,ax,gx,ay,time,az,gy\n")
    for i in range(12000):
        g = [b + random.gauss(0.0, 0.1) for b in (0.5, -0.3, 0.2)]
        a = [random.gauss(0.0, 0.02), random.gauss(0.0, 0.02), 9.80665 + random.gauss(0.0, 0.02)]
        f.write("%.5f,%.3f,%.5f,%.5f,%.5f,%.2f,%.5f,%.5f\n" % (g[2], 30.0, a[0], g[0], a[1], 0.01 * i, a[2], g[1]))
EOF

# 1. the deg/s rates are read as deg/s: N within 10 % of 0.01 deg/s/sqrt(Hz), and the reason said
"$bin" allan --in "$t/reorder.csv" --out "$t/a1" > "$t/a1.out" 2> "$t/a1.err" || { cat "$t/a1.err"; fail "allan on reorder.csv"; }
for c in gx gy gz; do
  n=$(n_of "$t/a1" $c)
  within "$n" 0.01 0.10 || fail "case 1: N of $c = $n deg/s/sqrt(Hz), planted 0.01 (read as rad/s?): $(grep rates "$t/a1.out")"
done
grep -q "rates in deg/s, although the accelerometer reads g in m/s^2" "$t/a1.out" || fail "case 1: the unit choice is not said"

# 2. the same file cut mid-write: the rows before the cut are analysed, the cut is said
head -c -20 "$t/reorder.csv" > "$t/cut.csv"
"$bin" allan --in "$t/cut.csv" --out "$t/a2" > "$t/a2.out" 2> "$t/a2.err" || { cat "$t/a2.err"; fail "case 2: allan refuses a recording cut mid-write"; }
grep -q "the last line is cut off" "$t/a2.out" || fail "case 2: the cut line is not said"
[[ $(jq -r .samples "$t/a2/allan_fit.json") == 11999 ]] || fail "case 2: samples $(jq -r .samples "$t/a2/allan_fit.json"), expected 11999"
"$bin" convert --in "$t/cut.csv" --out "$t/cut_log.csv" > "$t/c2.out" 2>&1 || { cat "$t/c2.out"; fail "case 2: convert"; }
"$bin" check --log "$t/cut_log.csv" > /dev/null 2>&1 || fail "case 2: check refuses the converted log"

# 3. a recording given where a log is expected: refused, and told to convert it
for cmd in check estimate; do
  args=(--log "$t/reorder.csv"); [[ $cmd == estimate ]] && args+=(--out "$t/e3")
  "$bin" $cmd "${args[@]}" > /dev/null 2> "$t/e3.err" && fail "case 3: $cmd accepted a foreign recording"
  grep -q "driftless convert --in FILE --out LOG.csv" "$t/e3.err" || fail "case 3: $cmd does not point to convert: $(cat "$t/e3.err")"
done

# 4. records that move: a real hand-turned MPU6050 and the independent generator's pan/tilt box
"$bin" allan --in "$real/rotate-ccw-around-z-pointing-up/mpu6050.csv" --out "$t/a4" > /dev/null 2> "$t/a4.err" ||
  fail "case 4: allan failed without --strict"
grep -q "warning: the record is not at rest" "$t/a4.err" || fail "case 4: a hand-turned record gets no warning"
jq -e '.warnings | length == 1' "$t/a4/allan_fit.json" > /dev/null || fail "case 4: allan_fit.json lacks the warning"
$py "$src/tests/diagnose/independent_log.py" --out "$t/pan_tilt.csv" --seed 3 --rate 100 --duration 60 --motion pan_tilt > /dev/null ||
  fail "case 4: the independent generator"
"$bin" allan --log "$t/pan_tilt.csv" --strict --out "$t/a5" > /dev/null 2> "$t/a5.err"
rc=$?
[[ $rc == 1 ]] || fail "case 4: --strict on a moving log exits $rc, expected 1"
grep -q "not at rest" "$t/a5.err" || fail "case 4: no cause on stderr: $(cat "$t/a5.err")"
"$bin" allan --in "$real/unmoved-with-x-pointing-forward/mpu6050.csv" --strict --out "$t/a6" > /dev/null 2> "$t/a6.err" ||
  fail "case 4: a static real record fails --strict: $(cat "$t/a6.err")"
# the streaming pass (.npy, bags) checks too: a robot that starts turning at 50 s
$py -c "
import numpy as np, sys
rng = np.random.default_rng(1); t = np.arange(20000) / 100.0
g = 0.1 * rng.standard_normal((20000, 3)) + [0.5, -0.3, 0.2]; g[:, 0] += 40 * np.sin(0.5 * t) * (t > 50)
np.save(sys.argv[1], np.column_stack([t, g]))" "$t/moving.npy"
"$bin" allan --in "$t/moving.npy" --time-column 1 --strict --out "$t/a9" > /dev/null 2> "$t/a9.err"
rc=$?
[[ $rc == 1 ]] && grep -q "not at rest.*first at 5[01] s" "$t/a9.err" || fail "case 4: streamed .npy that turns: exit $rc, $(cat "$t/a9.err")"

# 5. a log that says complete: true, cut mid-row: refused, naming the cut last line
head -c -15 "$t/pan_tilt.csv" > "$t/cut_complete.csv"
"$bin" check --log "$t/cut_complete.csv" > /dev/null 2> "$t/e5.err" && fail "case 5: a cut complete log accepted"
grep -q "it is the last line and has no line end" "$t/e5.err" || fail "case 5: the cause is not said: $(cat "$t/e5.err")"
# 6. an Arduino log: millis() stamps of a loop that takes 10.33 ms (steps 10, 10, 11 ms): the time
#    column is found and the rate is the loop's 96.8 Hz, not the median step's 100 Hz
$py - "$t/millis.csv" <<'EOF2'
import random, sys
random.seed(5)
with open(sys.argv[1], "w") as f:
    f.write("millis,gx,gy,gz\n")
    for i in range(6000):
        f.write("%d,%.2f,%.2f,%.2f\n" % (12345 + 10 * i + i // 3, 0.5 + random.gauss(0, 0.1), random.gauss(0, 0.1), 0.2))
EOF2
"$bin" allan --in "$t/millis.csv" --out "$t/a7" > "$t/a7.out" 2> "$t/a7.err" || fail "case 6: allan on an Arduino log: $(cat "$t/a7.err")"
rate=$(jq -r .sample_rate_hz "$t/a7/allan_fit.json" 2> /dev/null)
within "${rate:-0}" $(awk 'BEGIN { print 3000 / 31 }') 0.001 || fail "case 6: rate $rate Hz, the loop runs at 96.77 Hz"
# 7. a logger that stamps rows with the date and time: read (it was "no rows of numbers"), 100 Hz
$py - "$t/iso.csv" <<'EOF2'
import random, sys
random.seed(2)
with open(sys.argv[1], "w") as f:
    f.write("time,gx,gy,gz\n")
    for i in range(3000):
        s = 0.01 * i
        f.write("2024-05-01 12:%02d:%06.3f,%.3f,%.3f,%.3f\n" % (s // 60, s % 60, random.gauss(0.5, 0.1), -0.3, 0.2))
EOF2
"$bin" allan --in "$t/iso.csv" --out "$t/a8" > "$t/a8.out" 2> "$t/a8.err" || fail "case 7: allan on date-time stamps: $(cat "$t/a8.err")"
grep -q "holds dates and times" "$t/a8.out" || fail "case 7: the date-time column is not said"
within "$(jq -r .sample_rate_hz "$t/a8/allan_fit.json" 2> /dev/null)" 100 1e-6 || fail "case 7: rate is not 100 Hz"
# 8. a ground truth whose header names the quaternion scalar last (q_x, q_y, q_z, q_w): joined as that
#    order (read as w x y z, the identity became a 180 deg turn about z, silently)
$py - "$t/imu0.csv" "$t/gt_xyzw.csv" <<'EOF2'
import sys
with open(sys.argv[1], "w") as f:
    f.write("#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n")
    for i in range(400):
        f.write("%d,0.001,0.002,0.003,0,0,9.81\n" % (1403636579000000000 + 5000000 * i))
with open(sys.argv[2], "w") as f:
    f.write("#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_x [], q_RS_y [], q_RS_z [], q_RS_w []\n")
    for i in range(250):
        f.write("%d,0,0,0,0,0,0,1\n" % (1403636579000000000 + 10000000 * i))
EOF2
"$bin" convert --in "$t/imu0.csv" --ref "$t/gt_xyzw.csv" --out "$t/gt_log.csv" > "$t/c8.out" 2>&1 || { cat "$t/c8.out"; fail "case 8: convert --ref"; }
qw=$(awk -F, '/^t,/ { for (i = 1; i <= NF; ++i) if ($i == "ref_qw") c = i; next } !/^#/ && c { print $c; exit }' "$t/gt_log.csv")
awk -v q="${qw:-0}" 'BEGIN { exit !(q > 0.999) }' || fail "case 8: ref_qw = $qw for an identity written x y z w"
grep -q "quaternion columns q x y z w" "$t/c8.out" || fail "case 8: the quaternion order read is not said"
# exact 5 ms ns steps are 200 Hz, not 200.0000000001819 (the round-off of differences of large times)
grep -q "^# sample_rate_hz: 200$" "$t/gt_log.csv" || fail "case 8: $(grep -m1 sample_rate_hz "$t/gt_log.csv")"
[[ $fails == 0 ]] || { echo "$fails check(s) failed"; exit 1; }
echo "foreign data: all cases right or refused loudly"
