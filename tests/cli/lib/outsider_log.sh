# (in lib/, so that the cli tests' *.sh glob does not take it for a test)
# Sourced by the cli tests that run on generators written apart from twin/ (the outsider's
# tests/diagnose/probe_log.py by default; a script sets its own $gen after sourcing, e.g.
# independent_log.py or tests/estimator/navgen.py). Expects $src (the source folder). Gives $py,
# $gen, a scratch folder $t removed on exit, and fail(); exits 77 (skipped) when the Python has no numpy.
# python3, through the wrapper that shares the generated logs between CI's two suites (lib/py_cached.sh)
py=$src/tests/cli/lib/py_cached.sh
gen=$src/tests/diagnose/probe_log.py
"$py" -c 'import numpy' 2>/dev/null || { echo "no numpy for $py: skipped"; exit 77; }
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
