#!/usr/bin/env bash
# tests/cli/lib/py_cached.sh, the python3 wrapper that keeps the generators' logs for CI's second
# suite: a second run with the same script and arguments gives the same outputs and output text
# without running the script; another argument, another script text, another input file's contents
# or a failed run are not taken from the cache; without DRIFTLESS_GEN_CACHE it is python3.
# usage: py_cached.sh <path-to-driftless> <source-dir>
set -uo pipefail
src=$2
wrap=$src/tests/cli/lib/py_cached.sh
command -v zstd > /dev/null || { echo "no zstd: skipped"; exit 77; }
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }
export DRIFTLESS_GEN_CACHE=$t/cache
# a generator that counts its runs (in a file no argument names) and writes --out and --truth-out
cat > "$t/gen.py" <<'EOF'
import argparse, sys
ap = argparse.ArgumentParser()
ap.add_argument("--out", required=True)
ap.add_argument("--truth-out")
ap.add_argument("--seed", type=int, default=0)
ap.add_argument("--input")
ap.add_argument("--fail", action="store_true")
a = ap.parse_args()
with open(sys.argv[0] + ".runs", "a") as f:
    f.write("run\n")
if a.fail:
    print("refused", file=sys.stderr)
    sys.exit(3)
extra = open(a.input).read() if a.input else ""
with open(a.out, "w") as f:
    f.write("# seed %d\n%s" % (a.seed, extra) + "1,2,3\n" * 1000)
if a.truth_out:
    with open(a.truth_out, "w") as f:
        f.write('{"seed": %d}\n' % a.seed)
print("wrote %s" % a.out)
print("a note", file=sys.stderr)
EOF
runs() { wc -l < "$t/gen.py.runs"; }

"$wrap" "$t/gen.py" --out "$t/a.csv" --truth-out "$t/a.json" --seed 4 > "$t/a.txt" 2> "$t/a.err" || fail "first run"
[[ $(runs) == 1 ]] || fail "first run: $(runs) runs"
# the same arguments, other output paths: from the cache, outputs and text as the first run's
"$wrap" "$t/gen.py" --out "$t/b.csv" --truth-out "$t/b.json" --seed 4 > "$t/b.txt" 2> "$t/b.err" || fail "second run"
[[ $(runs) == 1 ]] || fail "the second run ran the script ($(runs) runs)"
cmp -s "$t/a.csv" "$t/b.csv" || fail "--out differs from the first run's"
cmp -s "$t/a.json" "$t/b.json" || fail "--truth-out differs from the first run's"
[[ $(cat "$t/b.txt") == "wrote $t/a.csv" ]] || fail "stdout not replayed: $(cat "$t/b.txt")"
[[ $(cat "$t/b.err") == "a note" ]] || fail "stderr not replayed: $(cat "$t/b.err")"
# another argument: run
"$wrap" "$t/gen.py" --out "$t/c.csv" --seed 5 > /dev/null 2>&1 || fail "seed 5"
[[ $(runs) == 2 ]] || fail "another seed came from the cache"
grep -q "^# seed 5$" "$t/c.csv" || fail "seed 5: wrong log"
# an input file's contents are part of the key
echo "first" > "$t/in.txt"
"$wrap" "$t/gen.py" --out "$t/d.csv" --input "$t/in.txt" > /dev/null 2>&1 || fail "input 1"
echo "second" > "$t/in.txt"
"$wrap" "$t/gen.py" --out "$t/e.csv" --input "$t/in.txt" > /dev/null 2>&1 || fail "input 2"
[[ $(runs) == 4 ]] || fail "a changed input file came from the cache ($(runs) runs)"
grep -q "^second$" "$t/e.csv" || fail "changed input: the old log"
# another script text: run
echo "# changed" >> "$t/gen.py"
"$wrap" "$t/gen.py" --out "$t/f.csv" --seed 4 > /dev/null 2>&1 || fail "changed script"
[[ $(runs) == 5 ]] || fail "a changed script came from the cache"
# a failed run keeps its exit status and text, and is not kept
for k in 1 2; do
  "$wrap" "$t/gen.py" --out "$t/g.csv" --fail > /dev/null 2> "$t/g.err"
  rc=$?
  [[ $rc == 3 ]] || fail "failed run $k: exit $rc, expected 3"
  grep -q refused "$t/g.err" || fail "failed run $k: its stderr is lost"
done
[[ $(runs) == 7 ]] || fail "a failed run was kept ($(runs) runs)"
# without the cache folder: python3 itself
unset DRIFTLESS_GEN_CACHE
"$wrap" "$t/gen.py" --out "$t/h.csv" --seed 4 > /dev/null 2>&1 || fail "no cache"
[[ $(runs) == 8 ]] || fail "without DRIFTLESS_GEN_CACHE the cache was used"
[[ $("$wrap" -c 'print(6 * 7)') == 42 ]] || fail "python3 -c through the wrapper"
echo "py_cached: ok"
