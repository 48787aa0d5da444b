#!/usr/bin/env bash
# The demo checks itself: on a run too short for the filter to lock, `driftless demo` must exit
# non-zero and say plainly which outputs do not hold what they claim and why; a figure that
# cannot be drawn is not written (not even an earlier run's file survives).
# usage: demo_checks.sh <path-to-driftless> <source-dir>
set -euo pipefail
bin=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# GIVEN an earlier run's Fig. 9 in the output folder (a stale file that would mislead)
mkdir -p "$work/demo/estimate"
echo "stale" > "$work/demo/estimate/fig9_attitude.png"
# WHEN the demo runs 60 s (two flips: the filter cannot lock)
set +e
"$bin" demo --duration 60 --no-video --out "$work/demo" > "$work/out.txt" 2> "$work/err.txt"
rc=$?
set -e
# THEN it exits 1 and names what failed and why
[ "$rc" -eq 1 ] || fail "demo --duration 60 exited $rc, expected 1: $(cat "$work/out.txt" "$work/err.txt")"
grep -q "outputs do not hold what they claim" "$work/err.txt" || fail "no summary line on stderr: $(cat "$work/err.txt")"
grep -qE "FAIL .*summary.json: the DriftLess filter locked on.*never locked" "$work/out.txt" ||
  fail "the lock failure is not named: $(cat "$work/out.txt")"
grep -qE "FAIL .*fig9_attitude.png.*not drawn: the filter never locked on" "$work/out.txt" ||
  fail "the missing Fig. 9 is not explained: $(cat "$work/out.txt")"
grep -qE "FAIL .*fig5_allan.png.*not drawn" "$work/out.txt" || fail "the missing Fig. 5 is not explained"
grep -qE "^ +ok +.*log.csv" "$work/out.txt" || fail "the log check should pass: $(cat "$work/out.txt")"
if grep -q "Look at:" "$work/out.txt"; then fail "a failed demo still lists outputs to look at"; fi
# AND the figures that could not be drawn are gone, the one that could is there
[ ! -e "$work/demo/estimate/fig9_attitude.png" ] || fail "a stale fig9_attitude.png survived"
[ ! -e "$work/demo/estimate/fig5_allan.png" ] || fail "fig5_allan.png was written without lock"
[ -s "$work/demo/estimate/fig4_bias.png" ] || fail "fig4_bias.png missing"
# AND Fig. 4's truth lines and 'estimate - truth' panels read the columns estimate.csv names
# true_bias* and b*: each column number its gnuplot script uses is looked up in the file's header
# (since estimate.csv gained 'locked', numbers fixed in the code drew the lock flag as a truth)
python3 - "$work/demo/estimate/estimate.csv" "$work/demo/estimate/fig4_bias.gp" <<'PY' || fail "fig4_bias.gp reads the wrong columns"
import re, sys
header = open(sys.argv[1]).readline().strip().split(",")
gp = open(sys.argv[2]).read()
name = lambda c: header[int(c) - 1]
truth = re.findall(r"using 1:(\d+) with linespoints dt 2", gp)
diffs = re.findall(r"using 1:\(\$(\d+)-\$(\d+)\)", gp)
assert len(truth) == 6 and len(diffs) == 6, (truth, diffs)
for c in truth: assert name(c).startswith("true_bias"), name(c)
for b, t in diffs: assert name(t) == "true_" + name(b).replace("b", "bias", 1), (name(b), name(t))
PY
grep -q '"name": "fig9_attitude", "written": false, "reason": "the filter never locked on' \
  "$work/demo/estimate/summary.json" || fail "summary.json does not say why Fig. 9 is missing"
echo "demo checks passed"
