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
