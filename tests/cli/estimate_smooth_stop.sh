#!/usr/bin/env bash
# A stop during --smooth's second pass (docs/estimator.md section 6.3): SIGINT / SIGTERM ends the
# pass at the next row; corrected.csv stays a valid file holding the smoothed rows written so far
# (the same bytes as a whole run's first rows); summary.json says "smoothed": false, "complete":
# false and stopped_at_t_s at the last row written; exit 130 / 143. Deterministic on any load: the
# program, told by DRIFTLESS_TEST_SMOOTH_HOLD, holds still after its 100th smoothed row and says so
# by creating that file; the signal is sent then.
# usage: estimate_smooth_stop.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1
t=$(mktemp -d)
pid=
cleanup() { [[ -n $pid ]] && kill -9 "$pid" 2>/dev/null; rm -rf "$t"; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; exit 1; }

# GIVEN 10 minutes of the default scenario (as estimate_smooth.sh: the plain filter keeps its lock,
# so the whole run exits 0) and its whole smoothed estimate
"$bin" simulate --duration 600 --seed 3 --out "$t/sim" > /dev/null 2>&1 || fail "simulate"
"$bin" estimate --log "$t/sim/log.csv" --out "$t/full" --corrected --smooth > /dev/null 2>&1 || fail "estimate --smooth: exit $?"
for sig in INT TERM; do
  want=$([[ $sig == INT ]] && echo 130 || echo 143)
  # WHEN the second pass has written 100 rows and the signal comes
  DRIFTLESS_TEST_SMOOTH_HOLD="$t/hold_$sig" "$bin" estimate --log "$t/sim/log.csv" --out "$t/s_$sig" --corrected \
    --smooth > "$t/s_$sig.out" 2> "$t/s_$sig.err" &
  pid=$!
  for _ in $(seq 3000); do [[ -e $t/hold_$sig ]] && break; kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
  [[ -e $t/hold_$sig ]] || fail "SIG$sig: the second pass never reached its 100th row: $(cat "$t/s_$sig.err")"
  kill -"$sig" "$pid"
  wait "$pid"
  rc=$?
  pid=
  # THEN it exits 130 / 143
  [[ $rc -eq $want ]] || fail "SIG$sig: exit $rc, want $want: $(cat "$t/s_$sig.err")"
  # AND corrected.csv holds exactly those 100 smoothed rows, byte for byte the whole run's first 100,
  # and summary.json says the outputs are not smoothed to the end and where they stop
  /usr/bin/python3 - "$t/full/corrected.csv" "$t/s_$sig/corrected.csv" "$t/s_$sig/summary.json" <<'PY' || fail "SIG$sig: outputs after the stop"
import json, sys
def rows(p):
    lines = [l for l in open(p) if not l.startswith('#')]
    return lines[0], lines[1:]
hf, full = rows(sys.argv[1]); hs, stopped = rows(sys.argv[2])
s = json.load(open(sys.argv[3]))
assert hs == hf, (hs, hf)
assert len(stopped) == 100, f"{len(stopped)} rows after the stop, want 100 (the row the signal came in ends the pass)"
assert stopped == full[:100], "the rows differ from the whole run's first 100"
assert all(r.rstrip("\n").split(",")[-1] == "1" for r in stopped), "a row not marked smoothed"
assert s["smoothed"] is False and s["complete"] is False, (s["smoothed"], s["complete"])
t_last = float(stopped[-1].split(",")[0])
assert abs(s["stopped_at_t_s"] - t_last) < 1e-9, (s["stopped_at_t_s"], t_last)
print(f"stopped after 100 smoothed rows at t = {t_last} s; of {len(full)}")
PY
done
echo "ok"
