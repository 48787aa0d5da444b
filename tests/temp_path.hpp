// A temporary file or folder name of this test process: tests of one binary run as separate
// processes in parallel (ctest -j), and several build trees may run the suite at once, so a fixed
// name in the temp folder would be shared and clobbered. CTest also points TMPDIR into the build
// tree (cmake/DriftlessFlags.cmake).
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace driftless::test {

/// temp folder / "<stem>-<pid><extension>", e.g. temp_path("log.csv") = /tmp/log-1234.csv.
inline std::filesystem::path temp_path(const std::string& name) {
  const std::filesystem::path p(name);
  return std::filesystem::temp_directory_path() /
         (p.stem().string() + "-" + std::to_string(::getpid()) + p.extension().string());
}

}  // namespace driftless::test
