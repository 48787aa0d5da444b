#!/usr/bin/env bash
# The exit-code table (README "Exit status and output files"): 0 success, 1 bad input or failed run,
# 2 usage error, 130/143 interrupted (tests/cli/interrupt.sh); each usage error is one readable line.
set -uo pipefail
bin=$1; src=$2
golden=$src/tests/data/estimator_golden/log.csv
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

# expect CODE PATTERN ARGS...: exit status and one stderr line matching the pattern
expect() {
  local want=$1 pattern=$2; shift 2
  "$bin" "$@" > "$t/out" 2> "$t/err"
  local rc=$?
  [[ $rc -eq $want ]] || { cat "$t/err"; fail "'$*': exit status $rc, want $want"; }
  if [[ -n $pattern ]]; then
    grep -q -- "$pattern" "$t/err" || { cat "$t/err"; fail "'$*': message lacks '$pattern'"; }
    [[ $(wc -l < "$t/err") -eq 1 ]] || { cat "$t/err"; fail "'$*': expected one message line"; }
    if grep -q "[0-9]\{40\}" "$t/err"; then fail "'$*': a number of 40 digits in the message"; fi
  fi
}

# 0: success, --help, --version
expect 0 "" check --log "$golden"
expect 0 "" --help
expect 0 "" --version
expect 0 "" estimate --help

# 2: usage errors, each a readable line naming the command
expect 2 "driftless: unknown command 'bogus'; the commands are demo, simulate" bogus
expect 2 "driftless: a command is required" 
expect 2 "driftless estimate: unknown option '--bogus'" estimate --bogus --log "$golden" --out "$t/e"
expect 2 "driftless simulate: --duration: expected a number > 0 (s), got '-5'" simulate --out "$t/s" --duration -5
expect 2 "driftless simulate: --duration: expected a number > 0 (s), got 'abc'" simulate --out "$t/s" --duration abc
expect 2 "driftless simulate: --seed: expected a whole number 0 .. 18446744073709551615, got '-1'" \
  simulate --out "$t/s" --seed -1
expect 2 "driftless hil: --seed: expected a whole number" hil --source emu-i2c --out "$t/h" --seed -3
# a count given as a negative number is refused, not wrapped around into 2^64 - 1 (which ran forever)
expect 2 "driftless allan: --validate: expected a whole number 0 .. 10000, got '-1'" \
  allan --log "$golden" --out "$t/a" --validate -1
# a unit not in the unit table is a usage error, found when the options are read
expect 2 "driftless convert: --units: expected deg/s, rad/s or lsb:" convert --in "$golden" --out "$t/c.csv" --units furlongs
expect 2 "driftless allan: --time-units: expected s, ms, us or ns" allan --in "$golden" --out "$t/a" --time-units parsecs
expect 2 "driftless convert: --ref-max-gap requires --ref" convert --in "$golden" --out "$t/c.csv" --ref-max-gap 1
expect 2 "driftless check: --log is required" check
expect 2 "driftless estimate: --mode" estimate --log "$golden" --out "$t/e" --mode sideways
expect 2 "driftless check: --log: File does not exist" check --log "$t/none.csv"
expect 2 "driftless allan: unknown option '--nope'" allan --nope

# 1: bad input (a refused file, naming file and line) and a failed run
printf '# latitude_deg: 400\nt,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n' > "$t/lat.csv"
expect 1 "lat.csv:1: latitude_deg: expected a latitude in deg within \[-90, 90\], got '400'" check --log "$t/lat.csv"
expect 1 "lat.csv:1: latitude_deg:" estimate --log "$t/lat.csv" --out "$t/e2"
printf 'duration_s: 5\nmotion: [static\n' > "$t/broken.yaml"
expect 1 "broken.yaml" simulate --scenario "$t/broken.yaml" --out "$t/s2"
mkdir -p "$t/ro" && touch "$t/ro/summary.json" && chmod 500 "$t/ro"
if [[ $(id -u) -ne 0 ]]; then  # root writes anywhere: this case needs a normal user
  expect 1 "cannot open for writing: Permission denied" estimate --log "$golden" --out "$t/ro"
fi
echo "exit codes: ok"
