#!/usr/bin/env bash
# A lock that comes late because the correction sigma settled at the lock level (stop-27 finding
# F27): the issue's own "10x noise, 5x instability" sensor on a car with --selfcal --tune auto
# settles at about 0.05 deg/s, dips under it at the last (short) update, and late_lock then said
# "record a longer log", which cannot help. Now steady_state_at_lock names the settled sigma, the
# wander between updates and the real fixes. On the outsider's generator (tests/estimator/navgen.py,
# written apart from twin/), 1200 s of F27's log (seed 221), without ref_q: with it, since stop 29,
# ref_q witnesses the car's straight runs as box dwells, which observe the shared vertical bias that
# kept the sigma at the lock level, and the same log locks at 99 s, ok (5.6 deg/h against 206 with
# the bias fixed; tests/cli/estimate_matrix.sh). Without ref_q the settling remains, and with it now
# vertical_unobserved, its cause.
# usage: estimate_steady_lock.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1; src=$2
# shellcheck source=lib/outsider_log.sh
source "$src/tests/cli/lib/outsider_log.sh"
nav="$py $src/tests/estimator/navgen.py"
$nav --out "$t/noisy.csv" --sensor noisy --bias 3 --scale 0.01 --misalign 0.5 --gsens 0.05 --motion car \
  --duration 1200 --temp --seed 221 --no-ref > /dev/null || fail "navgen"
"$bin" estimate --log "$t/noisy.csv" --out "$t/o" --selfcal --tune auto > "$t/out.txt" 2>&1
rc=$?
[ "$rc" = 0 ] || { cat "$t/out.txt"; fail "exit $rc, expected 0 (degraded)"; }
grep -q '"cause": "steady_state_at_lock", "severity": "degraded"' "$t/o/summary.json" ||
  { cat "$t/out.txt"; fail "no steady_state_at_lock finding"; }
if grep -q '"cause": "late_lock"' "$t/o/summary.json"; then fail "late_lock still given"; fi
grep -q "a longer log gives the same sigma" "$t/out.txt" || fail "the text does not say a longer log cannot help"
grep -q "attitude-start-sigma 0\.[0-9][0-9]" "$t/out.txt" || fail "no --attitude-start-sigma advice"
# the settled sigma of the text: at the lock level (0.9 of it at least, the finding's condition,
# and under 1.2 of it: the filter did lock), and the settling it claims, seen in estimate.csv's
# bias sigmas over the last 8 updates before the lock (each within 2 % of 4 updates earlier)
said=$(grep -o "settled at [0-9.]* deg/s" "$t/out.txt" | head -1 | grep -o "[0-9.]*[0-9]")
[ -n "$said" ] || { cat "$t/out.txt"; fail "no settled sigma in the text"; }
"$py" - "$t/o/estimate.csv" "$said" <<'PY' || fail "settled sigma $said against estimate.csv"
import sys, numpy as np
a = np.genfromtxt(sys.argv[1], delimiter=",", names=True)
said = float(sys.argv[2])
if not 0.045 <= said < 0.06:
    sys.exit(f"settled sigma {said} not at the lock level 0.05")
before = a[a["locked"] == 0][-8:]
for c in [f"sigma{i}_{x}" for i in (1, 2) for x in "xyz"]:
    s = before[c]
    if len(s) < 8 or np.max(np.abs(s[4:] - s[:4]) / s[4:]) > 0.02:
        sys.exit(f"{c} not settled over the last updates before the lock: {s}")
print(f"settled at {said} deg/s; bias sigmas settled within 2 % per cycle")
PY
echo "steady state at the lock level: said, with the real fixes"
