#!/usr/bin/env bash
# driftless calibrate end to end on the twin's pan/tilt rig (models/scenarios/calibration.yaml with
# 12 s segments): the recovered coefficients against the planted ones within tolerances derived
# from the gyro noise; the saved rig log refitted through --log --plan gives the same M; the model
# prior; and bad input (a missing orientation, a malformed plan or calibration block, a plan that
# does not match the log, a saturating rate) gives one clear error line.
# usage: bash calibrate.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1; src=$2
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

expect_error() {  # name pattern command...: exit 1, one line on stderr, holding the pattern
  local name=$1 pattern=$2; shift 2
  "$@" > "$t/$name.out" 2> "$t/$name.err"
  local rc=$?
  [[ $rc -eq 1 ]] || { cat "$t/$name.err"; fail "$name: exit code $rc, expected 1"; }
  grep -qF -- "$pattern" "$t/$name.err" || { cat "$t/$name.err"; fail "$name: message lacks '$pattern'"; }
  [[ $(wc -l < "$t/$name.err") -eq 1 ]] || { cat "$t/$name.err"; fail "$name: expected one error line"; }
  echo "$name: $(cat "$t/$name.err")"
}

scenario() {  # segment_s [orientations] -> the shipped calibration scenario, shortened
  sed -e "s/^  segment_s: 60 /  segment_s: $1 /" \
      -e "s/^  orientations: \[XY, YZ, XZ\]/  orientations: ${2:-[XY, YZ, XZ]}/" \
      "$src/models/scenarios/calibration.yaml"
}

# GIVEN the shipped rig with planted errors, 12 s per segment
scenario 12 > "$t/cal.yaml"
grep -q "^  segment_s: 12 " "$t/cal.yaml" || fail "could not shorten the scenario"
# WHEN calibrate runs it
"$bin" calibrate --scenario "$t/cal.yaml" --out "$t/calib.yaml" --prior-out "$t/prior.yaml" \
  --save-log "$t/rig.csv" --save-plan "$t/plan.yaml" > "$t/run.txt" 2> "$t/run.err" \
  || { cat "$t/run.err"; fail "calibrate --scenario"; }
cat "$t/run.txt"

# THEN every coefficient of every M is within 6 sigma of the twin's true M (realised sensor
# calibration + MuJoCo rest angles), sigma being the fit's own, from the gyro noise
awk '/max \|dM\|\/sigma/ { v = $NF } END { if (v == "" || v + 0 > 6.0) exit 1 }' "$t/run.txt" \
  || fail "fit not within 6 sigma of the twin's true M: $(grep 'max |dM|' "$t/run.txt")"

# AND the physical errors against the values planted in calibration.yaml. Noise-derived
# tolerance: one coefficient of M^-1 has sigma = s / (rate sqrt(N)), s = 0.005 deg/s/rtHz * sqrt(100 Hz)
# = 0.05 deg/s per sample, rate 50 deg/s, N plateau samples of its segment (calib.yaml samples_used);
# a scale error averages the two stops (/sqrt 2). Tolerance 5 sigma (plus 1e-4 % / deg rounding).
n_min=$(grep -o 'samples_used: [0-9]*' "$t/calib.yaml" | awk '{ print $2 }' | sort -n | head -1)
[[ -n $n_min && $n_min -gt 500 ]] || fail "samples_used missing or too small: '$n_min'"
sig=$(awk -v n="$n_min" 'BEGIN { printf "%.10g", 0.05 / (50 * sqrt(n)) }')
# errors: blocks in order sensor1, sensor2; values as written (flow sequences)
vals() {  # key sensor -> the values of key in sensorN's errors block, one per line
  awk -v key="$1" -v want="sensor$2" '
    /^sensor[12]:/ { cur = $1; sub(":", "", cur) }
    cur == want && $1 == key":" { line = $0; sub(/^[^:]*: */, "", line); gsub(/[][,]/, " ", line); print line }' \
    "$t/calib.yaml" | tr -s ' ' '\n' | grep -v '^$'
}
# planted: C = (I + K) diag(k) R_mount, so |row j of M^-1| - 1 = |row j of (I + K) diag(k)| - 1 and
# the angle between rows j, k of M^-1 is that of (I + K) diag(k) (T and R_mount are rotations)
check_planted() {  # sensor k_x k_y k_z K(9, percent, row-major)
  local s=$1; shift
  vals scale_error_pct "$s" > "$t/scale$s"
  vals nonorthogonality_deg "$s" > "$t/nonorth$s"
  [[ $(wc -l < "$t/scale$s") -eq 3 && $(wc -l < "$t/nonorth$s") -eq 3 ]] || fail "sensor $s: errors block not found"
  awk -v sig="$sig" -v s="$s" -v args="$*" -v scalefile="$t/scale$s" -v nofile="$t/nonorth$s" '
    BEGIN {
      split(args, a, " ")
      for (i = 1; i <= 3; ++i) k[i] = a[i]
      for (i = 1; i <= 3; ++i) for (j = 1; j <= 3; ++j) P[i, j] = ((i == j) + a[3 + 3 * (i - 1) + j] / 100) * k[j]
      for (i = 1; i <= 3; ++i) { getline v < scalefile; got_s[i] = v; n2 = 0
        for (j = 1; j <= 3; ++j) n2 += P[i, j]^2; want_s[i] = 100 * (sqrt(n2) - 1) }
      pi = atan2(0, -1); pairs[1] = "1 2"; pairs[2] = "2 3"; pairs[3] = "1 3"
      for (p = 1; p <= 3; ++p) { getline v < nofile; split(pairs[p], ij, " "); d = 0; ni = 0; nj = 0
        for (c = 1; c <= 3; ++c) { d += P[ij[1], c] * P[ij[2], c]; ni += P[ij[1], c]^2; nj += P[ij[2], c]^2 }
        want_n[p] = 90 - 180 / pi * atan2(sqrt(ni * nj - d * d), d); got_n[p] = v }
      tol_s = 5 * 100 * sig / sqrt(2) + 1e-4; tol_n = 5 * sqrt(2) * sig * 180 / pi + 1e-4
      bad = 0
      for (i = 1; i <= 3; ++i) {
        printf "sensor %s scale_error_pct[%d]: %.5f planted %.5f tol %.5f\n", s, i, got_s[i], want_s[i], tol_s
        if ((got_s[i] - want_s[i])^2 > tol_s^2) bad = 1
        printf "sensor %s nonorthogonality_deg[%d]: %.5f planted %.5f tol %.5f\n", s, i, got_n[i], want_n[i], tol_n
        if ((got_n[i] - want_n[i])^2 > tol_n^2) bad = 1
      }
      exit bad
    }' || fail "sensor $s: recovered errors outside the noise tolerance of the planted values"
}
# calibration.yaml: sensor1 scale [2, -2, 2] %, sensor2 [-2, -2, -2] %, cross-coupling matrices
check_planted 1 1.02 0.98 1.02  0 0.5 -0.5  0.5 0 0.5  -0.5 0.5 0
check_planted 2 0.98 0.98 0.98  0 0.5 -0.5  -0.5 0 0.5  -0.5 0.5 0
# the end-stop travel: planted +2 deg (platform 1) and -2 deg (platform 2). The noise sigma of
# a travel angle is ~0.002 deg, but the twin's soft end stops give way by ~0.01 deg under the
# motor's press (physics, not fit error: the 6-sigma check above uses the MuJoCo rest angles);
# against the planted value the issue's 0.05 deg holds
for s in 1 2; do
  want=$([[ $s -eq 1 ]] && echo 2 || echo -2)
  got=$(vals travel_error_deg "$s")
  awk -v g="$got" -v w="$want" 'BEGIN { exit !((g - w)^2 < 0.05^2) }' \
    || fail "sensor $s: travel error $got deg, planted $want deg (tolerance 0.05 deg)"
  echo "sensor $s travel_error_deg: $got planted $want tol 0.05"
done

# the model prior is a model-config file holding the calibrated errors
grep -q "^model:" "$t/prior.yaml" || fail "--prior-out: no model: block"
grep -q "scale_factor:" "$t/prior.yaml" && grep -q "stop1_error_deg:" "$t/prior.yaml" \
  || fail "--prior-out: scale_factor / stop errors missing"

# the saved rig log and plan, refitted through --log --plan, give the same errors to a small
# fraction of sigma (the log keeps t to 1 us and gyros to 7 digits, so a few samples at the
# plateau edges fall the other way)
"$bin" calibrate --log "$t/rig.csv" --plan "$t/plan.yaml" --out "$t/calib2.yaml" > /dev/null 2> "$t/refit.err" \
  || { cat "$t/refit.err"; fail "calibrate --log --plan on the saved rig log"; }
cp "$t/calib.yaml" "$t/calib1.yaml"
for s in 1 2; do
  for key in scale_error_pct nonorthogonality_deg; do
    cp "$t/calib1.yaml" "$t/calib.yaml"; vals "$key" "$s" > "$t/v1"
    cp "$t/calib2.yaml" "$t/calib.yaml"; vals "$key" "$s" > "$t/v2"
    tol=$(awk -v sig="$sig" -v k="$key" 'BEGIN { pi = atan2(0, -1); print 0.3 * (k == "scale_error_pct" ? 100 * sig : sig * 180 / pi) }')
    paste "$t/v1" "$t/v2" | awk -v tol="$tol" '{ if (($1 - $2)^2 > tol^2) bad = 1 } END { exit bad }' \
      || fail "sensor $s $key: --log --plan refit differs from --scenario by more than $tol: $(paste -d' ' "$t/v1" "$t/v2" | tr '\n' ' ')"
  done
done
cp "$t/calib1.yaml" "$t/calib.yaml"

# bad input: one clear line, exit 1
# - an orientation missing: the unobservable coefficients are named, and what to add
scenario 6 "[XY, YZ]" > "$t/missing.yaml"
expect_error missing "unobservable coefficient(s): the response to box y rate, M^-1[x,y], M^-1[y,y], M^-1[z,y]" \
  "$bin" calibrate --scenario "$t/missing.yaml" --out "$t/m.yaml"
grep -qF "add the XZ orientation" "$t/missing.err" || fail "missing: does not say which orientation to add"
# - a malformed plan: file:line and the key
sed -e '0,/rate_dps: 50/s//rate_dps: fast/' "$t/plan.yaml" > "$t/badplan.yaml"
line=$(grep -n "rate_dps: fast" "$t/badplan.yaml" | head -1 | cut -d: -f1)
expect_error badplan "badplan.yaml:$line" "$bin" calibrate --log "$t/rig.csv" --plan "$t/badplan.yaml" --out "$t/b.yaml"
grep -q "rate_dps" "$t/badplan.err" || fail "badplan: the key is not named"
# - a plan that does not match the log (every segment 5 s late)
awk '{ if (match($0, /t_start_s: [0-9.]+/)) { v = substr($0, RSTART + 11, RLENGTH - 11); sub(/t_start_s: [0-9.]+/, "t_start_s: " v + 5) }
       if (match($0, /t_end_s: [0-9.]+/)) { v = substr($0, RSTART + 9, RLENGTH - 9); sub(/t_end_s: [0-9.]+/, "t_end_s: " v + 5) }
       print }' "$t/plan.yaml" > "$t/late.yaml"
cmp -s "$t/plan.yaml" "$t/late.yaml" && fail "could not shift the plan"
expect_error late "plan does not match the log" "$bin" calibrate --log "$t/rig.csv" --plan "$t/late.yaml" --out "$t/l.yaml"
# - a malformed calibration block: an unknown key, with file:line
sed -e 's/^  remount_s: 3 /  remount_seconds: 3 /' "$t/cal.yaml" > "$t/badkey.yaml"
line=$(grep -n "remount_seconds" "$t/badkey.yaml" | cut -d: -f1)
expect_error badkey "badkey.yaml:$line" "$bin" calibrate --scenario "$t/badkey.yaml" --out "$t/k.yaml"
# - a table rate that saturates the gyro (0.8 x 250 deg/s allowed)
sed -e 's/^  rate_dps: 50 /  rate_dps: 240 /' -e 's/^  table_accel_dps2: 1000 /  table_accel_dps2: 5000 /' "$t/cal.yaml" > "$t/fast.yaml"
expect_error saturate "saturat" "$bin" calibrate --scenario "$t/fast.yaml" --out "$t/f.yaml"
echo "calibrate: ok"
