#!/usr/bin/env bash
# Bad logs give one clear line and exit 1; NaN rows and 'complete: false' are accepted with a warning.
set -uo pipefail
bin=$1; src=$2
golden=$src/tests/data/estimator_golden/log.csv
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

expect_error() {  # name file pattern
  local name=$1 file=$2 pattern=$3
  "$bin" estimate --log "$file" --out "$t/out_$name" > "$t/$name.out" 2> "$t/$name.err"
  local rc=$?
  [[ $rc -eq 1 ]] || fail "$name: exit code $rc, expected 1"
  grep -q -- "$pattern" "$t/$name.err" || { cat "$t/$name.err"; fail "$name: message lacks '$pattern'"; }
  [[ $(wc -l < "$t/$name.err") -eq 1 ]] || fail "$name: expected one error line"
}
expect_warning() {  # name file pattern
  local name=$1 file=$2 pattern=$3
  "$bin" estimate --log "$file" --out "$t/out_$name" > "$t/$name.out" 2> "$t/$name.err" || fail "$name: non-zero exit"
  grep -q -- "$pattern" "$t/$name.err" || { cat "$t/$name.err"; fail "$name: no warning '$pattern'"; }
  grep -q -- "$pattern" "$t/out_$name/summary.json" || fail "$name: summary.json lacks the warning"
}

: > "$t/empty.csv"
expect_error empty "$t/empty.csv" "empty file"

printf '# format: driftless-log 1\n# complete: true\nt,gyro1_x,gyro1_y\n0,1,2\n' > "$t/missing.csv"
expect_error missing_columns "$t/missing.csv" "lacks required column(s) gyro1_z"

(head -30 "$golden"; sed -n 30p "$golden") > "$t/dup.csv"
expect_error time "$t/dup.csv" "time must increase strictly"

(head -30 "$golden"; sed -n '31,60p' "$golden" | sed 's/^\([^,]*\),[^,]*,/\1,nan,/'; sed -n '61,400p' "$golden") > "$t/nan.csv"
expect_warning nan_rows "$t/nan.csv" "30 rows had a missing or NaN gyro value"

sed 's/^# complete: true $/# complete: false/' "$golden" > "$t/incomplete.csv"
echo "# incomplete: device unplugged" >> "$t/incomplete.csv"
expect_warning incomplete "$t/incomplete.csv" "complete: false"

(head -30 "$golden"; echo "1.234567,abc,1,2,3") > "$t/junk.csv"
"$bin" estimate --log "$t/junk.csv" --out "$t/out_junk" > /dev/null 2> "$t/junk.err" && fail "junk row accepted"
grep -q "junk.csv:" "$t/junk.err" || fail "junk row: message lacks file:line"

printf 'mode: paper\nsettle_s: soon\n' > "$t/bad.cfg"
"$bin" estimate --log "$golden" --config "$t/bad.cfg" --out "$t/out_cfg" > /dev/null 2> "$t/cfg.err" && fail "bad config accepted"
grep -q "bad.cfg:2: settle_s: expected a number" "$t/cfg.err" || { cat "$t/cfg.err"; fail "bad config message"; }
echo "ok"
