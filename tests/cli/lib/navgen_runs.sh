# (in lib/, so that the cli tests' *.sh glob does not take it for a test)
# Sourced after lib/outsider_log.sh by the cli tests that estimate logs of the outsider's generator
# (tests/estimator/navgen.py, mutate.py). Expects $bin, $src, $py and $t. Gives $nav, $mut and run().
nav="$py $src/tests/estimator/navgen.py"
mut="$py $src/tests/estimator/mutate.py"

# run NAME WANT_EXIT [estimate options]: estimate on $t/NAME.csv, exit code as expected
run() {
  local name=$1 want=$2; shift 2
  "$bin" estimate --log "$t/$name.csv" --out "$t/o_$name" "$@" > "$t/$name.txt" 2>&1
  local rc=$?
  [ "$rc" = "$want" ] || { cat "$t/$name.txt"; fail "$name: exit $rc, expected $want"; }
}

# first_finding NAME CAUSE SEVERITY: the first health finding of run NAME is CAUSE with SEVERITY;
# with skip_notes=1 set by the caller, the first that is not a note ("ok": a clipping MPU6050's
# saturation notes lead)
first_finding() {
  local got
  got=$(grep -o '"cause": "[a-z_]*", "severity": "[a-z]*"' "$t/o_$1/summary.json" |
    if [ "${skip_notes:-0}" = 1 ]; then grep -v '"ok"'; else cat; fi | head -1)
  [ "$got" = "\"cause\": \"$2\", \"severity\": \"$3\"" ] || { cat "$t/$1.txt"; fail "$1: first finding $got, expected $2 ($3)"; }
}
