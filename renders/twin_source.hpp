// The twin's box in renders: a poser for the shipped model (carriers included) and a frame
// source that simulates a scenario as it renders.
#pragma once

#include <memory>
#include <string>

#include "renders/render_job.hpp"
#include "twin/scenario.hpp"
#include "twin/simulator.hpp"
#include "twin/world.hpp"

namespace driftless::render {

/// The carrier a log names in its `carrier` metadata (none when absent); throws
/// std::invalid_argument listing the known names on an unknown one.
twin::Carrier carrier_from_metadata(const log::Metadata& meta);

/// Poses the twin's box model (models/driftless_box.xml with `box` applied) from a sample with
/// twin::pose_world_from_sample, the carrier shown and posed with it.
class TwinPoser final : public WorldPoser {
 public:
  TwinPoser(const twin::BoxParams& box, twin::Carrier carrier);
  const mjModel* model() const override { return world_.model(); }
  mjData* data() override { return world_.data(); }
  void pose(const Sample& s) override;
  FramedBodies bodies() const override { return find_framed_bodies(world_.model()); }

 private:
  twin::World world_;
  twin::Carrier carrier_;
};

/// Simulates a scenario and renders it as it runs. The world is posed from each output sample
/// exactly as a replay of the run's log poses it, so both give the same frames.
class ScenarioFrameSource final : public FrameSource {
 public:
  explicit ScenarioFrameSource(const twin::Scenario& scenario);
  WorldPoser& poser() override { return poser_; }
  const StreamInfo& info() const override { return info_; }
  bool next(Sample& sample, Sample& posed) override;

 private:
  twin::Simulator sim_;
  TwinPoser poser_;
  StreamInfo info_;
};

}  // namespace driftless::render
