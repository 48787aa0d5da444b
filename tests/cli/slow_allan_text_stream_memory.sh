#!/usr/bin/env bash
# driftless allan --stream on a large text file gives back its pages as it goes (every 64 MB of
# the mapped file, importers/text_reader.cpp): the peak memory of a 4x longer record stays that
# of the shorter one. Files of 72 and 290 MiB (8 M and 32 M one-column samples, a generated
# block repeated); the peak resident set of each run is read from the kernel's accounting of the
# finished child (getrusage). Without the release the mapped pages of the longer file alone
# would add 217 MiB; the bound allowed is 48 MiB.
set -euo pipefail
bin=$1
t=$(mktemp -d); trap 'rm -rf "$t"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

awk 'BEGIN { srand(3); for (i = 0; i < 800000; i++) printf "%.6f\n", 0.01 * (rand() - 0.5) }' > "$t/block.txt"
for i in $(seq 10); do cat "$t/block.txt"; done > "$t/short.csv"
for i in 1 2 3 4; do cat "$t/short.csv"; done > "$t/long.csv"
rm "$t/block.txt"

# peak resident set of one run, KiB (the child's maximum, from getrusage)
peak_kib() {
  python3 - "$@" <<'EOF'
import resource, subprocess, sys
rc = subprocess.run(sys.argv[1:], stdout=subprocess.DEVNULL).returncode
if rc != 0:
    sys.exit(f"exit {rc}: {' '.join(sys.argv[1:])}")
print(resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss)
EOF
}
run() { peak_kib "$bin" allan --csv "$t/$1.csv" --no-header --columns 1 --time-column none --rate 400 --stream --out "$t/o_$1"; }
short=$(run short)
long=$(run long)
bytes_short=$(stat -c %s "$t/short.csv") bytes_long=$(stat -c %s "$t/long.csv")
echo "peak resident set: $short KiB for $((bytes_short / 1048576)) MiB, $long KiB for $((bytes_long / 1048576)) MiB of text"
grep -q "col1" "$t/o_long/allan.csv" || fail "no curve written for the long file"
samples=$(python3 -c 'import json, sys; print(json.load(open(sys.argv[1]))["samples"])' "$t/o_long/allan_fit.json")
[[ $samples == 32000000 ]] || fail "the long file gave $samples samples, expected 32000000"
(( long - short < 48 * 1024 )) || fail "peak memory grew from $short KiB to $long KiB with the record (bound: +48 MiB)"
(( long < bytes_long / 1024 )) || fail "peak memory $long KiB is above the file's size: its pages are not given back"
echo "ok"
