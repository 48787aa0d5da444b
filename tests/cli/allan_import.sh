#!/usr/bin/env bash
# driftless allan --in on other people's layouts: EuRoC/TUM-VI, a blank-separated "time then six
# columns" file, a NumPy array (streamed), explicit taus, three deviations, the noise files with
# their units and inflation, the round trip, plots, gaps, and bad files with file:line.
set -euo pipefail
bin=$1; src=$2
real=$src/../shared/realdata/mpu6050-sunsided/unmoved-with-x-pointing-forward-10min/mpu6050.csv
[[ -f $real ]] || { echo "no real data at $real: skipped"; exit 0; }
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
n_of() { jq -r ".channels[\"$2\"].N.value" "$1/allan_fit.json"; }
same() { awk -v a="$1" -v b="$2" -v tol="$3" 'BEGIN { d = a - b; if (d < 0) d = -d; exit !(d <= tol * (a < 0 ? -a : a)) }'; }

"$bin" allan --in "$real" --columns gyro_x,gyro_y,gyro_z --out "$t/ref" > /dev/null

# EuRoC imu0/data.csv: ns stamps, rad/s, m/s^2 (the same samples)
awk -F, 'NR == 1 { print "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]"; next }
  { printf "%.0f,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", 1403636579758555392 + $1 * 1e9, $5 / 57.295779513082320876798,
    $6 / 57.295779513082320876798, $7 / 57.295779513082320876798, $2 * 9.80665, $3 * 9.80665, $4 * 9.80665 }' "$real" > "$t/data.csv"
"$bin" allan --in "$t/data.csv" --out "$t/euroc" --kalibr --openvins --vins-mono > "$t/euroc.txt"
grep -q "format euroc" "$t/euroc.txt" || fail "EuRoC not detected"
same "$(n_of "$t/euroc" 'w_RS_S_x [rad s^-1]')" "$(n_of "$t/ref" gyro_x)" 1e-6 || fail "EuRoC N differs from the text run"
grep -q "^accelerometer_noise_density: .* # m/s^2/sqrt(Hz)" "$t/euroc/imu.yaml" || fail "Kalibr accel line"
grep -q "^  gyroscope_random_walk: .* # rad/s^2/sqrt(Hz)" "$t/euroc/kalibr_imu_chain.yaml" || fail "OpenVINS file"
grep -q "^gyr_n: .* # rad/s/sqrt(Hz)" "$t/euroc/vins_mono_imu.yaml" || fail "VINS-Mono file"
[[ -f $t/euroc/imu_x.yaml && -f $t/euroc/imu_z.yaml ]] || fail "per-axis Kalibr files"
# --inflate multiplies the exported densities
"$bin" allan --in "$t/data.csv" --out "$t/euroc2" --kalibr --inflate 2 > /dev/null
a=$(awk '/^gyroscope_noise_density/ { print $2 }' "$t/euroc/imu.yaml"); b=$(awk '/^gyroscope_noise_density/ { print $2 }' "$t/euroc2/imu.yaml")
same "$b" "$(awk -v a="$a" 'BEGIN { print 2 * a }')" 1e-6 || fail "inflation"
grep -q "inflation factor 2" "$t/euroc2/imu.yaml" || fail "inflation not stated"

# a blank-separated "time then six columns" file, no header, SI units
awk -F, 'NR > 1 { printf "%.6f %.9g %.9g %.9g %.9g %.9g %.9g\n", $1, $5 / 57.295779513082320876798, $6 / 57.295779513082320876798,
  $7 / 57.295779513082320876798, $2 * 9.80665, $3 * 9.80665, $4 * 9.80665 }' "$real" > "$t/imu.txt"
"$bin" allan --in "$t/imu.txt" --out "$t/txt" > "$t/txt.txt"
grep -q "no header" "$t/txt.txt" || fail "positional columns not said"
same "$(n_of "$t/txt" col2)" "$(n_of "$t/ref" gyro_x)" 1e-4 || fail "blank-separated N differs"

# a NumPy array (t, gx, gy, gz as float64): streamed in bounded memory, same N
python3 - "$real" "$t/imu.npy" <<'PY'
import struct, sys
rows = [l.split(',') for l in open(sys.argv[1]).read().split('\n')[1:] if l]
hdr = "{'descr': '<f8', 'fortran_order': False, 'shape': (%d, 4), }" % len(rows)
hdr += ' ' * ((64 - (10 + len(hdr) + 1) % 64) % 64) + '\n'
with open(sys.argv[2], 'wb') as f:
    f.write(b'\x93NUMPY\x01\x00' + struct.pack('<H', len(hdr)) + hdr.encode())
    for r in rows: f.write(struct.pack('<4d', float(r[0]), float(r[4]), float(r[5]), float(r[6])))
PY
"$bin" allan --in "$t/imu.npy" --time-column 1 --out "$t/npy" > "$t/npy.txt"
jq -e '.format == "npy"' "$t/npy/allan_fit.json" > /dev/null || fail "npy"
same "$(n_of "$t/npy" col2)" "$(n_of "$t/ref" gyro_x)" 1e-6 || fail "streamed N differs from the in-memory one"
# and read into memory (--exact): the same doubles as the log's, so the same N
"$bin" allan --in "$t/imu.npy" --time-column 1 --exact --out "$t/npyx" > /dev/null
same "$(n_of "$t/npyx" col2)" "$(n_of "$t/ref" gyro_x)" 1e-12 || fail "npy read into memory: N differs from the log's"

# explicit taus, three deviations, the round trip, plots
"$bin" allan --in "$real" --columns gyro_x --taus 1,10,100,1000,3000 --dev adev,mdev,hdev --validate 3 --plot \
  --datasheet N=0.005 --out "$t/x" > "$t/x.txt"
[[ $(tail -n +2 "$t/x/allan.csv" | wc -l) -eq 3 ]] || fail "explicit taus: 1, 10, 100 s fit a 655 s record"
[[ -f $t/x/mdev.csv && -f $t/x/hdev.csv ]] || fail "mdev/hdev tables"
[[ $(grep -c ',mdev,' "$t/x/allan_points.csv") -eq 3 ]] || fail "mdev points"
jq -e '.channels.gyro_x.validation.records == 3 and (.channels.gyro_x.validation.verdict | length > 10)' "$t/x/allan_fit.json" > /dev/null \
  || fail "round trip"
grep -q "round trip" "$t/x.txt" || fail "round-trip verdict not printed"
if command -v gnuplot > /dev/null; then [[ -s $t/x/allan_gyro_x.png ]] || fail "channel plot"; fi
# the overview's axis names the units the deviations are in, and B_min's text stays inside the
# frame: its minimum lies in the upper half of the taus, so the text is set to its left
grep -q "set ylabel 'adev \[deg/s\]'" "$t/x/allan.gp" || fail "overview y axis: $(grep ylabel "$t/x/allan.gp")"
grep -Eq "set label 1 at [0-9.e+-]+,[0-9.e+-]+ right point" "$t/x/allan_gyro_x.gp" || fail "B_min label: $(grep 'label 1' "$t/x/allan_gyro_x.gp")"

# regular stamps with a gap: gap-aware by default, joined with --gaps ignore
awk 'BEGIN { print "t,gx"; srand(3); for (i = 0; i < 6000; ++i) { if (i == 3000) i += 50; printf "%.3f,%.6f\n", i / 100, rand() - 0.5 } }' > "$t/gap.csv"
"$bin" allan --in "$t/gap.csv" --out "$t/g" > "$t/g.txt"
grep -q "gap-aware" "$t/g.txt" || fail "gap policy not said"
grep -q "50 samples missing" "$t/g.txt" || fail "gap size"
"$bin" allan --in "$t/gap.csv" --gaps ignore --out "$t/g2" > "$t/g2.txt"
grep -q "contiguous across the gaps" "$t/g2.txt" || fail "--gaps ignore not said"

# bad files: the file and line, and a non-zero exit
printf 't,gx\n0,1\n0.01,2\n0.02,3\n0.03,4\n0.04,5\n0.05,x\n' > "$t/bad.csv"
if "$bin" allan --in "$t/bad.csv" --out "$t/bad" > /dev/null 2> "$t/bad.err"; then fail "bad file accepted"; fi
grep -q "bad.csv:7: column 'gx' (2): expected a number, got 'x'" "$t/bad.err" || { cat "$t/bad.err"; fail "bad-file message"; }
echo "ok"
