#!/usr/bin/env bash
# allan on the twin's own flipping log (regression: the fit segfaulted when every term of a
# candidate model fitted to zero, in the covariance of an empty active set)
set -euo pipefail
bin=$1
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
"$bin" simulate --scenario default --duration 120 --seed 3 --out "$t/sim" > /dev/null
"$bin" allan --log "$t/sim/log.csv" --out "$t/allan" > "$t/allan.txt" || { cat "$t/allan.txt"; echo "FAIL: allan on the twin log"; exit 1; }
jq -e '.channels | length == 6' "$t/allan/allan_fit.json" > /dev/null || { echo "FAIL: allan_fit.json lacks the six gyro channels"; exit 1; }
echo "allan on a twin log: ok"
