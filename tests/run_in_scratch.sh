#!/usr/bin/env bash
# Runs one test (CTest's command for it) with TMPDIR set to a scratch folder of its own, inside the
# build tree's TMPDIR, and removes the folder when the test passes or is skipped: what a test
# writes stays on disk only while it runs, so the suite's footprint is that of the tests running
# at once, not the sum of every test's files (the CI of 2026-11-24 ran out of disk on a shared
# machine; the Release suite had left 430 MB behind). A failed test's folder is kept for reading,
# and the script names it. When a test fails on a nearly full disk, it says so plainly, since the
# failure itself may only read "No space left on device" deep in a library's message.
# usage: run_in_scratch.sh PROGRAM [ARGS...]   (CTest passes the test's command; TMPDIR is the base)
set -uo pipefail
base=${TMPDIR:-/tmp}
# free MiB on the disk holding a folder ("?" when df cannot tell)
free_mib() { df -Pm "$1" 2> /dev/null | awk 'NR == 2 { print $4 }' || echo "?"; }
if ! scratch=$(mktemp -d "$base/test.XXXXXX"); then
  echo "run_in_scratch: cannot make a scratch folder in $base ($(free_mib "$base") MiB free there)" >&2
  exit 1
fi
started=$(date +%s.%N)
TMPDIR=$scratch "$@"
rc=$?
# DRIFTLESS_TEST_CPU_LOG (CI sets it): one line per test, its CPU seconds (user + system of the
# test's processes), wall seconds and command, so CI can say where a suite's time goes on a
# machine whose load would distort wall times
if [[ -n ${DRIFTLESS_TEST_CPU_LOG:-} ]]; then
  # 'times' in this shell (not in a subshell, which has no children): the shell's own user and
  # system time, then its children's, as "<m>m<s>s" each
  times > "$scratch.times"
  cpu=$(awk 'NR == 2 { t = 0; for (i = 1; i <= 2; ++i) { split($i, p, /[ms]/); t += 60 * p[1] + p[2] } printf "%.2f", t }' "$scratch.times")
  rm -f "$scratch.times"
  wall=$(awk -v a="$started" -v b="$(date +%s.%N)" 'BEGIN { printf "%.2f", b - a }')
  echo "$cpu $wall $rc $*" >> "$DRIFTLESS_TEST_CPU_LOG"
fi
# 77: a cli script that cannot run here (SKIP_RETURN_CODE); its files are not needed either
if [[ $rc -eq 0 || $rc -eq 77 ]]; then
  rm -rf "$scratch"
  exit "$rc"
fi
free=$(free_mib "$base")
echo "run_in_scratch: exit status $rc; the test's files are kept in $scratch" >&2
# below 1 GiB free, a failure may be the disk's and not the code's
if [[ $free =~ ^[0-9]+$ ]] && (( free < 1024 )); then
  echo "run_in_scratch: THE DISK IS NEARLY FULL: $free MiB free on the disk of $base. If the failure" \
       "above mentions 'No space left on device' (ENOSPC), the disk filled up; free space and rerun." >&2
fi
exit "$rc"
