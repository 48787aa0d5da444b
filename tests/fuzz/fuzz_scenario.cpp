// libFuzzer harness: the scenario loader (YAML text -> Scenario, validate, emit, read back).
// std::exception with a message is the expected refusal (bad YAML, a bad key or value).
#include <cstdint>
#include <exception>
#include <string>

#include "twin/scenario.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    driftless::twin::Scenario sc = driftless::twin::parse_scenario(text, "fuzz.yaml", "/nonexistent-fuzz-dir");
    sc.validate();
    (void)driftless::twin::parse_scenario(driftless::twin::emit_scenario(sc), "round-trip.yaml");
  } catch (const std::exception&) {
  }
  return 0;
}
