#!/usr/bin/env bash
# estimate --corrected --smooth (docs/estimator.md section 6.3): corrected.csv from the fixed-interval
# smoother has the same rows as the filter's, marked smoothed = 1, and a correction without steps
# between updates; --smooth without --corrected is refused.
# usage: estimate_smooth.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# GIVEN 10 minutes of the default scenario (calibrated MPU6050s: the plain filter keeps its lock; the
# uncalibrated pan/tilt log loses it for good, which is a failed verdict since stop 27)
"$bin" simulate --duration 600 --seed 3 --out "$t/sim" > /dev/null 2>&1 || fail "simulate"
# WHEN it is estimated with and without --smooth
"$bin" estimate --log "$t/sim/log.csv" --out "$t/f" --corrected > /dev/null 2>&1 || fail "estimate --corrected: exit $?"
"$bin" estimate --log "$t/sim/log.csv" --out "$t/s" --corrected --smooth > "$t/s.out" 2>&1 || fail "estimate --smooth: exit $?: $(cat "$t/s.out")"
# THEN the smoothed file has the filter's rows plus the smoothed column, every row 1, and its
# correction (log gyro1 - y1c) changes by less than 1e-3 deg/s from row to row after the lock,
# where the filter's steps by more than 0.02 deg/s at updates
python3 - "$t/sim/log.csv" "$t/f/corrected.csv" "$t/s/corrected.csv" <<'PY' || fail "smoothed corrected.csv"
import csv, sys
def rows(p):
    r = csv.reader(l for l in open(p) if not l.startswith('#'))
    h = next(r)
    return h, list(r)
hl, log = rows(sys.argv[1]); hf, filt = rows(sys.argv[2]); hs, smo = rows(sys.argv[3])
assert hs == hf + ["smoothed"], hs
assert len(smo) == len(filt) == len(log), (len(smo), len(filt), len(log))
assert all(r[-1] == "1" for r in smo), "a row not marked smoothed"
g = [hl.index(c) for c in ("gyro1_x", "gyro1_y", "gyro1_z")]
def steps(h, rs):
    y = [h.index(c) for c in ("y1c_x", "y1c_y", "y1c_z")]
    lock = next(i for i, r in enumerate(filt) if r[hf.index("locked")] == "1")
    corr = [[float(l[gi]) - float(r[yi]) for gi, yi in zip(g, y)] for l, r in zip(log, rs)]
    return max(max(abs(a[j] - b[j]) for j in range(3)) for a, b in zip(corr[lock:], corr[lock + 1:]))
sf, ss = steps(hf, filt), steps(hs, smo)
print(f"largest row-to-row change of the correction after the lock: filter {sf:.4g}, smoothed {ss:.4g} deg/s")
sys.exit(0 if ss < 1e-3 and sf > 0.02 else 1)
PY
# AND summary.json says which outputs are smoothed: true with --smooth, null without
grep -q '"smoothed": true' "$t/s/summary.json" || fail "summary.json of --smooth lacks \"smoothed\": true"
grep -q '"smoothed": null' "$t/f/summary.json" || fail "summary.json without --smooth lacks \"smoothed\": null"
# AND --smooth alone is refused with the reason
"$bin" estimate --log "$t/sim/log.csv" --out "$t/x" --smooth > /dev/null 2> "$t/x.err"
[[ $? -ne 0 ]] && grep -q -- "--smooth requires --corrected" "$t/x.err" || fail "--smooth without --corrected accepted: $(cat "$t/x.err")"
echo "ok"
