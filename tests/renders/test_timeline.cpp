// The frame clock: real time, from/to windows, and the time-lapse rule that still shows flips
// in real time (docs/render.md). Pure logic, no GL.
#include <vector>

#include <gtest/gtest.h>

#include "renders/timeline.hpp"
#include "tests/renders/render_fixture.hpp"

namespace driftless::render {
namespace {

struct Frame {
  double t_s;        // frame time
  double held_t_s;   // time of the sample it shows
  bool realtime;
};

// runs the planner over samples at rate_hz for duration_s with the given flip schedule
std::vector<Frame> plan(const TimelineParams& p, double duration_s, double rate_hz,
                        const testing::FlipSchedule& sched, std::size_t* max_buffer = nullptr) {
  FramePlanner<double> planner(p);
  PlatformTracker tracker;
  std::vector<Frame> frames;
  auto emit = [&](const FrameInfo& f, const double& held) {
    EXPECT_EQ(f.index, frames.size());
    frames.push_back({f.t_s, held, f.realtime_flip});
  };
  const long n = static_cast<long>(std::llround(duration_s * rate_hz));
  for (long i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) / rate_hz;
    const auto [a1, a2] = sched.angles(t);
    const bool starts = tracker.update(t, a1, a2);
    if (!planner.push(t, starts, tracker.rest_duration_s(t), t, emit)) break;
    if (max_buffer != nullptr) *max_buffer = std::max(*max_buffer, planner.buffered());
  }
  planner.finish(emit);
  return frames;
}

TEST(Timeline, RealTimeGivesOneFramePerPeriodHoldingTheLatestSample) {
  TimelineParams p;
  p.fps = 30;
  const auto frames = plan(p, 2.0, 100.0, {});
  // samples 0 .. 1.99 s: frames at k/30 s for k/30 <= 1.99
  ASSERT_EQ(frames.size(), 60u);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    EXPECT_NEAR(frames[k].t_s, k / 30.0, 1e-12);
    // sample and hold: the latest sample at or before the frame time
    EXPECT_LE(frames[k].held_t_s, frames[k].t_s + 1e-9);
    EXPECT_GT(frames[k].held_t_s, frames[k].t_s - 0.01 - 1e-9);
    EXPECT_FALSE(frames[k].realtime);
  }
}

TEST(Timeline, FromToCutsAWindowAndSpeedScalesTheClock) {
  TimelineParams p;
  p.fps = 25;
  p.from_s = 1.0;
  p.to_s = 3.0;
  p.speed = 2.0;  // 2 s of data in 1 s of video: 25 frames
  testing::FlipSchedule none;
  none.first_flip_s = 1e9;
  const auto frames = plan(p, 10.0, 100.0, none);
  ASSERT_EQ(frames.size(), 25u);
  EXPECT_NEAR(frames.front().t_s, 1.0, 1e-12);
  EXPECT_NEAR(frames.back().t_s, 1.0 + 24 * 2.0 / 25, 1e-12);
  // slow motion: x0.5 repeats samples but never goes back in time
  p.speed = 0.5;
  p.to_s = 1.5;
  const auto slow = plan(p, 10.0, 100.0, none);
  ASSERT_EQ(slow.size(), 25u);
  for (std::size_t k = 1; k < slow.size(); ++k) EXPECT_GT(slow[k].t_s, slow[k - 1].t_s);
}

TEST(Timeline, TimeLapseShowsSelectedFlipsInRealTime) {
  // GIVEN 600 s of data with a 1 s flip every 10 s (first at 5 s)
  testing::FlipSchedule sched;
  sched.first_flip_s = 5.0;
  sched.period_s = 10.0;
  sched.flip_s = 1.0;
  TimelineParams p;
  p.fps = 10;
  p.speed = 20;                    // 2 s of data per frame
  p.realtime_flip_every_s = 95;    // the first flip at least 95 s after the last one shown
  std::size_t max_buffer = 0;
  const auto frames = plan(p, 600.0, 100.0, sched, &max_buffer);
  // THEN frames run forward in time, real-time runs cover flips starting at 5, 105, 205, ...
  std::vector<double> rt_starts;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    if (k > 0) {
      EXPECT_GT(frames[k].t_s, frames[k - 1].t_s) << k;
    }
    if (frames[k].realtime && (k == 0 || !frames[k - 1].realtime)) {
      rt_starts.push_back(frames[k].t_s);
    }
    if (k > 0 && frames[k].realtime && frames[k - 1].realtime) {
      EXPECT_NEAR(frames[k].t_s - frames[k - 1].t_s, 1.0 / p.fps, 1e-9);  // x1
    }
  }
  ASSERT_EQ(rt_starts.size(), 6u);
  for (std::size_t i = 0; i < rt_starts.size(); ++i) {
    // up to 0.5 s of lead-in before the flip (less when a time-lapse frame fell into it)
    const double flip_s = 5.0 + 100.0 * static_cast<double>(i);
    EXPECT_GE(rt_starts[i], flip_s - 0.5 - 1e-9) << i;
    EXPECT_LE(rt_starts[i], flip_s) << i;
  }
  // each real-time run spans the 1 s flip plus lead and tail: about 2 s, 20 frames
  std::size_t rt_frames = 0;
  for (const auto& f : frames) rt_frames += f.realtime ? 1 : 0;
  EXPECT_NEAR(static_cast<double>(rt_frames) / 6.0, 20.0, 2.0);
  // and the rest is time-lapse: 600 s at 2 s per frame, minus the real-time stretches
  EXPECT_NEAR(static_cast<double>(frames.size() - rt_frames), (600.0 - 6 * 2.0) / 2.0, 8.0);
  // memory stays bounded by one time-lapse step of samples (2 s at 100 Hz), not the run
  EXPECT_LE(max_buffer, 2u * 200u + 10u);
}

TEST(Timeline, DefaultRuleIsOneRealTimeFlipPerFiveVideoSeconds) {
  TimelineParams p;
  p.speed = 600;
  EXPECT_DOUBLE_EQ(p.realtime_flip_interval_s(), 3000.0);
  p.realtime_flip_every_s = 0;
  EXPECT_TRUE(std::isinf(p.realtime_flip_interval_s()));
}

TEST(Timeline, BadOptionsAreRefusedWithTheOptionName) {
  TimelineParams p;
  p.fps = 0;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = {};
  p.speed = -1;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = {};
  p.from_s = 5;
  p.to_s = 2;
  try {
    p.validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("--to"), std::string::npos);
  }
}

TEST(PlatformTracker, SeesFlipsFromAnglesAndFromEmptyAngles) {
  PlatformTracker tr;
  // angles at rest, then a hardware-style gap (NaN while moving), then rest at the other stop
  EXPECT_FALSE(tr.update(0.00, 90, 90));
  EXPECT_FALSE(tr.update(0.01, 90, 90));
  EXPECT_TRUE(tr.update(0.02, kNaN, 90));
  EXPECT_TRUE(tr.moving(0));
  EXPECT_FALSE(tr.moving(1));
  EXPECT_EQ(tr.last_flip_platform(), 0);
  EXPECT_FALSE(tr.update(0.50, -90, 90));
  EXPECT_FALSE(tr.any_moving());
  EXPECT_NEAR(tr.rest_duration_s(0.8), 0.3, 1e-12);
  // a second flip (platform 2, from angles) lets it predict the third
  EXPECT_TRUE(tr.update(3.02, -90, 80));
  EXPECT_EQ(tr.last_flip_platform(), 1);
  EXPECT_NEAR(tr.predicted_next_flip_s(), 6.02, 1e-12);
  EXPECT_EQ(tr.predicted_next_platform(), 0);
}

}  // namespace
}  // namespace driftless::render
