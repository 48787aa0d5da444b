#!/usr/bin/env bash
# mpirun -np 2 driftless sweep: the grid split over 2 ranks gathers to the same table as one
# process; a failing run on rank 1 is reported as rank 1's. Skips only when mpirun is absent or
# the program was built without MPI.
set -euo pipefail
bin=$1; src=$2
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
command -v mpirun > /dev/null || { echo "mpirun not found: MPI sweep test skipped"; exit 0; }
grep -q -- "--config" <<< "$("$bin" sweep --help)" || fail "no sweep command"
# Open MPI's runtime (libmpi and the MCA plugins it dlopen()s and unloads) leaves allocations at
# exit that LeakSanitizer cannot attribute; under a sanitizer build leak checks stay on for the
# single-process sweep above, which runs the same sweep code, and are off for the mpirun ranks.
mpi=(env "ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0" mpirun -np 2 --oversubscribe)
[[ $(id -u) == 0 ]] && mpi+=(--allow-run-as-root)
export OMPI_MCA_btl=self,vader OMPI_MCA_plm=isolated OMPI_MCA_rmaps_base_oversubscribe=1

cat > "$t/s.yaml" <<YAML
name: mpi_test
runner: fast
scenario: default
duration_s: 120
monte_carlo: 3
seed: 11
fixed:
  estimator.initial_sigma_dps: 25
  flip_schedule.standstill_s: 10
grid:
  flip_angle_deg: {set: flip_schedule.flip_angle_deg, values: [45, 90]}
YAML
"$bin" sweep --config "$t/s.yaml" --out "$t/one" --jobs 1 --no-plots > /dev/null || fail "single-process sweep"
"${mpi[@]}" "$bin" sweep --config "$t/s.yaml" --out "$t/mpi" --jobs 1 --no-plots > "$t/mpi.txt" 2>&1 ||
  fail "mpirun sweep failed: $(cat "$t/mpi.txt")"
grep -q "2 rank(s)" "$t/mpi.txt" || {
  grep -q "1 rank(s)" "$t/mpi.txt" && { echo "driftless built without MPI: MPI sweep test skipped"; exit 0; }
  fail "no rank count: $(cat "$t/mpi.txt")"; }
cmp -s "$t/one/runs.csv" "$t/mpi/runs.csv" || { diff "$t/one/runs.csv" "$t/mpi/runs.csv" | head; fail "runs.csv differs"; }
cmp -s "$t/one/summary.csv" "$t/mpi/summary.csv" || fail "summary.csv differs"

# runs 1, 3, 5 go to rank 1; make run 3 (point 1, mc 0) fail: a bad value at the second point
sed 's/values: \[45, 90\]}/values: [45, 90]}\n  nd: {set: model.sensor2.effects.white_noise.density_dps_rthz, vector3: true, values: [0.005, -1]}/' \
  "$t/s.yaml" > "$t/bad.yaml"
if "${mpi[@]}" "$bin" sweep --config "$t/bad.yaml" --out "$t/bad" --jobs 1 --no-plots > "$t/bad.txt" 2>&1; then
  fail "a failing run must make mpirun exit non-zero"
fi
grep -q "rank 1: run [0-9]* failed" "$t/bad.txt" || fail "rank 1's failure not reported: $(cat "$t/bad.txt")"
grep -q "rank 0: run [0-9]* failed" "$t/bad.txt" || fail "rank 0's failure not reported: $(cat "$t/bad.txt")"
[[ -s $t/bad/runs.csv ]] || fail "the table must still be written"
echo "ok"
