// GIVEN a box model and a log with flips WHEN it is rendered off-screen THEN the decoded video has
// the right frames, shows the platforms moving only during flips, and fails cleanly without GL.
#include <cstdlib>

#include <gtest/gtest.h>

#include "renders/gl_context.hpp"
#include "renders/render_job.hpp"
#include "tests/renders/render_fixture.hpp"

namespace driftless::render {
namespace {

using namespace testing;

constexpr int kW = 256, kH = 192;

RenderParams small_params(const std::filesystem::path& out) {
  RenderParams p;
  p.scene.width_px = kW;
  p.scene.height_px = kH;
  p.scene.camera = "cam_fixed";
  p.timeline.fps = 20;
  p.encoder.crf = 12;  // near-lossless, so encoder noise stays far below real changes
  p.out = out;
  return p;
}

// pixel position of a world point seen from an MJCF camera (pinhole with the camera's fovy)
std::pair<int, int> project(const mjModel* m, const mjData* d, int cam, const mjtNum* world,
                            int w, int h) {
  const mjtNum* p = d->cam_xpos + 3 * cam;
  const mjtNum* R = d->cam_xmat + 9 * cam;  // columns: right, up, backwards
  mjtNum rel[3] = {world[0] - p[0], world[1] - p[1], world[2] - p[2]};
  mjtNum c[3];
  for (int k = 0; k < 3; ++k) c[k] = R[k] * rel[0] + R[3 + k] * rel[1] + R[6 + k] * rel[2];
  const double f = 0.5 * h / std::tan(0.5 * m->cam_fovy[cam] * kRadPerDeg);
  return {static_cast<int>(0.5 * w + f * c[0] / -c[2]), static_cast<int>(0.5 * h - f * c[1] / -c[2])};
}

class RenderVideoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    unsetenv(kNoGlEnv);
    unsetenv(kFfmpegEnv);
  }
  ModelPtr model_ = load_model();
  BoxPoser poser_{model_.get()};
};

TEST_F(RenderVideoTest, FramesSizeRateAndContentAreRight) {
  // GIVEN 4 s of log with flips starting at 1 s and 4 s (1 s of motion each)
  const auto dir = scratch_dir("frames");
  FlipSchedule sched;
  write_flip_log(dir / "run.csv", 4.0, 100.0, sched);
  LogFrameSource src(dir / "run.csv", poser_);
  // WHEN rendered at 20 frames/s in real time (scene only: the overlay text changes every frame)
  auto params = small_params(dir / "run.mp4");
  params.overlay = false;
  const auto stats = render_video(src, params);
  // THEN 80 frames of 192x144 at 20 frames/s reach the file
  EXPECT_FALSE(stats.png_fallback);
  EXPECT_EQ(stats.frames, 80u);
  const auto facts = probe(dir / "run.mp4");
  EXPECT_EQ(facts.frames, 80);
  EXPECT_EQ(facts.width, kW);
  EXPECT_EQ(facts.height, kH);
  EXPECT_NEAR(facts.fps, 20.0, 1e-9);
  const auto frames = decode(dir / "run.mp4", kW, kH);
  ASSERT_EQ(frames.size(), 80u);
  // no frame is blank or uniform
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_GT(pixel_stddev(frames[i]), 10.0) << "frame " << i;
  }

  // around platform 2 (it flips during 1..2 s): still during the standstill 0..1 s, changed
  // across the flip, still again during 2.2..3.9 s
  Sample s;
  s.plat1_deg = s.plat2_deg = 90.0;
  s.set_q_enu_from_body(Eigen::Quaterniond(
      Eigen::AngleAxisd(30.0 * kRadPerDeg, Eigen::Vector3d::UnitZ())));
  s.ref_p_enu_m.setZero();
  poser_.pose(s);
  const mjData* d = poser_.data();
  const int cam = mj_name2id(model_.get(), mjOBJ_CAMERA, "cam_fixed");
  const int body = mj_name2id(model_.get(), mjOBJ_BODY, "platform2");
  const auto [u, v] = project(model_.get(), d, cam, d->xpos + 3 * body, kW, kH);
  const int half = 20;
  ASSERT_GT(u - half, 0);
  ASSERT_LT(u + half, kW);
  ASSERT_GT(v - half, 0);
  ASSERT_LT(v + half, kH);
  auto diff = [&](int a, int b) {
    return mean_abs_diff(frames[a], frames[b], kW, u - half, v - half, 2 * half, 2 * half);
  };
  // frame k shows t = k / 20 s
  EXPECT_LT(diff(2, 18), 1.0) << "standstill 0.1..0.9 s";
  EXPECT_GT(diff(18, 42), 3.0) << "flip of platform 2 during 1..2 s";
  EXPECT_LT(diff(46, 78), 1.0) << "standstill 2.3..3.9 s";
}

TEST_F(RenderVideoTest, WithoutGlTheErrorIsClear) {
  // GIVEN a machine where no GL context can be made (forced)
  setenv(kNoGlEnv, "1", 1);
  const auto dir = scratch_dir("nogl");
  write_flip_log(dir / "run.csv", 0.5, 100.0, FlipSchedule{});
  LogFrameSource src(dir / "run.csv", poser_);
  // WHEN rendering THEN a GlUnavailable error says why, and no output appears
  try {
    render_video(src, small_params(dir / "run.mp4"));
    FAIL() << "expected GlUnavailable";
  } catch (const GlUnavailable& e) {
    EXPECT_NE(std::string(e.what()).find("no OpenGL context"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "run.mp4"));
  unsetenv(kNoGlEnv);
}

TEST_F(RenderVideoTest, WithoutFfmpegFramesBecomePngFiles) {
  // GIVEN no ffmpeg program
  setenv(kFfmpegEnv, "/nonexistent/ffmpeg", 1);
  const auto dir = scratch_dir("png");
  write_flip_log(dir / "run.csv", 0.5, 100.0, FlipSchedule{});
  LogFrameSource src(dir / "run.csv", poser_);
  // WHEN rendering 0.5 s at 20 frames/s
  const auto stats = render_video(src, small_params(dir / "run.mp4"));
  unsetenv(kFfmpegEnv);
  // THEN 10 numbered PNG files of the right size appear next to where the MP4 would be
  EXPECT_TRUE(stats.png_fallback);
  EXPECT_EQ(stats.frames, 10u);
  EXPECT_FALSE(std::filesystem::exists(dir / "run.mp4"));
  for (int i = 0; i < 10; ++i) {
    const auto f = dir / "run_frames" / fmt::format("frame_{:06d}.png", i);
    ASSERT_TRUE(std::filesystem::exists(f)) << f;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "run_frames" / "frame_000010.png"));
  const auto facts = probe(dir / "run_frames" / "frame_000009.png");
  EXPECT_EQ(facts.width, kW);
  EXPECT_EQ(facts.height, kH);
}

}  // namespace
}  // namespace driftless::render
