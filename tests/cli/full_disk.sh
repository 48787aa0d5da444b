#!/usr/bin/env bash
# A full output disk (a 256 KiB tmpfs): every command that writes stops with one line
# "<file>: No space left on device", exits 1 and leaves nothing that looks complete: no result
# file under its final name, no partial file, a log that says complete: false.
# Needs root for the mount; exits 77 (skipped, with a message) where it cannot mount.
set -uo pipefail
bin=$1; src=$2
t=$(mktemp -d); disk="$t/disk"; mkdir -p "$disk"
cleanup() { umount "$disk" 2>/dev/null; rm -rf "$t"; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; exit 1; }
if ! mount -t tmpfs -o size=256k tmpfs "$disk" 2>/dev/null; then
  echo "SKIP: cannot mount a small tmpfs here (needs root); the full-disk cases are untested"
  exit 77
fi

# a 2 min twin log outside the small disk: its outputs overflow 256 KiB
"$bin" simulate --scenario default --duration 120 --seed 3 --out "$t/sim" > /dev/null 2>&1 || fail "simulate for the input"

# expect_full NAME CMD...: exit 1, one line naming a file on the small disk and the reason, no
# partial file, no empty file (an empty PNG or JSON would pass for a result)
expect_full() {
  local name=$1; shift
  rm -rf "${disk:?}"/*
  [[ -n ${FILL_KIB:-} ]] && head -c "${FILL_KIB}k" /dev/zero > "$disk/filler" 2>/dev/null
  "$@" > "$t/$name.out" 2> "$t/$name.err"
  local rc=$?
  [[ $rc -eq 1 ]] || { cat "$t/$name.err"; fail "$name: exit status $rc, want 1"; }
  grep -q "$disk/.*: No space left on device" "$t/$name.err" || { cat "$t/$name.err"; fail "$name: no '<file>: No space left on device' line"; }
  grep -qi "terminate called\|Aborted\|core dumped" "$t/$name.err" && fail "$name: aborted"
  [[ -z $(find "$disk" -name '*.partial-*') ]] || { find "$disk"; fail "$name: a partial file was left"; }
  [[ -z $(find "$disk" -type f -size 0) ]] || { find "$disk" -type f -size 0; fail "$name: an empty file was left"; }
}

expect_full simulate "$bin" simulate --scenario default --duration 120 --seed 3 --out "$disk/sim"
grep -q "^# complete: false" "$disk/sim/log.csv" || fail "simulate: the log on the full disk does not say complete: false"

expect_full estimate "$bin" estimate --log "$t/sim/log.csv" --out "$disk/est" --corrected
for f in corrected.csv estimate.csv attitude.csv summary.json; do
  [[ ! -e $disk/est/$f ]] || fail "estimate: $f looks complete on a full disk"
done

# the disk nearly full (about 12 KiB left) for the commands whose outputs are small
FILL_KIB=244
expect_full allan "$bin" allan --log "$src/tests/data/estimator_golden/log.csv" --out "$disk/allan" --plot
expect_full diagnose "$bin" diagnose --log "$t/sim/log.csv" --out "$disk/diag"
[[ ! -e $disk/diag/report.html ]] || fail "diagnose: report.html on a full disk"
expect_full render "$bin" render --log "$t/sim/log.csv" --out "$disk/video.mp4" --width 160 --height 120 --fps 10
[[ ! -e $disk/video.mp4 ]] || fail "render: video.mp4 on a full disk"

echo "full disk: ok"
