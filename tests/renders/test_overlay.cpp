// GIVEN the overlay's inputs WHEN its text, chart axes and frame layout are made THEN ticks are
// round, axes fit the data (never a blown-up flat line), flips say where they go, no next flip is
// promised past the end, the attitude error waits for lock, and text fits its box.
#include <gtest/gtest.h>

#include "renders/chart.hpp"
#include "renders/overlay.hpp"
#include "renders/scene_renderer.hpp"

namespace driftless::render {
namespace {

TEST(Chart, TicksAreRoundStepsInsideTheRange) {
  const Ticks t = round_ticks(-6.3, 13.0, 5);
  EXPECT_EQ(t.step, 5.0);
  EXPECT_EQ(t.values, (std::vector<double>{-5.0, 0.0, 5.0, 10.0}));
  EXPECT_EQ(t.decimals, 0);
  const Ticks u = round_ticks(0.0012, 0.0047, 4);
  EXPECT_DOUBLE_EQ(u.step, 0.001);
  EXPECT_EQ(u.values.size(), 3u);  // 0.002, 0.003, 0.004
  EXPECT_EQ(u.decimals, 3);
  const Ticks w = round_ticks(20.0, 20.7, 4);  // a short time axis
  EXPECT_DOUBLE_EQ(w.step, 0.2);
  EXPECT_EQ(w.decimals, 1);
  for (double v : w.values) EXPECT_TRUE(v >= 20.0 && v <= 20.7) << v;
}

TEST(Chart, ValueAxisKeepsAMinimumSpanAndItsSide) {
  // a flat line at 3.5 deg/s with 5e-6 of noise is not blown up to a +-5e-6 axis
  const AxisRange a = value_axis(3.499998, 3.500003, 0.02, 5);
  EXPECT_GE(a.hi - a.lo, 0.02 - 1e-12);
  EXPECT_LE(a.lo, 3.499998);
  EXPECT_GE(a.hi, 3.500003);
  // a non-negative error angle keeps its axis at or above zero, ending on ticks
  const AxisRange b = value_axis(0.0, 118.2, 0.1, 5);
  EXPECT_EQ(b.lo, 0.0);
  EXPECT_GE(b.hi, 118.2);
  EXPECT_NEAR(std::remainder(b.hi, b.ticks.step), 0.0, 1e-9);
}

TEST(Chart, TextIsCutToFitItsWidth) {
  mjrContext con;
  mjr_defaultContext(&con);
  for (int& w : con.charWidth) w = 7;
  EXPECT_EQ(text_width_px("abcd", con), 28);
  EXPECT_EQ(fit_text("abcd", 28, con), "abcd");
  const std::string cut = fit_text("sensor 1 bias estimate, deg/s", 70, con);
  EXPECT_LE(text_width_px(cut, con), 70);
  EXPECT_EQ(cut.substr(cut.size() - 2), "..");
}

TEST(Chart, StripChartTimeAxisStartsAtItsFirstPoint) {
  StripChart c("t", {{"a", {1, 0, 0}}}, {}, 30.0, 1.0);
  EXPECT_TRUE(c.empty());
  EXPECT_TRUE(std::isnan(c.first_t_s()));
  c.push(12.5, {1.0});
  c.push(13.0, {kNaN});  // NaN leaves the line alone
  c.push(50.0, {2.0});
  EXPECT_EQ(c.first_t_s(), 12.5);
  EXPECT_EQ(c.points(0, 50.0).size(), 1u);  // 12.5 slid out of the 30 s window
}

OverlayState flipping(double from_deg, double now_deg) {
  OverlayState st;
  st.plat_deg[1] = now_deg;
  st.moving[1] = true;
  st.flip_from_deg[1] = from_deg;
  st.plat_deg[0] = 90.0;
  return st;
}

TEST(Overlay, AFlipSaysWhereItComesFromAndGoes) {
  EXPECT_EQ(platform_text(flipping(-90.0, -12.3), 1), "-90 -> +90 deg, moving (now -12)");
  EXPECT_EQ(platform_text(flipping(90.0, 45.0), 1), "+90 -> -90 deg, moving (now +45)");
  EXPECT_EQ(platform_text(flipping(-90.0, 10.0), 0), "+90 deg, at rest");
  EXPECT_EQ(platform_text(flipping(kNaN, kNaN), 1), "moving");  // hardware: empty while moving
}

TEST(Overlay, NoNextFlipPastTheEndAndNoAttitudeErrorBeforeLock) {
  OverlayState st = flipping(-90.0, 0.0);
  st.next_flip_s = 604.6;
  st.next_platform = 0;
  st.attitude.available = true;
  PlayState play;
  play.t_s = 590.0;
  play.speed = 10.0;
  play.end_s = 600.0;
  auto rows = overlay_rows(play, st);
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[3].title, "next flip");
  EXPECT_EQ(rows[3].value, "none before the end (600 s)");
  EXPECT_EQ(rows[4].value.substr(0, 1), "-");  // a dash until the filter locks
  EXPECT_EQ(rows[4].value.find("deg"), std::string::npos);
  st.attitude.started = true;
  st.attitude.start_s = 63.3;
  st.attitude.corrected_deg = 1.734;
  play.end_s = 700.0;
  rows = overlay_rows(play, st);
  EXPECT_EQ(rows[3].value, "~604.6 s, platform 1");
  EXPECT_EQ(rows[4].value, "1.73 deg since lock at 63.3 s");
}

TEST(Overlay, LayoutGivesTheViewMostOfTheFrameAndDropsWhatDoesNotFit) {
  const FrameLayout l = frame_layout(640, 480, 5, 19, 3);
  EXPECT_EQ(l.charts.size(), 3u);
  EXPECT_EQ(l.scene.left, 0);
  EXPECT_EQ(l.scene.bottom, 0);
  EXPECT_GE(l.scene.width, 400);
  EXPECT_GE(l.scene.height, 360);  // the text band takes the rest
  EXPECT_EQ(l.text.bottom, l.scene.height);
  EXPECT_EQ(l.column.left, l.scene.width);
  for (const auto& c : l.charts) {
    EXPECT_GE(c.width, kMinChartWidthPx);
    EXPECT_GE(c.bottom, 0);
    EXPECT_LE(c.bottom + c.height, l.title.bottom);
  }
  // a small frame shows the world only: the overlay would not be readable
  const FrameLayout s = frame_layout(192, 144, 5, 11, 3);
  EXPECT_TRUE(s.charts.empty());
  EXPECT_EQ(s.text.height, 0);
  EXPECT_EQ(s.scene.width, 192);
  EXPECT_EQ(s.scene.height, 144);
}

}  // namespace
}  // namespace driftless::render
