// The measurement log: round trip, crash safety and clear errors on malformed files.
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "estimator/log.hpp"

#include "tests/temp_path.hpp"

namespace driftless::log {
namespace {

std::filesystem::path temp_file(const std::string& name) {
  auto dir = test::temp_path("driftless_test_log");
  std::filesystem::create_directories(dir);
  return dir / (name + "_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()));
}

void write_text(const std::filesystem::path& p, const std::string& text) {
  std::ofstream(p, std::ios::binary) << text;
}

Sample make_sample(double t) {
  Sample s;
  s.t_s = t;
  s.gyro1_dps = Eigen::Vector3d(0.1 * t, -0.25, 1.0 / 131.0);
  s.gyro2_dps = Eigen::Vector3d(-4.5, 0.0, 2.0);
  s.plat1_deg = 90.0;
  s.plat2_deg = t > 0.05 ? kNaN : -90.0;
  s.set_q_enu_from_body(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())));
  s.temp1_c = 25.125;
  s.temp2_c = 26.0;
  s.true_bias1_dps = Eigen::Vector3d(0.01, 0.02, 0.03);
  s.true_bias2_dps = Eigen::Vector3d(-0.01, -0.02, -0.03);
  return s;
}

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

TEST(LogTest, RoundTripKeepsValuesAtTheirWrittenPrecision) {
  const auto path = temp_file("roundtrip.csv");
  Metadata meta;
  meta.set("sample_rate_hz", "100");
  meta.set("latitude_deg", "52.0");
  {
    LogWriter w(path, meta, kFieldRefQ | kFieldTemp | kFieldTrueBias);
    for (int i = 0; i < 10; ++i) w.write(make_sample(0.01 * i));
    w.event(0.095, "switch twin -> replay");
    w.finish(true);
  }
  LogReader r(path);
  EXPECT_TRUE(r.metadata().complete());
  EXPECT_DOUBLE_EQ(r.metadata().sample_rate_hz(), 100.0);
  EXPECT_DOUBLE_EQ(r.metadata().latitude_deg(), 52.0);
  EXPECT_EQ(r.fields(), kFieldRefQ | kFieldTemp | kFieldTrueBias);
  Sample s;
  int n = 0;
  while (r.next(s)) {
    const Sample e = make_sample(0.01 * n);
    EXPECT_NEAR(s.t_s, e.t_s, 1e-9);
    EXPECT_TRUE(s.gyro1_dps.isApprox(e.gyro1_dps, 1e-6));
    EXPECT_NEAR(s.gyro1_dps.z(), 1.0 / 131.0, 5e-8);
    EXPECT_NEAR(s.plat1_deg, 90.0, 1e-12);
    EXPECT_EQ(std::isnan(s.plat2_deg), std::isnan(e.plat2_deg));
    EXPECT_NEAR(s.ref_q_wxyz[3], e.ref_q_wxyz[3], 1e-10);
    EXPECT_NEAR(s.true_bias2_dps.z(), -0.03, 1e-12);
    EXPECT_TRUE(std::isnan(s.accel1_mps2.x()));  // not in the file
    ++n;
  }
  EXPECT_EQ(n, 10);
  ASSERT_EQ(r.events().size(), 1u);
  EXPECT_EQ(r.events()[0].text, "t=0.095000 switch twin -> replay");
}

TEST(LogTest, SameSamplesGiveByteIdenticalFiles) {
  const auto a = temp_file("det_a.csv");
  const auto b = temp_file("det_b.csv");
  for (const auto& p : {a, b}) {
    LogWriter w(p, Metadata{}, kFieldTemp);
    for (int i = 0; i < 100; ++i) w.write(make_sample(0.01 * i));
    w.finish(true);
  }
  std::ifstream fa(a, std::ios::binary), fb(b, std::ios::binary);
  const std::string sa((std::istreambuf_iterator<char>(fa)), {});
  const std::string sb((std::istreambuf_iterator<char>(fb)), {});
  EXPECT_EQ(sa, sb);
  EXPECT_NE(sa.find("# complete: true "), std::string::npos);
}

TEST(LogTest, UnfinishedWriterLeavesAnIncompleteButValidLog) {
  const auto path = temp_file("unfinished.csv");
  {
    LogWriter w(path, Metadata{}, 0);
    for (int i = 0; i < 5; ++i) w.write(make_sample(0.01 * i));
    // destroyed without finish(): as after an exception unwinding the run
  }
  LogReader r(path);
  EXPECT_FALSE(r.metadata().complete());
  Sample s;
  int n = 0;
  while (r.next(s)) ++n;
  EXPECT_EQ(n, 5);
  // the trailer says why; it is read once the reader reaches the end
  EXPECT_EQ(r.metadata().get("incomplete_reason").value_or(""),
            "writer closed before the run finished");
}

TEST(LogTest, RowCutOffMidWriteIsDroppedFromAnIncompleteLog) {
  const auto path = temp_file("cut.csv");
  write_text(path,
             "# format: driftless-log 1\n# complete: false\n"
             "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n"
             "0.00,1,2,3,4,5,6,90,90\n0.01,1,2,3,4,5,6,90,90\n0.02,1,2,3,4,5");
  LogReader r(path);
  Sample s;
  int n = 0;
  while (r.next(s)) ++n;
  EXPECT_EQ(n, 2);
  EXPECT_TRUE(r.dropped_truncated_row());
}

TEST(LogTest, CompleteLogWithAShortRowIsAnErrorNamingFileAndLine) {
  const auto path = temp_file("short.csv");
  write_text(path,
             "# format: driftless-log 1\n# complete: true\n"
             "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n"
             "0.00,1,2,3,4,5,6,90,90\n0.01,1,2,3,4,5\n");
  const std::string msg = message_of([&] {
    LogReader r(path);
    Sample s;
    while (r.next(s)) {
    }
  });
  EXPECT_NE(msg.find(path.string() + ":5:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("expected 9 fields"), std::string::npos) << msg;
}

TEST(LogTest, ColumnsInAnyOrderAndUnknownColumnsIgnored) {
  const auto path = temp_file("order.csv");
  write_text(path,
             "# format: driftless-log 1\n# complete: true\n"
             "plat2_deg,my_extra,gyro2_z,gyro2_y,gyro2_x,gyro1_z,gyro1_y,gyro1_x,plat1_deg,t\n"
             "-90,7,6,5,4,3,2,1,90,0.5\n");
  LogReader r(path);
  Sample s;
  ASSERT_TRUE(r.next(s));
  EXPECT_EQ(s.gyro1_dps, Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s.gyro2_dps, Eigen::Vector3d(4, 5, 6));
  EXPECT_EQ(s.t_s, 0.5);
  EXPECT_EQ(r.value(r.column_index("my_extra")), 7.0);
}

TEST(LogTest, BadInputGetsClearMessages) {
  const std::string header = "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n";
  auto check = [&](const std::string& name, const std::string& text, const std::string& expect) {
    const auto path = temp_file(name);
    write_text(path, text);
    const std::string msg = message_of([&] {
      LogReader r(path);
      Sample s;
      while (r.next(s)) {
      }
    });
    EXPECT_NE(msg.find(expect), std::string::npos) << name << ": " << msg;
    EXPECT_NE(msg.find(path.string()), std::string::npos) << name << ": " << msg;
  };
  check("empty.csv", "", "empty file");
  check("missing.csv", "# format: driftless-log 1\nt,gyro1_x,gyro1_y\n0,1,2\n",
        "lacks required column(s) gyro1_z, gyro2_x");
  check("time.csv", "# format: driftless-log 1\n" + header + "1,0,0,0,0,0,0,90,90\n1,0,0,0,0,0,0,90,90\n",
        ":4: t = 1.000000 s is not greater");
  check("junk.csv", "# format: driftless-log 1\n" + header + "0,abc,0,0,0,0,0,90,90\n",
        "column 'gyro1_x': expected a number, got 'abc'");
  check("format.csv", "# format: other-log 3\n" + header, "unsupported format 'other-log 3'");
  check("nofile.csv", "", "empty file");
  EXPECT_NE(message_of([] { LogReader r("/nonexistent/x.csv"); }).find("no such file"),
            std::string::npos);
}

TEST(LogTest, NanGyroRowsAreReturnedAndCounted) {
  const auto path = temp_file("nan.csv");
  write_text(path,
             "# format: driftless-log 1\n# complete: true\n"
             "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n"
             "0.00,1,2,3,4,5,6,90,90\n0.01,nan,2,3,4,5,6,90,90\n0.02,1,2,,4,5,6,90,\n");
  LogReader r(path);
  Sample s;
  int n = 0;
  while (r.next(s)) ++n;
  EXPECT_EQ(n, 3);
  EXPECT_EQ(r.rows_with_missing_gyro(), 2u);
}

}  // namespace
}  // namespace driftless::log
