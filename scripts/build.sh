#!/usr/bin/env bash
# Configure and build. Usage: scripts/build.sh [BUILD_DIR] [extra cmake args...]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
build_dir=${1:-"$root/build"}
shift || true
jobs=$(nproc 2>/dev/null || echo 2)
# ccache (when installed) keys on paths relative to the checkout, so a second clone or a second
# build folder of the same sources reuses the objects instead of compiling them again
export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$root} CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-1}
# the cache on a shared disk is bounded: a whole CI (Release, sanitizer and fuzz objects) stores
# about 0.2 GB, so 1 GB keeps several states of the code warm (ccache's own default is 5 GB)
export CCACHE_MAXSIZE=${CCACHE_MAXSIZE:-1G}
# the tests share a precompiled header; ccache caches the files compiled with it only when told
# that the header's definitions and time stamps do not change the result
export CCACHE_SLOPPINESS=${CCACHE_SLOPPINESS:-pch_defines,time_macros,include_file_mtime,include_file_ctime}
cmake -S "$root" -B "$build_dir" -DCMAKE_BUILD_TYPE=${BUILD_TYPE:-Release} "$@" >/dev/null
cmake --build "$build_dir" -j "$jobs"
