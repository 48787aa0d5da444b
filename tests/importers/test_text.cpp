// Delimited text: the real recordings of both folders, headers or none, separators, units and time
// bases detected, columns by name or index, and bad files named by file:line.
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <tuple>

#include <gtest/gtest.h>

#include "import_fixture.hpp"

namespace driftless::importers::test {
namespace {

constexpr double kDegPerRad = 57.295779513082320876798;
constexpr double kG = 9.80665;

bool says(const ImuReader& r, const std::string& what) {
  for (const auto& a : r.info().assumptions) {
    if (a.find(what) != std::string::npos) return true;
  }
  return false;
}

// Opening `file` with `o` throws an ImportError whose text holds `expected`.
void expect_refused(const std::filesystem::path& file, const ImportOptions& o, const std::string& expected) {
  try {
    open_imu(file, o);
    ADD_FAILURE() << "accepted: " << expected;
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
  }
}

int channel(const ImuReader& r, const std::string& name) {
  for (std::size_t c = 0; c < r.info().channels.size(); ++c) {
    if (r.info().channels[c].name == name) return static_cast<int>(c);
  }
  return -1;
}

TEST(TextImport, SunsidedRecordingIsReadWithItsHeaderUnitsAndTime) {
  DRIFTLESS_NEED_REALDATA();
  // GIVEN the real 10-min MPU6050 recording (header sec,acc_*,gyro_*,temp; deg/s and g)
  const Csv csv = plain_csv(sunsided_10min());
  // WHEN it is opened with everything detected
  auto r = open_imu(sunsided_10min(), {});
  const Table t = read_all(*r, 4096);
  // THEN it is text with time, three gyro, three accel and one temperature channel
  EXPECT_EQ(r->info().format, Format::kText);
  EXPECT_TRUE(r->info().has_time);
  ASSERT_EQ(t.t.size(), csv.rows.size());
  const int gx = channel(*r, "gyro_x"), az = channel(*r, "acc_z"), temp = channel(*r, "temp");
  ASSERT_GE(gx, 0);
  ASSERT_GE(az, 0);
  ASSERT_GE(temp, 0);
  EXPECT_EQ(r->info().channels[static_cast<std::size_t>(temp)].quantity, Quantity::kTemperature);
  EXPECT_TRUE(says(*r, "rates in deg/s"));
  EXPECT_TRUE(says(*r, "accelerations in g"));
  for (std::size_t i = 0; i < csv.rows.size(); i += 997) {
    EXPECT_DOUBLE_EQ(t.t[i], csv.rows[i][0]);
    EXPECT_DOUBLE_EQ(t.ch[static_cast<std::size_t>(gx)][i], csv.rows[i][4]);
    EXPECT_NEAR(t.ch[static_cast<std::size_t>(az)][i], csv.rows[i][3] * kG, 1e-12);
    EXPECT_EQ(t.loc[i], i + 2);  // line numbers: the header is line 1
  }
}

TEST(TextImport, TomisuarezRawCountsWithRatePreambleAreDetected) {
  DRIFTLESS_NEED_REALDATA();
  // GIVEN 'Fs,100', settings lines, a header ax..gz and raw counts (131 LSB per deg/s)
  auto r = open_imu(tomisuarez_static(), {});
  const Table t = read_all(*r);
  // THEN the rate comes from the preamble, the counts are scaled, and there is no time column
  EXPECT_DOUBLE_EQ(r->info().nominal_rate_hz, 100.0);
  EXPECT_FALSE(r->info().has_time);
  EXPECT_TRUE(says(*r, "131 LSB per deg/s"));
  const int gx = channel(*r, "gx");
  ASSERT_GE(gx, 0);
  EXPECT_DOUBLE_EQ(t.ch[static_cast<std::size_t>(gx)][0], -480.0 / 131.0);  // the first data row's gx
  EXPECT_EQ(t.loc[0], 6u);
  // the static bias about -3.34 deg/s (the folder's README)
  double mean = 0.0;
  for (double v : t.ch[static_cast<std::size_t>(gx)]) mean += v;
  EXPECT_NEAR(mean / static_cast<double>(t.t.size()), -3.34, 0.1);
}

TEST(TextImport, HeaderlessBlankSeparatedSiFileTakesTimeGyroAccel) {
  DRIFTLESS_NEED_REALDATA();
  // GIVEN the real data rewritten as "time wx wy wz ax ay az", blank-separated, rad/s and m/s^2
  const Csv csv = plain_csv(sunsided_10min());
  const auto dir = scratch("headerless");
  std::string s;
  for (std::size_t i = 0; i < 2000; ++i) {
    const auto& r = csv.rows[i];
    s += std::to_string(r[0]) + "  " + std::to_string(r[4] / kDegPerRad) + " " + std::to_string(r[5] / kDegPerRad) + "\t" +
         std::to_string(r[6] / kDegPerRad) + " " + std::to_string(r[1] * kG) + " " + std::to_string(r[2] * kG) + " " +
         std::to_string(r[3] * kG) + "\n";
  }
  write_text(dir / "imu.txt", s);
  auto r = open_imu(dir / "imu.txt", {});
  const Table t = read_all(*r);
  // THEN column 1 is time, 2-4 gyro in rad/s (an SI file: the accelerometer reads g in m/s^2)
  EXPECT_TRUE(says(*r, "no header"));
  EXPECT_TRUE(says(*r, "SI file"));
  ASSERT_EQ(r->info().channels.size(), 6u);
  EXPECT_EQ(r->info().channels[0].quantity, Quantity::kRate);
  EXPECT_EQ(r->info().channels[3].quantity, Quantity::kAccel);
  EXPECT_NEAR(t.ch[0][10], csv.rows[10][4], 1e-4);  // deg/s again (6 printed digits)
}

TEST(TextImport, AccelerometerFirstIsRecognisedByGravity) {
  // GIVEN "t ax ay az gx gy gz" without header, accel in m/s^2 reading gravity on z
  const auto dir = scratch("accel_first");
  std::string s;
  for (int i = 0; i < 300; ++i) {
    s += std::to_string(0.01 * i) + " 0.01 -0.02 9.81 " + std::to_string(0.001 * (i % 7)) + " 0.002 -0.001\n";
  }
  write_text(dir / "imu.txt", s);
  auto r = open_imu(dir / "imu.txt", {});
  // THEN the first triad is taken as the accelerometer and the reader says so
  EXPECT_TRUE(says(*r, "accelerometer first"));
  EXPECT_EQ(r->info().channels[0].quantity, Quantity::kAccel);
  EXPECT_EQ(r->info().channels[3].quantity, Quantity::kRate);
}

TEST(TextImport, ColumnsByIndexSeparatorAndTimeUnitsFromTheStep) {
  // GIVEN ';'-separated rows with millisecond stamps and no header
  const auto dir = scratch("ms");
  std::string s;
  for (int i = 0; i < 500; ++i) s += std::to_string(1000 + 10 * i) + ";1.5;" + std::to_string(i) + ";0.25\n";
  write_text(dir / "a.csv", s);
  ImportOptions o;
  o.columns = {"2", "4"};
  o.time_column = "1";
  auto r = open_imu(dir / "a.csv", o);
  const Table t = read_all(*r);
  // THEN the step of 10 is read as milliseconds (100 Hz), and only columns 2 and 4 are channels
  EXPECT_TRUE(says(*r, "time in ms"));
  ASSERT_EQ(t.ch.size(), 2u);
  EXPECT_NEAR(t.t[1] - t.t[0], 0.01, 1e-12);
  EXPECT_DOUBLE_EQ(t.ch[1][3], 0.25);
  // and nanosecond stamps (EuRoC-like epoch values) are read as such when the name says so
  std::string n = "time_ns,gx,gy,gz\n";
  for (int i = 0; i < 100; ++i) n += std::to_string(1403636579758555392LL + 5000000LL * i) + ",0,0,0\n";
  write_text(dir / "b.csv", n);
  auto rb = open_imu(dir / "b.csv", {});
  const Table tb = read_all(*rb);
  // and the 1.4e18 ns stamps keep their 5 ms steps to 1e-9 s (as double seconds they resolve only
  // 2.4e-7 s): the epoch, the first stamp floored to whole seconds, is subtracted in integers
  EXPECT_EQ(rb->info().epoch_s, 1403636579);
  EXPECT_NEAR(tb.t[0], 0.758555392, 1e-12);
  for (std::size_t i = 1; i < tb.t.size(); ++i) EXPECT_NEAR(tb.t[i] - tb.t[i - 1], 0.005, 1e-9) << i;
}

TEST(TextImport, AColumnNamedForTwoChannelsIsRefused) {
  // GIVEN a recording with a gyro triad, an accelerometer triad and a temperature
  const auto dir = scratch("twice");
  std::string s = "t,gx,gy,gz,ax,ay,az,temp\n";
  for (int i = 0; i < 50; ++i) s += std::to_string(0.01 * i) + ",0.1,0.2,0.3,0,0,9.81,25\n";
  write_text(dir / "a.csv", s);
  const auto refused = [&](const ImportOptions& o, const std::string& expected) {
    expect_refused(dir / "a.csv", o, expected);
  };
  // WHEN an option names a column another channel already reads, THEN it is refused, naming both
  ImportOptions twice;
  twice.columns = {"gx", "gx", "gz"};  // one axis read twice, gy never
  refused(twice, "a.csv: --columns gx: column 2 ('gx') is already read as another channel");
  ImportOptions by_index;
  by_index.columns = {"2", "3", "gy"};
  refused(by_index, "--columns gy: column 3 ('gy') is already read");
  ImportOptions temp_on_accel;
  temp_on_accel.temp_column = "ax";  // the detected accelerometer's x
  refused(temp_on_accel, "--temp-column ax: column 5 ('ax') is already read");
  ImportOptions accel_on_gyro;
  accel_on_gyro.columns = {"gx", "gy", "gz"};
  accel_on_gyro.accel_columns = {"ax", "gz", "az"};
  refused(accel_on_gyro, "--accel-columns gz: column 4 ('gz') is already read");
  ImportOptions gyro_on_time;
  gyro_on_time.columns = {"t", "gy", "gz"};  // the detected time column
  refused(gyro_on_time, "--columns t: column 1 ('t') is already read as the time");
  // AND each column named once is read
  ImportOptions ok;
  ok.columns = {"gz", "gy", "gx"};
  ok.accel_columns = {"ax", "ay", "az"};
  ok.temp_column = "temp";
  EXPECT_NO_THROW(open_imu(dir / "a.csv", ok));
}

TEST(TextImport, OptionsForAnotherFormatAreRefusedNotIgnored) {
  // GIVEN a delimited-text recording and a .npy array
  const auto dir = scratch("otherformat");
  std::string s = "t,gx,gy,gz\n";
  for (int i = 0; i < 50; ++i) s += std::to_string(0.01 * i) + ",0.1,0.2,0.3\n";
  write_text(dir / "a.csv", s);
  const auto refused = [&](const ImportOptions& o, const std::string& expected) {
    expect_refused(dir / "a.csv", o, expected);
  };
  // WHEN a bag's --topic is given for the text file, THEN it is refused, naming the detected format
  ImportOptions topic;
  topic.topic = "/imu0";
  refused(topic, "a.csv: --topic applies to ROS bags, but this file is text (delimited text)");
  // AND a text option given with another --format is refused too
  ImportOptions sep;
  sep.format = Format::kNpy;
  sep.separator = ";";
  refused(sep, "--separator applies to delimited text, but this file is npy (as given (--format))");
  // AND the text options on the text file are taken
  ImportOptions ok;
  ok.separator = ",";
  EXPECT_NO_THROW(open_imu(dir / "a.csv", ok));
}

TEST(TextImport, MissingValuesAreNaNAndBadRowsNameFileAndLine) {
  const auto dir = scratch("bad");
  write_text(dir / "ok.csv", "t,gx,gy,gz\n0,1,2,3\n0.01,,2,3\n0.02,nan,2,3\n0.03,1,2,3\n0.04,1,2,3\n0.05,1,2,3\n0.06,1,2,3\n");
  auto r = open_imu(dir / "ok.csv", {});
  const Table t = read_all(*r);
  EXPECT_TRUE(std::isnan(t.ch[0][1]));
  EXPECT_TRUE(std::isnan(t.ch[0][2]));
  // a junk value in a used column
  write_text(dir / "junk.csv", "t,gx,gy,gz\n0,1,2,3\n0.01,1,2,3\n0.02,1,2,3\n0.03,1,2,3\n0.04,1,2,3\n0.05,1,abc,3\n");
  try {
    auto j = open_imu(dir / "junk.csv", {});
    read_all(*j);
    FAIL() << "junk accepted";
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("junk.csv:7: column 'gy' (3): expected a number, got 'abc'"), std::string::npos) << e.what();
  }
  // a row with fewer fields
  write_text(dir / "short.csv", "t,gx,gy,gz\n0,1,2,3\n0.01,1,2,3\n0.02,1,2,3\n0.03,1,2,3\n0.04,1,2,3\n0.05,1,2\n");
  try {
    auto j = open_imu(dir / "short.csv", {});
    read_all(*j);
    FAIL() << "short row accepted";
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("short.csv:7: expected 4 fields as in line 2, got 3"), std::string::npos) << e.what();
  }
  // no numbers at all, an unknown column, an index out of range
  write_text(dir / "words.csv", "hello\nworld\n");
  EXPECT_THROW(open_imu(dir / "words.csv", {}), ImportError);
  ImportOptions o;
  o.columns = {"omega"};
  try {
    open_imu(dir / "ok.csv", o);
    FAIL();
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("the header has: t, gx, gy, gz"), std::string::npos) << e.what();
  }
  o.columns = {"9"};
  EXPECT_THROW(open_imu(dir / "ok.csv", o), ImportError);
  EXPECT_THROW(open_imu(dir / "absent.csv", {}), ImportError);
}

}  // namespace
}  // namespace driftless::importers::test

namespace driftless::importers::test {
namespace {

TEST(TextImport, FieldsParsedWhereTheyStandReadAsTheirSpelling) {
  // GIVEN number spellings around separators: signs, blanks and tabs, exponents, a bare point,
  // missing values, and the same values blank-separated (the reader parses a plain number where
  // it stands and takes every other field the general way)
  const auto dir = scratch("spellings");
  const std::string rows = " +1.25 ;\t-2e-3\t;3.\nnan;;1.0E+2\n-0;7; 0.5\n";
  std::string semi = "gx;gy;gz\n", blank = "gx gy gz\n";
  for (int i = 0; i < 3; ++i) semi += rows;
  for (int i = 0; i < 3; ++i) blank += " +1.25 \t-2e-3\t3.\nnan nan 1.0E+2\n-0  7 \t 0.5\n";
  write_text(dir / "semi.csv", semi);
  write_text(dir / "blank.txt", blank);
  ImportOptions o;
  o.units = "deg/s";
  o.time_column = "none";
  for (const char* name : {"semi.csv", "blank.txt"}) {
    auto r = open_imu(dir / name, o);
    const Table t = read_all(*r, 1000, true);
    // THEN each value is its spelling's, missing ones NaN; an unstamped bare read has no t or loc
    ASSERT_EQ(t.ch.size(), 3u) << name;
    ASSERT_EQ(t.ch[0].size(), 9u) << name;
    EXPECT_TRUE(t.t.empty() && t.loc.empty()) << name;
    for (std::size_t k = 0; k < 9; k += 3) {
      EXPECT_EQ(t.ch[0][k], 1.25) << name;
      EXPECT_EQ(t.ch[1][k], -2e-3) << name;
      EXPECT_EQ(t.ch[2][k], 3.0) << name;
      EXPECT_TRUE(std::isnan(t.ch[0][k + 1]) && std::isnan(t.ch[1][k + 1])) << name;
      EXPECT_EQ(t.ch[2][k + 1], 100.0) << name;
      EXPECT_TRUE(t.ch[0][k + 2] == 0.0 && std::signbit(t.ch[0][k + 2])) << name;
      EXPECT_EQ(t.ch[1][k + 2], 7.0) << name;
      EXPECT_EQ(t.ch[2][k + 2], 0.5) << name;
    }
  }
  // and a number followed by text in its field is refused, naming it
  write_text(dir / "trail.csv", "gx;gy;gz\n1;2;3\n1;2;3\n1;2;3\n1;2;3\n1;2;3\n1;2;3\n1;2.5x;3\n");
  try {
    auto r = open_imu(dir / "trail.csv", o);
    read_all(*r);
    FAIL() << "2.5x accepted";
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("trail.csv:8: column 'gy' (2): expected a number, got '2.5x'"), std::string::npos)
        << e.what();
  }
}

TEST(TextImport, LongFilesParsedOnTwoThreadsGiveTheSameRowsAndLineNumbers) {
  // GIVEN a 3 MB file (the reader parses whole buffered stretches of 1 MB and more on two threads)
  const auto dir = scratch("two_threads");
  std::string text = "# a comment line\nt,gx,gy,gz\n";
  for (int i = 0; i < 120000; ++i) {
    text += std::to_string(i) + "." + std::to_string(100 + i % 900) + "," + std::to_string(i % 7) + ",0.5,-1\n";
    if (i == 70000) text += "# a comment between rows\n";
  }
  write_text(dir / "long.csv", text);
  // WHEN it is read in large blocks (two threads) and in small ones (line by line)
  ImportOptions o;
  o.time_units = "s";
  auto big = open_imu(dir / "long.csv", o);
  auto small = open_imu(dir / "long.csv", o);
  const Table a = read_all(*big, 1u << 20), b = read_all(*small, 1000);
  // THEN both hold every row with the same values, stamps and line numbers
  ASSERT_EQ(a.t.size(), 120000u);
  ASSERT_EQ(b.t.size(), 120000u);
  EXPECT_EQ(a.t, b.t);
  EXPECT_EQ(a.ch, b.ch);
  EXPECT_EQ(a.loc, b.loc);
  EXPECT_EQ(a.loc[70001], 70001u + 2 + 2);  // after the header, the first comment and the one between rows
  // and a bad value late in the file is named by its own line, whichever thread parsed it
  text.replace(text.rfind(",0.5,"), 5, ",x.5,");
  write_text(dir / "bad.csv", text);
  try {
    auto r = open_imu(dir / "bad.csv", o);
    read_all(*r, 1u << 20);
    FAIL() << "junk accepted";
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:120003: column 'gy' (3)"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace driftless::importers::test

namespace driftless::importers::test {
namespace {

// "t,gx,gy,gz,ax,ay,az" at 100 Hz: gyro white noise of sigma_dps (in `rate_scale` units per deg/s) on a
// turn of amplitude turn_dps at 0.5 Hz; accelerometer at rest in m/s^2 (gravity on z)
std::string si_like_file(double sigma_dps, double turn_dps, double rate_scale, int rows = 300) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  std::string s = "t,gx,gy,gz,ax,ay,az\n";
  char b[200];
  for (int i = 0; i < rows; ++i) {
    const double turn = turn_dps * std::sin(2.0 * 3.141592653589793 * 0.5 * 0.01 * i);
    std::snprintf(b, sizeof b, "%.2f,%.7f,%.7f,%.7f,%.4f,%.4f,%.4f\n", 0.01 * i, rate_scale * (0.5 + turn + sigma_dps * n(rng)),
                  rate_scale * (-0.3 + sigma_dps * n(rng)), rate_scale * (0.2 + sigma_dps * n(rng)), 0.02 * n(rng),
                  0.02 * n(rng), kG + 0.02 * n(rng));
    s += b;
  }
  return s;
}

TEST(TextImport, DegreesPerSecondBesideAnSiAccelerometerAreNotTakenAsRadians) {
  const auto dir = scratch("si_guess");
  // GIVEN gyro in deg/s (MPU6050-like noise, 0.1 deg/s per sample at 100 Hz: 0.01 deg/s/sqrt(Hz)) beside an
  // accelerometer in m/s^2, no units in the header
  write_text(dir / "dps.csv", si_like_file(0.1, 0.0, 1.0));
  auto r = open_imu(dir / "dps.csv", {});
  const Table t = read_all(*r);
  // THEN rad/s (57x the noise: 0.57 deg/s/sqrt(Hz), beyond every MEMS gyro) is refused as the guess, and said
  EXPECT_TRUE(says(*r, "rates in deg/s, although the accelerometer reads g in m/s^2")) << r->info().assumptions[2];
  EXPECT_TRUE(says(*r, "as rad/s its white noise would be"));
  double mean = 0.0;
  for (double v : t.ch[1]) mean += v / static_cast<double>(t.ch[1].size());
  EXPECT_NEAR(mean, -0.3, 0.03);  // deg/s as written
  // GIVEN the same sensor written in rad/s, at rest and turning +-115 deg/s (2 rad/s)
  for (const double turn : {0.0, 115.0}) {
    write_text(dir / "rad.csv", si_like_file(0.1, turn, 1.0 / kDegPerRad));
    auto s = open_imu(dir / "rad.csv", {});
    const Table u = read_all(*s);
    // THEN the SI guess stands: rad/s, converted to deg/s
    EXPECT_TRUE(says(*s, "rates in rad/s: the accelerometer reads g in m/s^2, an SI file")) << turn;
    double m = 0.0;
    for (double v : u.ch[1]) m += v / static_cast<double>(u.ch[1].size());
    EXPECT_NEAR(m, -0.3, 0.03) << turn;
  }
  // GIVEN deg/s readings of a fast turn (+-500 deg/s): as rad/s they would pass any MEMS full scale
  write_text(dir / "fast.csv", si_like_file(0.01, 500.0, 1.0));
  auto f = open_imu(dir / "fast.csv", {});
  EXPECT_TRUE(says(*f, "beyond the +-4000 deg/s of any MEMS gyro"));
  // GIVEN a unit in the header: taken from it, and said so (not "no unit given")
  write_text(dir / "named.csv", "t,gx [deg/s],gy [deg/s],gz [deg/s]\n0,1,2,3\n0.01,1,2,3\n0.02,1,2,3\n0.03,1,2,3\n0.04,1,2,3\n");
  auto n = open_imu(dir / "named.csv", {});
  EXPECT_TRUE(says(*n, "rates in deg/s (from the header)"));
  EXPECT_FALSE(says(*n, "no unit given"));
}

TEST(TextImport, ArduinoMillisAndMicrosColumnsAreTheTime) {
  const auto dir = scratch("arduino");
  // GIVEN the header names of Arduino sketches' clocks, whole ms and whole us
  for (const auto& [name, step, scale] : {std::tuple{"millis", 10, 1e-3}, std::tuple{"micros", 10000, 1e-6}}) {
    std::string s = std::string(name) + ",gx,gy,gz\n";
    for (int i = 0; i < 20; ++i) s += std::to_string(5000 + step * i) + ",1,2,3\n";
    write_text(dir / "a.csv", s);
    auto r = open_imu(dir / "a.csv", {});
    const Table t = read_all(*r);
    // THEN the column is the time, in its unit, and said so
    EXPECT_TRUE(r->info().has_time) << name;
    EXPECT_TRUE(says(*r, std::string("Arduino's ") + name + "()")) << name;
    ASSERT_EQ(t.t.size(), 20u);
    EXPECT_NEAR(t.t[1] - t.t[0], step * scale, 1e-12) << name;
    EXPECT_EQ(r->info().channels.size(), 3u) << name;
  }
}

TEST(TextImport, QuotedHeaderNamesAndARadianFileWithoutUnitsAreSaid) {
  const auto dir = scratch("phone");
  // GIVEN a phyphox-like file: quoted names with their units, rad/s
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n(0.0, 0.1 / kDegPerRad);  // a phone MEMS: 0.01 deg/s/sqrt(Hz) at 100 Hz
  std::string q = "\"Time (s)\",\"Gyroscope x (rad/s)\",\"Gyroscope y (rad/s)\",\"Gyroscope z (rad/s)\"\n";
  std::string bare = "time,gx,gy,gz\n";
  char b[160];
  for (int i = 0; i < 300; ++i) {
    std::snprintf(b, sizeof b, "%.2f,%.9e,%.9e,%.9e\n", 0.01 * i, n(rng), n(rng), n(rng));
    q += b;
    bare += b;
  }
  write_text(dir / "phyphox.csv", q);
  auto r = open_imu(dir / "phyphox.csv", {});
  // THEN the names come without their quotes, time and units from them
  ASSERT_EQ(r->info().channels.size(), 3u);
  EXPECT_EQ(r->info().channels[0].name, "Gyroscope x (rad/s)");
  EXPECT_TRUE(r->info().has_time);
  EXPECT_TRUE(says(*r, "rates in rad/s (from the header)"));
  // GIVEN the same rad/s numbers without any unit: read as deg/s, and the note says they are too quiet
  // for a MEMS gyro in deg/s (1.7e-4 deg/s/sqrt(Hz)) and what they would be in rad/s
  write_text(dir / "bare.csv", bare);
  auto s = open_imu(dir / "bare.csv", {});
  EXPECT_TRUE(says(*s, "below every MEMS gyro's")) << s->info().assumptions[3];
  // GIVEN an MPU6050-like file in deg/s (0.1 deg/s per sample at 100 Hz): no such remark
  std::string dps = "time,gx,gy,gz\n";
  for (int i = 0; i < 300; ++i) {
    std::snprintf(b, sizeof b, "%.2f,%.6f,%.6f,%.6f\n", 0.01 * i, n(rng) * kDegPerRad, n(rng) * kDegPerRad, n(rng) * kDegPerRad);
    dps += b;
  }
  write_text(dir / "dps.csv", dps);
  auto d = open_imu(dir / "dps.csv", {});
  EXPECT_TRUE(says(*d, "rates in deg/s: no unit given"));
  EXPECT_FALSE(says(*d, "below every MEMS gyro's"));
}

TEST(TextImport, RecordingCutOffMidWriteLosesItsLastLineOnly) {
  const auto dir = scratch("cut_tail");
  const std::string rows = "t,gx,gy,gz\n0,1,2,3\n0.01,1,2,3\n0.02,1,2,3\n0.03,1,2,3\n0.04,1,2,3\n0.05,1,2,3\n";
  // GIVEN a last line cut mid-write: no line end and too few fields
  write_text(dir / "cut.csv", rows + "0.06,1,");
  auto r = open_imu(dir / "cut.csv", {});
  const Table t = read_all(*r);
  // THEN the rows before it are read and the cut line is said, not an error
  EXPECT_EQ(t.t.size(), 6u);
  EXPECT_TRUE(says(*r, "the last line is cut off (no line end, 3 of 4 fields"));
  // GIVEN a last line without a line end but whole: a row
  write_text(dir / "whole.csv", rows + "0.06,1,2,3");
  auto w = open_imu(dir / "whole.csv", {});
  EXPECT_EQ(read_all(*w).t.size(), 7u);
  EXPECT_FALSE(says(*w, "cut off"));
  // GIVEN a short line that ends in a line end: still an error naming its line
  write_text(dir / "short.csv", rows + "0.06,1,\n");
  auto s = open_imu(dir / "short.csv", {});
  EXPECT_THROW(read_all(*s), ImportError);
}

}  // namespace
}  // namespace driftless::importers::test
