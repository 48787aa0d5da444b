// The one writer of log metadata: typed fields in, exact text out; a reader gets the same doubles.
#include <gtest/gtest.h>

#include <cmath>

#include "estimator/log.hpp"
#include "estimator/log_metadata.hpp"

namespace driftless::log {
namespace {

TEST(LogMetadata, HingeAxesAndNumbersRoundTripExactly) {
  // GIVEN a tilted hinge whose components need all 17 significant digits
  const Eigen::Vector3d axis = Eigen::Vector3d(0.1, std::sqrt(0.5), 1.0 / 3.0).normalized();
  LogInfo info;
  info.sample_rate_hz = 100.0;
  info.latitude_deg = 52.123456789012345;
  info.hinge1_axis = axis;
  info.hinge2_axis = Eigen::Vector3d::UnitX();
  // WHEN it is written and read back
  Metadata m;
  write_log_info(m, info);
  // THEN every double is the same (std::to_string kept 6 decimals: ~1e-7 off)
  EXPECT_EQ(m.hinge1_axis(), axis);
  EXPECT_EQ(m.latitude_deg(), info.latitude_deg);
  EXPECT_EQ(*m.get("sample_rate_hz"), "100");
  EXPECT_EQ(*m.get("hinge2_axis"), "1 0 0");
}

TEST(LogMetadata, WritesGivenFieldsInTheDocumentedOrderAndKeepsExistingPlaces) {
  Metadata m;
  m.set("latitude_deg", "0");  // an earlier writer's key keeps its place
  LogInfo info;
  info.sample_rate_hz = 200.0;
  info.latitude_deg = -33.5;
  info.source = "twin";
  info.seed = 42;
  info.duration_s = 0.0001;
  write_log_info(m, info);
  std::vector<std::string> keys;
  for (const auto& [k, v] : m.entries()) keys.push_back(k);
  EXPECT_EQ(keys, (std::vector<std::string>{"latitude_deg", "sample_rate_hz", "source", "seed", "duration_s"}));
  EXPECT_EQ(*m.get("latitude_deg"), "-33.5");
  EXPECT_EQ(*m.get("seed"), "42");
  EXPECT_EQ(*m.get("duration_s"), "0.0001");
  EXPECT_FALSE(m.has("scenario"));  // empty text is left out
  EXPECT_FALSE(m.has("hinge1_axis"));
}

TEST(LogMetadata, SettersWriteExactText) {
  Metadata m;
  set_number(m, "switch_at_s", 1.0 / 3.0);
  set_vector3(m, "v", Eigen::Vector3d(1e-20, -2.5, 1e16));
  EXPECT_EQ(*m.get("switch_at_s"), "0.3333333333333333");
  EXPECT_EQ(*m.get("v"), "1e-20 -2.5 1e+16");
  EXPECT_EQ(m.get_vector3("v", Eigen::Vector3d::Zero()), Eigen::Vector3d(1e-20, -2.5, 1e16));
}

}  // namespace
}  // namespace driftless::log
