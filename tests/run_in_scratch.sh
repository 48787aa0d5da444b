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
TMPDIR=$scratch "$@"
rc=$?
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
