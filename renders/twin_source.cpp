#include "renders/twin_source.hpp"

#include <stdexcept>

#include <fmt/core.h>

namespace driftless::render {

twin::Carrier carrier_from_metadata(const log::Metadata& meta) {
  const auto name = meta.get("carrier");
  if (!name || name->empty()) return twin::Carrier::none;
  std::string known;
  for (auto c : {twin::Carrier::none, twin::Carrier::pan_tilt, twin::Carrier::vehicle,
                 twin::Carrier::ship}) {
    if (*name == twin::carrier_name(c)) return c;
    known += fmt::format("{}{}", known.empty() ? "" : ", ", twin::carrier_name(c));
  }
  throw std::invalid_argument(
      fmt::format("log metadata 'carrier: {}' is not a known carrier ({})", *name, known));
}

TwinPoser::TwinPoser(const twin::BoxParams& box, twin::Carrier carrier)
    : world_(box), carrier_(carrier) {
  Sample rest;  // box at its reference pose, platforms at 0 until the first frame
  twin::pose_world_from_sample(world_, rest, carrier_);
}

void TwinPoser::pose(const Sample& s) {
  twin::pose_world_from_sample(world_, s, carrier_);
  keep_ground_under(world_.model(), world_.data(), world_.box_body());
}

ScenarioFrameSource::ScenarioFrameSource(const twin::Scenario& scenario)
    : sim_(scenario), poser_(scenario.model.box, sim_.motion().carrier()) {
  info_.title = scenario.name;
  info_.metadata = sim_.metadata();
  info_.end_s = scenario.duration_s;
}

bool ScenarioFrameSource::next(Sample& sample, Sample& posed) {
  if (!sim_.next(sample)) return false;
  posed = sample;  // a simulated sample has true platform angles: no gaps to fill
  return true;
}

}  // namespace driftless::render
