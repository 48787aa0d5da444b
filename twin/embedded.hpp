// Texts built into the program: models/driftless_box.xml and models/scenarios/*.yaml, so the
// driftless binary runs without the source tree. Generated at configure time (twin/CMakeLists.txt).
#pragma once

#include <span>
#include <string_view>

namespace driftless::twin::embedded {

/// A file built into the binary: its name (scenario stem or file name) and text.
struct NamedText {
  std::string_view name;
  std::string_view text;
};

/// models/driftless_box.xml.
extern const std::string_view kBoxMjcf;
/// models/scenarios/*.yaml, by stem ("default", "static", ...), sorted by name.
std::span<const NamedText> scenarios();

}  // namespace driftless::twin::embedded
