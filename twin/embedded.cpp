#include "twin/embedded.hpp"

#include "driftless_embedded_models.inc"  // generated: kEmbeddedBoxMjcf, kEmbeddedScenarios

namespace driftless::twin::embedded {

const std::string_view kBoxMjcf = kEmbeddedBoxMjcf;

std::span<const NamedText> scenarios() { return kEmbeddedScenarios; }

}  // namespace driftless::twin::embedded
