#!/usr/bin/env bash
# Install everything DriftLess Twin needs from Debian 12 packages. Idempotent: skips apt when all present.
set -euo pipefail
packages=(
  build-essential cmake pkg-config ccache git universal-ctags
  ninja-build  # the build tool (scripts/build.sh): targets overlap, shorter start-up than make
  lld  # the linker (CMakeLists.txt: DRIFTLESS_USE_LLD), a third of GNU ld's link time
  libmujoco-dev libqhull-dev libeigen3-dev libyaml-cpp-dev libosmesa6-dev
  libpng-dev libcli11-dev libgtest-dev libgmock-dev libbenchmark-dev libfmt-dev libfast-float-dev
  ffmpeg gnuplot-nox openmpi-bin libopenmpi-dev
  clang libclang-rt-14-dev  # libFuzzer harnesses (tests/fuzz, CI)
  librosbag-dev libsensor-msgs-dev
  libbz2-dev liblz4-dev  # compressed bag chunks read directly (importers/bag_records.cpp)
  chromium  # the look test (tests/cli/look.sh) opens the report and the figures headless
  python3-numpy  # the independent log generator of the diagnose tests (tests/diagnose/independent_log.py)
  zstd  # CI keeps the test generators' logs compressed for its second suite (tests/cli/lib/py_cached.sh)
)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} Debian packages present"
  exit 0
fi
echo "setup: installing ${missing[*]}"
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  command -v sudo >/dev/null || { echo "setup: need root (or sudo) to install: ${missing[*]}" >&2; exit 1; }
  sudo_cmd=(sudo)
fi
export DEBIAN_FRONTEND=noninteractive
"${sudo_cmd[@]}" apt-get update -qq
"${sudo_cmd[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
echo "setup: done"
