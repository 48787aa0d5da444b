#!/usr/bin/env bash
# Configure and build. Usage: [BUILD_TYPE=...] [BUILD_TARGET=...] scripts/build.sh [BUILD_DIR] [extra cmake args...]
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
# ccache's depend mode: on a miss it reads the compiler's own dependency file (-MD, which Ninja and
# make ask for) instead of running the preprocessor once more before compiling: 207 preprocessor
# runs, 16 s of CPU, in a cold Release build (2 % of it). Hits are looked up as before (direct mode),
# so objects cached without it are still found, from any clone.
export CCACHE_DEPEND=${CCACHE_DEPEND:-1}
# Ninja for a new build folder (scripts/setup.sh installs ninja-build): it starts a target's objects
# while the libraries it links are still linking, and its start-up is shorter than make's. A folder
# already configured keeps its generator (CMake refuses to change it in place).
generator=()
if [[ ! -f "$build_dir/CMakeCache.txt" ]] && command -v ninja > /dev/null; then
  generator=(-G Ninja)
fi
cmake -S "$root" -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=${BUILD_TYPE:-Release} "$@" >/dev/null
# BUILD_TARGET: one target and what it needs instead of everything (tests/fuzz/run.sh: fuzzers)
cmake --build "$build_dir" -j "$jobs" ${BUILD_TARGET:+--target "$BUILD_TARGET"}
