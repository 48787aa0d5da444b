#!/usr/bin/env bash
# Set up (Debian packages), build, and run the whole test suite through CTest.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh" "$root/build"
cd "$root/build"
# one test more than cores: the real-time and signal tests mostly wait (SerialSource.*: 8.3 s of wall
# time for 0.15 s of CPU; cli.hil 5.7 s for 0.6 s; cli.interrupt 10.9 s for 4.5 s), and a waiting
# test would hold a core's slot
ctest --output-on-failure -j "$(( $(nproc 2>/dev/null || echo 2) + 1 ))" --timeout 600
