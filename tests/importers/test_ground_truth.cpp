// Ground truth joined onto IMU stamps (`driftless convert --ref`): the EuRoC / Vicon layout read with
// its ns stamps whole, slerp against the closed form of a constant-rate rotation, the span and gaps,
// and damaged files named by line.
#include <cmath>
#include <cstdio>
#include <string>

#include <gtest/gtest.h>

#include "import_fixture.hpp"
#include "importers/ground_truth.hpp"

namespace driftless::importers::test {
namespace {

constexpr std::int64_t kEpochS = 1403636579;
constexpr double kRateRadps = 0.2;  // rad/s about z

// q_ref_from_body of a rotation about z by kRateRadps * t (t in s since the epoch)
Eigen::Quaterniond truth_at(double t_s) { return Eigen::Quaterniond(Eigen::AngleAxisd(kRateRadps * t_s, Eigen::Vector3d::UnitZ())); }

// a EuRoC ground truth at 200 Hz from 0.5 s after the epoch, with a 0.2 s dropout after row 50
std::string euroc_ground_truth(int rows) {
  std::string s = "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z [], "
                  "v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1]\n";
  for (int j = 0; j < rows; ++j) {
    const std::int64_t ns = 500'000'000LL + 5'000'000LL * j + (j > 50 ? 200'000'000LL : 0);
    const double t = 1e-9 * static_cast<double>(ns);
    const Eigen::Quaterniond q = truth_at(t);
    char line[256];
    std::snprintf(line, sizeof line, "%lld,%.9f,0,1.5,%.17g,%.17g,%.17g,%.17g,0,0,0\n",
                  static_cast<long long>(kEpochS * 1'000'000'000LL + ns), 2.0 * t, q.w(), q.x(), q.y(), q.z());
    s += line;
  }
  return s;
}

TEST(GroundTruth, SlerpOntoImuStampsMatchesTheClosedFormAndKnowsSpanAndGaps) {
  // GIVEN a ground truth of a constant-rate rotation with one dropout
  const auto dir = scratch("ground_truth");
  write_text(dir / "data.csv", euroc_ground_truth(200));
  const GroundTruth gt = read_ground_truth(dir / "data.csv");
  ASSERT_EQ(gt.poses.size(), 200u);
  EXPECT_EQ(gt.poses[0].t_ns, kEpochS * 1'000'000'000LL + 500'000'000LL);  // the ns stamp kept whole
  EXPECT_EQ(gt.median_step_ns, 5'000'000);
  // WHEN poses are looked up at IMU times between its stamps (s since the IMU's epoch)
  PoseInterpolator at(gt, kEpochS, 10 * gt.median_step_ns);
  EXPECT_DOUBLE_EQ(at.first_s(), 0.5);
  // THEN slerp gives the rotation of the closed form (exact for a constant axis and rate), and the
  // position its linear interpolation
  for (double t = 0.5; t < 0.75; t += 0.0031) {
    const PoseAt p = at.at(t);
    ASSERT_EQ(p.where, PoseAt::Where::kInside) << t;
    EXPECT_LT(p.q_ref_from_body.angularDistance(truth_at(t)), 1e-12) << t;
    EXPECT_NEAR(p.p_ref_m.x(), 2.0 * t, 1e-9) << t;
  }
  // before the first stamp, inside the dropout, after the last: said, not invented
  EXPECT_EQ(at.at(0.4999).where, PoseAt::Where::kBefore);
  EXPECT_EQ(at.at(0.85).where, PoseAt::Where::kGap);
  EXPECT_EQ(at.at(0.5 + 0.005 * 199 + 0.2 + 1e-3).where, PoseAt::Where::kAfter);
  // and a lookup going back in time finds its bracket again
  EXPECT_LT(at.at(0.6).q_ref_from_body.angularDistance(truth_at(0.6)), 1e-12);
}

TEST(GroundTruth, DamagedFilesAreRefusedWithTheirLine) {
  const auto dir = scratch("ground_truth_bad");
  auto refused = [&](const std::string& name, const std::string& text, const std::string& expected) {
    write_text(dir / name, text);
    try {
      read_ground_truth(dir / name);
      ADD_FAILURE() << name << " accepted";
    } catch (const ImportError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  const std::string head = "#timestamp [ns],px,py,pz,qw,qx,qy,qz\n";
  refused("nohead.csv", "t,px,py,pz,qw,qx,qy,qz\n", "nohead.csv:1: expected the header #timestamp");
  refused("back.csv", head + "2000,0,0,0,1,0,0,0\n1000,0,0,0,1,0,0,0\n", "back.csv:3: timestamp 1000 ns does not increase");
  refused("norm.csv", head + "1000,0,0,0,1,0,0,0\n2000,0,0,0,0.1,0,0,0\n", "norm.csv:3: quaternion norm");
  refused("short.csv", head + "1000,0,0,0,1,0,0\n", "short.csv:2: expected at least 8 fields");
  refused("junk.csv", head + "1000,0,0,x,1,0,0,0\n", "junk.csv:2: column 4: expected a number, got 'x'");
  refused("one.csv", head + "1000,0,0,0,1,0,0,0\n", "at least 2 rows");
}

}  // namespace
}  // namespace driftless::importers::test

namespace driftless::importers::test {
namespace {

TEST(GroundTruth, QuaternionOrderComesFromTheHeaderNames) {
  const auto dir = scratch("ground_truth_order");
  // GIVEN the same 30 deg turn about z written scalar first (EuRoC) and scalar last (many tools: x y z w)
  const double c = std::cos(M_PI / 12.0), s = std::sin(M_PI / 12.0);
  const Eigen::Quaterniond truth(c, 0.0, 0.0, s);
  char row[160];
  std::snprintf(row, sizeof row, "1000,1,2,3,%.17g,0,0,%.17g\n2000,1,2,3,%.17g,0,0,%.17g\n", c, s, c, s);
  write_text(dir / "wxyz.csv", std::string("#timestamp [ns],p_x [m],p_y [m],p_z [m],q_w [],q_x [],q_y [],q_z []\n") + row);
  std::snprintf(row, sizeof row, "1000,1,2,3,0,0,%.17g,%.17g\n2000,1,2,3,0,0,%.17g,%.17g\n", s, c, s, c);
  write_text(dir / "xyzw.csv", std::string("#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_x [], q_RS_y [], "
                                           "q_RS_z [], q_RS_w []\n") + row);
  // THEN both read as the same rotation, and the order read is said
  const GroundTruth a = read_ground_truth(dir / "wxyz.csv"), b = read_ground_truth(dir / "xyzw.csv");
  EXPECT_EQ(a.quaternion_order, "w x y z");
  EXPECT_EQ(b.quaternion_order, "x y z w");
  EXPECT_LT(a.poses[0].q_ref_from_body.angularDistance(truth), 1e-12);
  EXPECT_LT(b.poses[0].q_ref_from_body.angularDistance(truth), 1e-12);
  EXPECT_EQ(b.poses[1].p_ref_m, Eigen::Vector3d(1, 2, 3));
  // GIVEN names that do not spell an order (no axis letters, or one twice): EuRoC's w x y z
  write_text(dir / "plain.csv", std::string("#timestamp,a,b,c,d,e,f,g\n") + "1000,0,0,0,1,0,0,0\n2000,0,0,0,1,0,0,0\n");
  EXPECT_EQ(read_ground_truth(dir / "plain.csv").quaternion_order, "w x y z");
  write_text(dir / "twice.csv", std::string("#timestamp,px,py,pz,qx,qx,qy,qz\n") + "1000,0,0,0,1,0,0,0\n2000,0,0,0,1,0,0,0\n");
  EXPECT_EQ(read_ground_truth(dir / "twice.csv").quaternion_order, "w x y z");
}

}  // namespace
}  // namespace driftless::importers::test

