#!/usr/bin/env bash
# Box dwells (docs/estimator.md section 1d) on boxes that never truly stop, from the outsider's
# generator (tests/estimator/navgen.py, written apart from twin/), no ref_q so that only the dwells'
# own checks can speak:
# - a box rocking +-20 deg over 17 s passes a turning point twice a period, below 2 deg/s for about
#   a second: those stretches were used as dwells, the gate rejected most of them without a word,
#   and the one it took moved the shared vertical bias (273 deg/h against 2 without --selfcal);
#   now they are refused as moving (summary.json box_dwells.refused_moving); with no dwell at all
#   nothing observes the bias both sensors share about the vertical, which health names since
#   stop 29 (vertical_unobserved, degraded: the drift it allows, and the pause as the fix);
# - a box turning steadily at 0.5 deg/s has no trend in its pauses: they are used and the gate
#   rejects about half, which is now a box_dwells_rejected finding (degraded) with the fix.
# usage: estimate_box_dwells.sh <path-to-driftless> <source-dir>
set -uo pipefail
bin=$1; src=$2
source "$src/tests/cli/lib/outsider_log.sh"
gen=$src/tests/estimator/navgen.py
json() { "$py" -c "import json,sys; d=json.load(open(sys.argv[1])); print($2)" "$1"; }

# GIVEN the rocking box (a perfect BMI088 pair)
"$py" "$gen" --out "$t/rock.csv" --sensor bmi088 --motion rock --duration 600 --seed 7 --no-ref > /dev/null || fail "generator"
# WHEN estimate --selfcal runs THEN no turning point is used as a dwell, none is rejected, and the
# unobserved vertical is named (the only degraded finding)
"$bin" estimate --log "$t/rock.csv" --out "$t/r" --selfcal > "$t/r.out" 2>&1 || fail "rock: exit $?: $(cat "$t/r.out")"
[ "$(json "$t/r/summary.json" "[f['cause'] for f in d['health']['findings'] if f['severity'] != 'ok']")" = "['vertical_unobserved']" ] ||
  fail "rock: findings: $(cat "$t/r.out")"
[ "$(json "$t/r/summary.json" "d['box_dwells']['updates']")" = 0 ] || fail "turning points used as dwells: $(json "$t/r/summary.json" "d['box_dwells']")"
[ "$(json "$t/r/summary.json" "d['box_dwells']['refused_moving'] >= 4")" = True ] || fail "turning points not refused: $(json "$t/r/summary.json" "d['box_dwells']")"
if grep -q "box dwell updates were rejected" "$t/r.out"; then fail "a dwell rejection named on the rocking box"; fi

# GIVEN the box turning steadily at 0.5 deg/s about the vertical
"$py" "$gen" --out "$t/yaw.csv" --sensor bmi088 --motion slowyaw --yaw-rate 0.5 --duration 600 --seed 3 --no-ref > /dev/null || fail "generator"
# WHEN estimate --selfcal runs THEN the dwells' rejections are a finding with its fix, and --strict fails
"$bin" estimate --log "$t/yaw.csv" --out "$t/y" --selfcal --strict > "$t/y.out" 2>&1 && fail "slow turn: --strict exited 0"
[ "$(json "$t/y/summary.json" "[f['cause'] for f in d['health']['findings']].count('box_dwells_rejected')")" = 1 ] ||
  fail "no box_dwells_rejected finding: $(cat "$t/y.out")"
# AND (stop 30) the fix is the one that applies to this log: it has no ref_q, so only |f| decided
# the pauses: "Log ref_q" (main: only "Set box_dwell_updates: false")
grep -q "box dwell updates were rejected by their gate.*Log ref_q (the box's attitude from a reference).*set box_dwell_updates: false" "$t/y.out" ||
  fail "no cause or fix: $(cat "$t/y.out")"
echo "ok"
