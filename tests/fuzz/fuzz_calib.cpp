// libFuzzer harness: the calib.yaml reader (`driftless estimate --calib`, `calibrate --prior-out`).
// std::exception with a message (bad YAML, a bad key or value, a singular M) is the expected refusal.
#include <cstdint>
#include <exception>
#include <string>

#include "calibration/calib_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)driftless::calib::parse_calib(text, "fuzz_calib.yaml").to_filter_calibration();
  } catch (const std::exception&) {
  }
  return 0;
}
