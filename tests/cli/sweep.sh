#!/usr/bin/env bash
# driftless sweep end to end: a small grid, the table and plots, byte-identical tables for 1 and
# 2 threads, a failing run reported (exit 1) with the rest of the table intact, bad files refused.
set -euo pipefail
bin=$1; src=$2
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

cat > "$t/s.yaml" <<YAML
name: cli_test
runner: fast
scenario: default
duration_s: 240
monte_carlo: 2
seed: 3
fixed:
  estimator.initial_sigma_dps: 25
  flip_schedule.standstill_s: 10
grid:
  flip_angle_deg: {set: flip_schedule.flip_angle_deg, values: [30, 90]}
plots:
  - {x: flip_angle_deg, y: [bias_err_rms_dph]}
YAML
"$bin" sweep --config "$t/s.yaml" --out "$t/a" --jobs 1 > "$t/a.txt" || fail "sweep failed: $(cat "$t/a.txt")"
"$bin" sweep --config "$t/s.yaml" --out "$t/b" --jobs 2 --no-plots > /dev/null || fail "sweep -j2 failed"
for f in runs.csv summary.csv; do
  [[ -s $t/a/$f ]] || fail "no $f"
  cmp -s "$t/a/$f" "$t/b/$f" || fail "$f differs between 1 and 2 threads"
done
[[ $(grep -c ',ok,' "$t/a/runs.csv") == 4 ]] || fail "expected 4 ok runs: $(cat "$t/a/runs.csv")"
head -5 "$t/a/runs.csv" | grep -q '^run,point,mc,seed,flip_angle_deg,status,bias_err_rms_dph' || fail "runs.csv header"
[[ -s $t/a/plot_bias_err_rms_dph_vs_flip_angle_deg.gp ]] || fail "no gnuplot script"
if command -v gnuplot > /dev/null; then
  [[ -s $t/a/plot_bias_err_rms_dph_vs_flip_angle_deg.png ]] || fail "gnuplot did not draw the png"
fi
grep -q "speed-up" "$t/a.txt" || fail "no timing line"

# a run that fails (a negative noise density) is reported and the sweep exits 1; others are kept
sed -e 's/  flip_angle_deg: {set: flip_schedule.flip_angle_deg, values: \[30, 90\]}/  nd: {set: model.sensor1.effects.white_noise.density_dps_rthz, vector3: true, values: [0.005, -1]}/' \
    -e '/plots:/,$d' "$t/s.yaml" > "$t/bad.yaml"
if "$bin" sweep --config "$t/bad.yaml" --out "$t/c" --jobs 2 > /dev/null 2> "$t/c.err"; then
  fail "a failing run must make the sweep exit non-zero"
fi
grep -q "run 2 failed" "$t/c.err" || fail "failed run not reported: $(cat "$t/c.err")"
[[ $(grep -c ',ok,' "$t/c/runs.csv") == 2 ]] || fail "the good runs must stay in the table"
[[ $(grep -c ',failed: ' "$t/c/runs.csv") == 2 ]] || fail "the failed runs must be marked"

# bad sweep files: one line naming file and key
printf 'name: x\nbogus: 1\n' > "$t/u.yaml"
if "$bin" sweep --config "$t/u.yaml" --out "$t/d" 2> "$t/u.err"; then fail "unknown key accepted"; fi
grep -q "u.yaml:2: bogus: unknown key" "$t/u.err" || fail "message: $(cat "$t/u.err")"

# every shipped sweep file names a known runner (tests/twin/test_sweep_files.cpp parses them)
for f in "$src"/models/sweeps/*.yaml; do
  grep -Eq '^runner: (fast|twin|fdi)' "$f" || fail "$f: no runner"
done
echo "ok"
