// GIVEN a scenario of the twin WHEN it is rendered while it simulates, and its log is replayed
// THEN both videos hold the same frames (within encoder tolerance), flips included.
#include <gtest/gtest.h>

#include "renders/twin_source.hpp"
#include "tests/renders/render_fixture.hpp"

namespace driftless::render {
namespace {

TEST(RenderTwin, ScenarioAndItsLogGiveTheSameFrames) {
  const auto dir = testing::scratch_dir("twin");
  twin::Scenario sc = twin::load_scenario("static");
  sc.duration_s = 4.0;
  sc.flip_schedule.standstill_s = 0.8;  // a flip within the first seconds
  twin::simulate_to_log(sc, dir / "run.csv");

  RenderParams p;
  p.scene.width_px = 192;
  p.scene.height_px = 144;
  p.scene.camera = "cam_closeup";
  p.timeline.fps = 15;
  p.encoder.crf = 12;
  p.out = dir / "scenario.mp4";
  ScenarioFrameSource sim_src(sc);
  const auto a = render_video(sim_src, p);

  log::LogReader head(dir / "run.csv");
  TwinPoser poser(sc.model.box, carrier_from_metadata(head.metadata()));
  LogFrameSource log_src(dir / "run.csv", poser);
  p.out = dir / "log.mp4";
  const auto b = render_video(log_src, p);

  ASSERT_EQ(a.frames, 60u);
  ASSERT_EQ(b.frames, a.frames);
  const auto fa = testing::decode(dir / "scenario.mp4", 192, 144);
  const auto fb = testing::decode(dir / "log.mp4", 192, 144);
  ASSERT_EQ(fa.size(), 60u);
  ASSERT_EQ(fb.size(), 60u);
  double worst = 0, motion = 0;
  for (std::size_t i = 0; i < fa.size(); ++i) {
    worst = std::max(worst, testing::mean_abs_diff(fa[i], fb[i], 192, 0, 0, 192, 144));
    // the 3D view sits in the lower left, under the text band and beside the charts
    motion = std::max(motion, testing::mean_abs_diff(fa[0], fa[i], 192, 0, 72, 110, 72));
  }
  // same frames: the difference is encoder noise, far below what a flip changes
  EXPECT_LT(worst, 0.5);
  EXPECT_GT(motion, 5.0 * std::max(worst, 0.2));
}

}  // namespace
}  // namespace driftless::render
