// libFuzzer harness: the calibration plan loader (rig plan YAML of `driftless calibrate --plan`).
// std::exception with a message (bad YAML, a bad key or value) is the expected refusal.
#include <cstdint>
#include <exception>
#include <string>

#include "calibration/rig_plan.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    (void)driftless::calib::parse_rig_plan(text, "fuzz_plan.yaml");
  } catch (const std::exception&) {
  }
  return 0;
}
