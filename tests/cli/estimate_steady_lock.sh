#!/usr/bin/env bash
# A lock that comes late because the correction sigma settled at the lock level (stop-27 finding
# F27): the issue's own "10x noise, 5x instability" sensor on a car with --selfcal --tune auto
# settles at about 0.05 deg/s, dips under it at the last (short) update, and late_lock then said
# "record a longer log", which cannot help. Now steady_state_at_lock names the settled sigma, the
# wander between updates, the closed-form steady state (docs/estimator.md section 6.5) and the real
# fixes. Then the lock's hysteresis: at a lock level on that steady state the `locked` flag
# alternated 0/1 at every update; now it changes once. Then the closed form against the filter's
# own sigma on a static log, at a q whose steady state is below the lock level and at one above it
# (lock_unreachable, known from the first updates), and a bias step whose gate re-lock is a real
# loss of the lock, still reported (lock_losses). On the outsider's generator
# (tests/estimator/navgen.py, written apart from twin/), 1200 s of F27's log (seed 221), without
# ref_q: with it, since stop 29, ref_q witnesses the car's straight runs as box dwells, which observe
# the shared vertical bias that kept the sigma at the lock level, and the same log locks at 99 s, ok
# (5.6 deg/h against 206 with the bias fixed; tests/cli/estimate_matrix.sh). Without ref_q the
# settling remains, and with it now vertical_unobserved, its cause.
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
grep -q "closed-form steady state of this q, T and R is 0\.0[0-9]* deg/s for the bias alone" "$t/out.txt" ||
  { cat "$t/out.txt"; fail "the text does not give the closed form for the bias alone"; }
grep -q "flipping more often does not lower b[12]_[xyz]'s sigma" "$t/out.txt" || fail "the text still advises flipping more often"

# the same log cut before its last (short) update never locks: never_locked says the sigma had
# settled, so a longer log cannot help (it advised a longer log before)
awk -F, '/^#/ || /^t,/ {print; next} $1 < 1170 {print}' "$t/noisy.csv" > "$t/cut.csv"
"$bin" estimate --log "$t/cut.csv" --out "$t/c" --selfcal --tune auto > "$t/c.txt" 2>&1
grep -q '"cause": "never_locked"' "$t/c/summary.json" || { cat "$t/c.txt"; fail "the cut log locked"; }
grep -q "never locked: .*where it had settled .*so a longer log gives the same sigma" "$t/c.txt" ||
  { cat "$t/c.txt"; fail "never_locked does not say the sigma settled"; }

# the hysteresis: a lock level on the settled sigma (0.054) made `locked` flicker at every update
"$bin" estimate --log "$t/noisy.csv" --out "$t/h" --selfcal --tune auto --attitude-start-sigma 0.054 --corrected \
  > "$t/h.txt" 2>&1 || { cat "$t/h.txt"; fail "hysteresis run: exit $?"; }
"$py" - "$t/h" <<'PY' || fail "the locked flag flickers"
import sys, json, numpy as np
d = sys.argv[1]
losses = len(json.load(open(d + "/summary.json"))["lock_losses"])
est = np.genfromtxt(d + "/estimate.csv", delimiter=",", names=True)
cor = np.loadtxt(d + "/corrected.csv", delimiter=",", skiprows=1, usecols=[11])
for name, col in (("estimate.csv", est["locked"]), ("corrected.csv", cor)):
    changes = int(np.sum(np.abs(np.diff(col))))
    if col.max() != 1 or changes > 1 + 2 * losses:
        sys.exit(f"{name}: locked changes {changes} times with {losses} lock losses")
print(f"locked changes once; {losses} lock losses")
PY

# the closed form against the filter's own sigma: a static box, the noise and q given
$nav --out "$t/static.csv" --sensor noisy --bias 3 --motion static --duration 600 --seed 229 > /dev/null ||
  fail "navgen static"
for q in 3e-5 1e-4; do
  printf 'noise_density_dps_rthz: 0.05\nq_override_dps2_per_s: %s\n' "$q" > "$t/q.yaml"
  "$bin" estimate --log "$t/static.csv" --out "$t/s$q" --config "$t/q.yaml" > "$t/s$q.txt" 2>&1
  echo $? > "$t/s$q.rc"
  "$py" - "$t/s$q" "$(cat "$t/s$q.rc")" <<'PY' || { cat "$t/s$q.txt"; fail "q $q: closed form against the filter"; }
import sys, json, numpy as np
d, rc = sys.argv[1], int(sys.argv[2])
h = json.load(open(d + "/summary.json"))["health"]
ss = h["steady_state"]
a = np.genfromtxt(d + "/estimate.csv", delimiter=",", names=True)
sig = np.array([a[f"sigma{i}_{x}"] for i in (1, 2) for x in "xyz"]).T[-5:-1]  # the last cycle (not the log's end)
hi, lo = sig.max(), sig.min()
if abs(ss["sigma_dps"] - hi) > 0.02 * hi or abs(ss["sigma_low_dps"] - lo) > 0.05 * lo:
    sys.exit(f"closed form {ss['sigma_dps']:.5f}/{ss['sigma_low_dps']:.5f} against the filter's {hi:.5f}/{lo:.5f}")
causes = [f["cause"] for f in h["findings"]]
unreachable = ss["sigma_dps"] >= 0.05
if unreachable != ("lock_unreachable" in causes) or unreachable != ss["lock_unreachable"]:
    sys.exit(f"lock_unreachable {ss['lock_unreachable']}, findings {causes}, closed form {ss['sigma_dps']}")
if unreachable and (rc != 1 or h["locked"] or not ss["interval_for_lock_s"] < ss["interval_s"]):
    sys.exit(f"unreachable: exit {rc}, locked {h['locked']}, interval {ss['interval_for_lock_s']} of {ss['interval_s']}")
if not unreachable and (rc != 0 or not h["locked"]):
    sys.exit(f"reachable: exit {rc}, locked {h['locked']}")
print(f"closed form {ss['sigma_dps']:.5f} against the filter's {hi:.5f}; unreachable {unreachable}")
PY
done
grep -q "the lock level 0.05 deg/s cannot be reached" "$t/s1e-4.txt" || fail "no lock_unreachable text"

# a real loss is still one: a 1 deg/s bias step at 300 s makes the gate re-lock; the lock is lost
# there, reported in lock_losses, and comes back
$nav --out "$t/step.csv" --sensor noisy --bias 3 --motion static --duration 600 --seed 229 --step 300:1:0:1.0 \
  > /dev/null || fail "navgen step"
printf 'noise_density_dps_rthz: 0.05\nq_override_dps2_per_s: 3e-5\n' > "$t/q.yaml"
"$bin" estimate --log "$t/step.csv" --out "$t/st" --config "$t/q.yaml" > "$t/st.txt" 2>&1 || { cat "$t/st.txt"; fail "step run"; }
"$py" - "$t/st" <<'PY' || fail "the bias step's loss of lock"
import sys, json, numpy as np
d = sys.argv[1]
s = json.load(open(d + "/summary.json"))
losses, relocks = s["lock_losses"], s["relocks"]
if len(losses) != 1 or not losses[0]["relock"] or len(relocks) != 1 or losses[0]["t_s"] != relocks[0]["t_s"]:
    sys.exit(f"lock_losses {losses}, relocks {relocks}")
if not (losses[0]["locked_again_t_s"] or 0) > losses[0]["t_s"] or s["health"]["lock_losses"] != 1:
    sys.exit(f"not locked again after the loss: {losses}")
locked = np.genfromtxt(d + "/estimate.csv", delimiter=",", names=True)["locked"]
if int(np.sum(np.abs(np.diff(locked)))) != 3:
    sys.exit(f"locked changes {int(np.sum(np.abs(np.diff(locked))))} times, expected 3 (lock, loss, lock)")
print(f"bias step: lost at {losses[0]['t_s']} s (re-lock), locked again at {losses[0]['locked_again_t_s']} s")
PY
grep -q "lock_unreachable above" "$t/s1e-4.txt" || fail "never_locked does not point to lock_unreachable"
echo "steady state at the lock level: said, with the closed form; the lock holds through it"
