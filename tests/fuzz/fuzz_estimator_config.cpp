// libFuzzer harness: the estimator configuration parser ('key: value' lines) and validate().
// std::invalid_argument / std::runtime_error with a message are the expected refusals.
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <string>

#include "estimator/config.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    std::istringstream in(text);
    driftless::est::EstimatorConfig cfg = driftless::est::parse_estimator_config(in, "fuzz.cfg", {});
    cfg.validate();
    std::ostringstream out;
    driftless::est::write_estimator_config(out, cfg);
    std::istringstream back(out.str());
    (void)driftless::est::parse_estimator_config(back, "round-trip.cfg", {});  // what it writes it reads
  } catch (const std::invalid_argument&) {
  } catch (const std::runtime_error&) {
  }
  return 0;
}
