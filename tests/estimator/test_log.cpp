// The measurement log: round trip, crash safety and clear errors on malformed files.
#include <sys/stat.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>

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

// GIVEN a log with accel, ref_q and temperature columns WHEN read parsing only the temperatures
// THEN fields() holds the parsed group, header_fields() every complete one (estimate's model choice
// asks whether gravity is logged before any pass parses the accel columns)
TEST(LogTest, HeaderFieldsNameTheGroupsPresentWhetherParsedOrNot) {
  const auto path = temp_file("header_fields.csv");
  Metadata meta;
  meta.set("sample_rate_hz", "100");
  {
    LogWriter w(path, meta, kFieldAccel | kFieldRefQ | kFieldTemp);
    for (int i = 0; i < 3; ++i) w.write(make_sample(0.01 * i));
    w.finish(true);
  }
  ReaderOptions temps;
  temps.fields = kFieldTemp;
  LogReader r(path, temps);
  EXPECT_EQ(r.fields(), kFieldTemp);
  EXPECT_EQ(r.header_fields(), kFieldAccel | kFieldRefQ | kFieldTemp);
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
  check("format.csv", "# format: other-log 3\n" + header,
        ":1: format: expected 'driftless-log 1', got 'other-log 3'");
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

// the one validation: each standard metadata key with a bad value is refused naming file, line, key
TEST(LogValidation, BadMetadataValuesNameFileLineAndKey) {
  const std::string header = "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n";
  const std::string row = "0,1,2,3,4,5,6,90,90\n";
  struct Case {
    const char* line;
    const char* expect;
  };
  const Case cases[] = {
      {"# sample_rate_hz: 0 0 1", "sample_rate_hz: expected a sample rate in Hz, > 0"},
      {"# sample_rate_hz: 0", "sample_rate_hz: "},
      {"# sample_rate_hz: -100", "sample_rate_hz: "},
      {"# sample_rate_hz: inf", "sample_rate_hz: "},
      {"# latitude_deg: 400", "latitude_deg: expected a latitude in deg within [-90, 90], got '400'"},
      {"# latitude_deg: nan", "latitude_deg: "},
      {"# hinge1_axis: nan", "hinge1_axis: expected three finite numbers 'x y z', not all zero"},
      {"# hinge2_axis: 0 0 0", "hinge2_axis: expected three finite numbers"},
      {"# hinge1_axis: 1 0", "hinge1_axis: "},
      {"# hinge1_axis: 1 0 0 1", "hinge1_axis: "},
      {"# gyro_full_scale_dps: 0", "gyro_full_scale_dps: "},
      {"# sensors: 3", "sensors: expected 1 (single-sensor form) or 2"},
      {"# complete: maybe", "complete: expected 'true' or 'false'"},
      {"# duration_s: -5", "duration_s: "},
  };
  int n = 0;
  for (const Case& c : cases) {
    const auto path = temp_file("meta" + std::to_string(n++) + ".csv");
    write_text(path, std::string("# format: driftless-log 1\n# source: test\n") + c.line + "\n" + header + row);
    const std::string msg = message_of([&] { LogReader r(path); });
    EXPECT_EQ(msg.rfind(path.string() + ":3: ", 0), 0u) << c.line << " -> " << msg;
    EXPECT_NE(msg.find(c.expect), std::string::npos) << c.line << " -> " << msg;
  }
}

TEST(LogValidation, RepeatedMetadataKeyNamesBothLines) {
  const auto path = temp_file("repeat.csv");
  write_text(path, "# format: driftless-log 1\n# latitude_deg: 52\n# source: a\n# latitude_deg: 10\n"
                   "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n");
  EXPECT_EQ(message_of([&] { LogReader r(path); }),
            path.string() + ":4: metadata key 'latitude_deg' repeats line 2 (each key once; see docs/log-format.md)");
}

TEST(LogValidation, GyroBeyondTheFullScaleIsRefusedWithItsLine) {
  const std::string head = "# format: driftless-log 1\n# complete: true\n";
  const std::string header = "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n";
  const auto path = temp_file("huge.csv");
  write_text(path, head + header + "0,1,2,3,4,5,6,90,90\n0.01,1,2,3,4,1e308,6,90,90\n");
  const std::string msg = message_of([&] {
    LogReader r(path);
    Sample s;
    while (r.next(s)) {
    }
  });
  EXPECT_EQ(msg.rfind(path.string() + ":5: column 'gyro2_y': 1e+308 deg/s is beyond 1.1 x the gyro full scale of "
                                      "4000 deg/s assumed without a gyro_full_scale_dps key",
                      0),
            0u)
      << msg;
  // a stated full scale: +-250 deg/s; 260 is a saturated reading within the margin, 300 is not
  const auto stated = temp_file("fs.csv");
  write_text(stated, head + "# gyro_full_scale_dps: 250\n" + header + "0,250.1298,2,3,4,5,6,90,90\n" +
                         "0.01,1,2,3,4,5,-260,90,90\n0.02,1,2,3,4,5,6,90,90\n");
  LogReader r(stated);
  Sample s;
  while (r.next(s)) {
  }
  EXPECT_EQ(r.rows_saturated(), 2u);
  write_text(stated, head + "# gyro_full_scale_dps: 250\n" + header + "0,300,2,3,4,5,6,90,90\n");
  EXPECT_NE(message_of([&] {
              LogReader r2(stated);
              Sample s2;
              r2.next(s2);
            }).find(":5: column 'gyro1_x': 300 deg/s is beyond 1.1 x the gyro full scale of 250 deg/s stated"),
            std::string::npos);
}

TEST(LogValidation, EachSensorsOwnFullScaleOverridesTheSharedOne) {
  // GIVEN two unlike gyros (P3): sensor 1 of +-250 deg/s, sensor 2 of +-2000 reading 600 deg/s
  const std::string head = "# format: driftless-log 1\n# complete: true\n# gyro_full_scale_dps: 250\n";
  const std::string header = "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n";
  const std::string rows = "0,1,2,250,4,600,6,90,90\n0.01,1,2,-250,4,5,2000,90,90\n0.02,1,2,3,4,5,6,90,90\n";
  const auto path = temp_file("unlike.csv");
  const auto read_all = [&](LogReader& r) {
    Sample s;
    while (r.next(s)) {
    }
  };
  // WHEN only the shared key says 250 THEN sensor 2's good reading is refused, the key named
  write_text(path, head + header + rows);
  EXPECT_NE(message_of([&] {
              LogReader r(path);
              read_all(r);
            }).find(":5: column 'gyro2_y': 600 deg/s is beyond 1.1 x the gyro full scale of 250 deg/s stated in "
                    "gyro_full_scale_dps"),
            std::string::npos);
  // WHEN gyro2_full_scale_dps says 2000 THEN every row is read; the saturated ones are sensor 1's two
  // rows at 250 and sensor 2's at 2000
  write_text(path, head + "# gyro2_full_scale_dps: 2000\n" + header + rows);
  LogReader r(path);
  read_all(r);
  EXPECT_EQ(r.rows_read(), 3u);
  EXPECT_EQ(r.rows_saturated(), 2u);
  EXPECT_EQ(r.metadata().gyro_full_scale_dps(1), 250.0);
  EXPECT_EQ(r.metadata().gyro_full_scale_dps(2), 2000.0);
  EXPECT_EQ(r.metadata().gyro_full_scale_key(2), "gyro2_full_scale_dps");
  // AND gyro1_full_scale_dps alone states sensor 1 only: sensor 2 keeps the 4000 deg/s bound
  write_text(path, std::string("# format: driftless-log 1\n# gyro1_full_scale_dps: 250\n") + header + rows);
  LogReader r1(path);
  read_all(r1);
  EXPECT_EQ(r1.rows_saturated(), 2u);
  EXPECT_TRUE(r1.metadata().gyro_full_scale_key(2).empty());
  EXPECT_EQ(r1.metadata().gyro_full_scale_dps(2), kDefaultGyroFullScaleDps);
}

TEST(LogValidation, TimeGapsAreReportedWithTheirLines) {
  const auto path = temp_file("gaps.csv");
  std::string text = "# format: driftless-log 1\n# sample_rate_hz: 100\n"
                     "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n";
  for (int i = 0; i < 5; ++i) text += std::to_string(0.01 * i) + ",0,0,0,0,0,0,90,90\n";
  text += "1000000000,0,0,0,0,0,0,90,90\n1000000000.5,0,0,0,0,0,0,90,90\n";  // 0.5 s: below 1 s
  write_text(path, text);
  LogReader r(path);
  Sample s;
  while (r.next(s)) {
  }
  EXPECT_DOUBLE_EQ(r.gap_threshold_s(), 1.0);  // max(1 s, 10 / 100 Hz)
  ASSERT_EQ(r.gap_count(), 1u);
  EXPECT_EQ(r.gaps()[0].line, 9u);
  EXPECT_NEAR(r.gaps()[0].t_before_s, 0.04, 1e-12);
  EXPECT_NEAR(r.gaps()[0].length_s, 1e9 - 0.04, 1e-3);
}

TEST(LogValidation, StampRateFromTheMedianAndTheMeanIntervalAgainstTheStatedRate) {
  // GIVEN stamps at 400 Hz under a 'sample_rate_hz: 100' line, every 7th row dropped and one 3 s gap
  const auto path = temp_file("stamp_rate.csv");
  std::string text = "# format: driftless-log 1\n# sample_rate_hz: 100\n"
                     "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n";
  int kept = 0, steps = 0, doubled = 0;  // gap-free intervals: 2.5 ms, or 5 ms over a dropped row
  for (int i = 0; i < 1000; ++i) {
    if (i % 7 == 3) continue;
    const double t = 0.0025 * i + (i >= 500 ? 3.0 : 0.0);
    text += std::to_string(t) + ",0,0,0,0,0,0,90,90\n";
    steps += kept > 0 && i != 500 && i != 501 ? 1 : 0;   // row 500 follows the gap (row 499 is kept)
    doubled += kept > 0 && i % 7 == 4 && i != 501 ? 1 : 0;
    ++kept;
  }
  write_text(path, text);
  LogReader r(path);
  Sample s;
  while (r.next(s)) {
  }
  ASSERT_EQ(r.rows_read(), static_cast<std::uint64_t>(kept));
  // THEN the median interval is the stamps' 2.5 ms (the drops do not move it), the mean one is
  // over the gap-free intervals (the gap left out), each 2.5 or 5 ms
  EXPECT_NEAR(r.stamp_rate_median_hz(), 400.0, 1e-3);
  EXPECT_NEAR(r.stamp_rate_mean_hz(), double(steps) / (0.0025 * (steps + doubled)), 1e-3);
  EXPECT_EQ(r.gap_count(), 1u);
}

TEST(LogValidation, ByteOrderMarkAndTextInUnknownColumnsAreAccepted) {
  const auto path = temp_file("bom.csv");
  write_text(path, "\xEF\xBB\xBFt,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg,note\n"
                   "0,1,2,3,4,5,6,90,90,standing still\n");
  LogReader r(path);
  Sample s;
  ASSERT_TRUE(r.next(s));
  EXPECT_EQ(s.gyro1_dps, Eigen::Vector3d(1, 2, 3));
  EXPECT_TRUE(std::isnan(r.value(r.column_index("note"))));
}

TEST(LogValidation, WriterRefusesInvalidMetadata) {
  Metadata meta;
  meta.set("latitude_deg", "400");
  const auto path = temp_file("writer_meta.csv");
  EXPECT_NE(message_of([&] { LogWriter w(path, meta, 0); }).find("latitude_deg: "), std::string::npos);
}

// a log of one gyro triad: written, read back by readers that accept it, refused by the others
TEST(LogSingleSensor, RoundTripAndRefusalByTwoSensorReaders) {
  const auto path = temp_file("single.csv");
  Metadata meta;
  meta.set("sample_rate_hz", "100");
  {
    LogWriter w(path, meta, kLayoutSingleSensor | kFieldAccel | kFieldTemp | kFieldRefQ);
    for (int i = 0; i < 3; ++i) w.write(make_sample(0.01 * i));
    w.finish(true);
  }
  std::ifstream in(path);
  std::string l1, l2, l3, l4, header;
  std::getline(in, l1);
  std::getline(in, l2);
  std::getline(in, l3);
  std::getline(in, l4);
  std::getline(in, header);
  EXPECT_EQ(l3, "# sensors: 1");
  EXPECT_EQ(header, "t,gyro1_x,gyro1_y,gyro1_z,plat1_deg,ref_qw,ref_qx,ref_qy,ref_qz,accel1_x,accel1_y,accel1_z,temp1");
  ReaderOptions single;
  single.accept_single_sensor = true;
  LogReader r(path, single);
  EXPECT_EQ(r.sensors(), 1);
  EXPECT_EQ(r.fields(), kLayoutSingleSensor | kFieldAccel | kFieldTemp | kFieldRefQ);
  Sample s;
  int n = 0;
  while (r.next(s)) {
    EXPECT_TRUE(s.gyro1_dps.allFinite());
    EXPECT_TRUE(std::isnan(s.gyro2_dps.x()));
    ++n;
  }
  EXPECT_EQ(n, 3);
  EXPECT_EQ(r.rows_with_missing_gyro(), 0u);
  EXPECT_NE(message_of([&] { LogReader two(path); })
                .find(path.string() + ":3: sensors: a single-sensor log ('sensors: 1'); this command needs both gyro triads"),
            std::string::npos);
}

TEST(LogSingleSensor, PlatformColumnIsOptionalAndSensorTwoColumnsAreRefused) {
  const auto path = temp_file("single_min.csv");
  write_text(path, "# sensors: 1\nt,gyro1_x,gyro1_y,gyro1_z\n0,1,2,3\n0.01,1,2,3\n");
  ReaderOptions single;
  single.accept_single_sensor = true;
  LogReader r(path, single);
  Sample s;
  ASSERT_TRUE(r.next(s));
  EXPECT_EQ(s.plat1_deg, 0.0);  // fixed to the box
  write_text(path, "# sensors: 1\nt,gyro1_x,gyro1_y,gyro1_z,gyro2_x\n0,1,2,3,4\n");
  EXPECT_NE(message_of([&] { LogReader r2(path, single); }).find(":2: column 'gyro2_x' in a single-sensor log"),
            std::string::npos);
}

// RAII: a constructor that throws leaks no descriptor
TEST(LogTest, RefusedHeadersLeakNoFileDescriptor) {
  auto open_fds = [] {
    std::size_t n = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator("/proc/self/fd")) ++n;
    return n;
  };
  const auto path = temp_file("leak.csv");
  write_text(path, "# format: driftless-log 1\nt,gyro1_x\n0,1\n");
  const std::size_t before = open_fds();
  for (int i = 0; i < 100; ++i) EXPECT_FALSE(message_of([&] { LogReader r(path); }).empty());
  EXPECT_EQ(open_fds(), before);
}

}  // namespace
}  // namespace driftless::log

namespace driftless::log {
namespace {

TEST(LogTest, ForeignRecordIsToldToConvertAndACutCompleteLogSaysWhy) {
  // GIVEN a recording another tool wrote (no '# format:' line, its own columns)
  const auto foreign = temp_file("foreign.csv");
  write_text(foreign, "time,gx,gy,gz\n0,1,2,3\n0.01,1,2,3\n");
  // THEN the refusal names the command that reads it
  const std::string msg = message_of([&] { LogReader r(foreign); });
  EXPECT_NE(msg.find("lacks required column(s)"), std::string::npos) << msg;
  EXPECT_NE(msg.find("driftless convert --in FILE --out LOG.csv"), std::string::npos) << msg;
  // GIVEN a driftless log missing a column: no such hint (it is a log)
  const auto own = temp_file("own.csv");
  write_text(own, "# format: driftless-log 1\nt,gyro1_x,gyro1_y\n0,1,2\n");
  EXPECT_EQ(message_of([&] { LogReader r(own); }).find("convert"), std::string::npos);
  // GIVEN a log that says complete: true but whose last row was cut mid-write (no line end)
  const auto cut = temp_file("cut_complete.csv");
  write_text(cut,
             "# format: driftless-log 1\n# complete: true\n"
             "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n"
             "0.00,1,2,3,4,5,6,90,90\n0.01,1,2,3,4,5");
  const std::string why = message_of([&] {
    LogReader r(cut);
    Sample s;
    while (r.next(s)) {
    }
  });
  // THEN the error names the line, and says it is the unterminated last line of a log claiming completeness
  EXPECT_NE(why.find(":5: expected 9 fields as in the header, got 6; it is the last line and has no line end"),
            std::string::npos) << why;
  EXPECT_NE(why.find("complete: true"), std::string::npos) << why;
}

// what a reader gives of a file: every row's t and gyro1_x, the events, and the error it ends on
struct ReadOut {
  std::vector<double> t, g;
  std::vector<std::string> events;
  std::string error;
  bool dropped_tail = false;
};

ReadOut read_out(const std::filesystem::path& p) {
  ReadOut o;
  LogReader r(p);
  o.error = message_of([&] {
    Sample s;
    while (r.next(s)) {
      o.t.push_back(s.t_s);
      o.g.push_back(s.gyro1_dps.x());
    }
  });
  for (const Event& e : r.events()) o.events.push_back(std::to_string(e.line) + " " + e.text);
  o.dropped_tail = r.dropped_truncated_row();
  return o;
}

// rows over several of the parse thread's batches (4096 rows), with events, blank lines and
// metadata-like comments among them, and a tail chosen by the caller
std::string long_log(const std::string& complete, const std::string& tail) {
  std::ostringstream os;
  os << "# format: driftless-log 1\n# complete: " << complete
     << "\nt,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg\n";
  for (int i = 0; i < 10000; ++i) {
    if (i % 4095 == 7) os << "# event: mark " << i << "\n\n";
    os << i * 0.01 << "," << (i % 97) * 0.125 << ",2,3,4,5,6,90,90\n";
  }
  os << tail;
  return os.str();
}

TEST(LogTest, TheParseThreadGivesTheRowsEventsAndErrorsOfAStreamReadInPlace) {
  // GIVEN long logs (a file is parsed on a thread of its own, a FIFO on the caller's) that end well,
  // on a malformed row, and on a row cut mid-write in an incomplete and in a complete log
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"true", ""},
      {"true", "100.5,1,2,x,4,5,6,90,90\n101,1,2,3,4,5,6,90,90\n"},
      {"false", "100.5,1,2,3,4,5,6,90,90\n100.51,1,2,3,4"},
      {"true", "100.5,1,2,3,4,5,6,90,90\n100.51,1,2,3,4"},
      {"true", "100.5,1,2,3,4,5,6,90,90\n99,1,2,3,4,5,6,90,90\n"},
  };
  int k = 0;
  for (const auto& [complete, tail] : cases) {
    const std::string text = long_log(complete, tail);
    const auto file = temp_file("threaded_" + std::to_string(k) + ".csv");
    write_text(file, text);
    const auto fifo = temp_file("stream_" + std::to_string(k++) + ".fifo");
    std::filesystem::remove(fifo);
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    std::thread writer([&] { write_text(fifo, text); });
    const ReadOut a = read_out(file), b = read_out(fifo);
    writer.join();
    // THEN both give the same rows, events (with their lines) and error (file:line apart from the name)
    EXPECT_EQ(a.t, b.t) << tail;
    EXPECT_EQ(a.g, b.g) << tail;
    EXPECT_EQ(a.events, b.events) << tail;
    EXPECT_EQ(a.dropped_tail, b.dropped_tail) << tail;
    const auto after_name = [](const std::string& e, const std::filesystem::path& p) {
      return e.empty() ? e : e.substr(e.find(p.filename().string()) + p.filename().string().size());
    };
    EXPECT_EQ(after_name(a.error, file), after_name(b.error, fifo)) << tail;
    ASSERT_GE(a.t.size(), 10000u);
    EXPECT_EQ(a.events.size(), 3u);
  }
  // and the cases end as the serial reader ended them
  const ReadOut bad = read_out(temp_file("threaded_1.csv"));
  EXPECT_NE(bad.error.find(":10010: column 'gyro1_z': expected a number, got 'x'"), std::string::npos) << bad.error;
  EXPECT_EQ(bad.t.size(), 10000u);
  const ReadOut cut = read_out(temp_file("threaded_2.csv"));
  EXPECT_TRUE(cut.error.empty()) << cut.error;
  EXPECT_TRUE(cut.dropped_tail);
  EXPECT_EQ(cut.t.size(), 10001u);
  EXPECT_NE(read_out(temp_file("threaded_3.csv")).error.find("has no line end"), std::string::npos);
  EXPECT_NE(read_out(temp_file("threaded_4.csv")).error.find(":10011: t = 99.000000 s is not greater"),
            std::string::npos);
}

TEST(LogTest, TheRefusedColumnsGroupIsKnown) {
  // GIVEN a value that is no number in an accel column, and one in a gyro column (required)
  const auto accel = temp_file("bad_accel.csv"), gyro = temp_file("bad_gyro.csv");
  const std::string head =
      "# format: driftless-log 1\nt,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg,"
      "accel1_x,accel1_y,accel1_z,accel2_x,accel2_y,accel2_z\n0,1,2,3,4,5,6,90,90,0,0,1,0,0,1\n";
  write_text(accel, head + "0.01,1,2,3,4,5,6,90,90,0,x,1,0,0,1\n");
  write_text(gyro, head + "0.01,1,2,y,4,5,6,90,90,0,0,1,0,0,1\n");
  for (const auto& [path, group] : {std::pair<std::filesystem::path, std::uint32_t>{accel, kFieldAccel}, {gyro, 0u}}) {
    LogReader r(path);
    Sample s;
    EXPECT_EQ(r.refused_group(), 0u);
    EXPECT_FALSE(message_of([&] {
                   while (r.next(s)) {
                   }
                 }).empty());
    // THEN the reader says which optional group it refused (none for a required column)
    EXPECT_EQ(r.refused_group(), group) << path;
  }
}

TEST(LogTest, AReaderLeftMidFileStopsItsParseThread) {
  // GIVEN a long log of which a caller reads a few rows only
  const auto file = temp_file("left_mid_file.csv");
  std::string text = long_log("true", "");
  for (int i = 0; i < 3; ++i) text += text.substr(text.find("0,0,2"));  // t stops rising: never reached
  write_text(file, text);
  const auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < 50; ++i) {
    LogReader r(file);
    Sample s;
    for (int j = 0; j < 5000 && r.next(s); ++j) {
    }
  }
  // THEN the readers go away at once (their threads stopped, not run to the end or left blocked)
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 20.0);
}

}  // namespace
}  // namespace driftless::log
