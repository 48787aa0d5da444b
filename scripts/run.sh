#!/usr/bin/env bash
# Set up (Debian packages), build, and run the main job on the embedded default scenario into out/demo/.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
bash "$root/scripts/setup.sh"
bash "$root/scripts/build.sh" "$root/build"
cd "$root"
"$root/build/bin/driftless" demo --out "$root/out/demo" "$@"
