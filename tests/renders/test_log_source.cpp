// GIVEN a hardware-style log (platform angles empty while a platform moves) WHEN it is replayed
// THEN the overlay sees the gap as motion and the world is posed by interpolating across it.
#include <gtest/gtest.h>

#include "renders/render_job.hpp"
#include "tests/renders/render_fixture.hpp"

namespace driftless::render {
namespace {

TEST(LogFrameSource, InterpolatesPlatformAnglesAcrossGapsAndPosesTheBox) {
  const auto dir = testing::scratch_dir("log_source");
  {
    log::Metadata meta;
    meta.set("sample_rate_hz", "10");
    log::LogWriter w(dir / "hw.csv", meta, kFieldRefQ | kFieldRefP);
    for (int i = 0; i < 20; ++i) {
      Sample s;
      s.t_s = 0.1 * i;
      s.gyro1_dps.setZero();
      s.gyro2_dps.setZero();
      // platform 1 leaves +90 after t = 0.5 s and is read back at -90 from t = 1.0 s
      s.plat1_deg = s.t_s < 0.55 ? 90.0 : (s.t_s < 0.95 ? kNaN : -90.0);
      s.plat2_deg = 90.0;
      s.set_q_enu_from_body(
          Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ())));
      s.ref_p_enu_m = Eigen::Vector3d(1.0, 2.0, 3.0);
      w.write(s);
    }
    w.finish(true);
  }
  auto model = testing::load_model();
  BoxPoser poser(model.get());
  LogFrameSource src(dir / "hw.csv", poser);
  Sample raw, posed;
  std::vector<std::pair<double, double>> seen;  // (raw, posed) platform 1
  while (src.next(raw, posed)) seen.emplace_back(raw.plat1_deg, posed.plat1_deg);
  ASSERT_EQ(seen.size(), 20u);
  // the raw gap stays NaN (the overlay's tracker reads it as motion)
  for (int i = 6; i <= 9; ++i) EXPECT_TRUE(std::isnan(seen[i].first)) << i;
  // posed: linear in time from +90 at 0.5 s to -90 at 1.0 s
  for (int i = 6; i <= 9; ++i) {
    const double t = 0.1 * i;
    EXPECT_NEAR(seen[i].second, 90.0 - 180.0 * (t - 0.5) / 0.5, 1e-9) << i;
  }
  // posing puts the box at ref_p with attitude ref_q and the platform at its angle (rad)
  poser.pose(posed);
  const mjData* d = poser.data();
  const int box = mj_name2id(model.get(), mjOBJ_BODY, "box");
  EXPECT_NEAR(d->xpos[3 * box + 0], 1.0, 1e-12);
  EXPECT_NEAR(d->xpos[3 * box + 1], 2.0, 1e-12);
  EXPECT_NEAR(d->xpos[3 * box + 2], 3.0, 1e-12);
  // the log keeps 10 decimals of the quaternion
  EXPECT_NEAR(d->xquat[4 * box + 0], std::cos(0.25), 1e-9);
  EXPECT_NEAR(d->xquat[4 * box + 3], std::sin(0.25), 1e-9);
  const int j1 = mj_name2id(model.get(), mjOBJ_JOINT, "hinge1");
  EXPECT_NEAR(d->qpos[model->jnt_qposadr[j1]], -90.0 * kRadPerDeg, 1e-12);
}

}  // namespace
}  // namespace driftless::render
