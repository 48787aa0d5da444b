// EuRoC / TUM-VI imu0/data.csv and NumPy .npy arrays, written in the test from the real recordings
// of both folders and read back; bad files named with their line or row.
#include <cmath>
#include <cstdint>
#include <cstring>

#include <gtest/gtest.h>

#include "import_fixture.hpp"

namespace driftless::importers::test {
namespace {

constexpr double kDegPerRad = 57.295779513082320876798;
constexpr double kG = 9.80665;

// a C-order 2-D .npy of doubles (or int16), format version 1.0
template <class T>
void write_npy(const std::filesystem::path& p, const std::vector<std::vector<double>>& rows, const char* descr) {
  std::string dict = std::string("{'descr': '") + descr + "', 'fortran_order': False, 'shape': (" + std::to_string(rows.size()) +
                     ", " + std::to_string(rows[0].size()) + "), }";
  while ((10 + dict.size() + 1) % 64 != 0) dict += ' ';
  dict += '\n';
  std::ofstream f(p, std::ios::binary);
  f.write("\x93NUMPY\x01\x00", 8);
  const std::uint16_t len = static_cast<std::uint16_t>(dict.size());
  f.write(reinterpret_cast<const char*>(&len), 2);
  f << dict;
  for (const auto& r : rows) {
    for (double v : r) {
      const T x = static_cast<T>(v);
      f.write(reinterpret_cast<const char*>(&x), sizeof x);
    }
  }
}

TEST(EurocImport, RealRecordingInEurocLayoutReadsBackInDegPerSecond) {
  DRIFTLESS_NEED_REALDATA();
  // GIVEN the sunsided recording written as EuRoC imu0/data.csv: ns stamps, rad/s, m/s^2
  const Csv csv = plain_csv(sunsided_10min());
  const auto dir = scratch("euroc");
  std::string s = "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
                  "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
  char line[256];
  for (const auto& r : csv.rows) {
    std::snprintf(line, sizeof line, "%lld,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n",
                  static_cast<long long>(1403636579758555392LL + std::llround(r[0] * 1e9)), r[4] / kDegPerRad,
                  r[5] / kDegPerRad, r[6] / kDegPerRad, r[1] * kG, r[2] * kG, r[3] * kG);
    s += line;
  }
  write_text(dir / "data.csv", s);
  // WHEN read with format detection
  auto r = open_imu(dir / "data.csv", {});
  const Table t = read_all(*r, 5000);
  // THEN it is EuRoC, stamps in s, gyro back in deg/s, accel in m/s^2
  EXPECT_EQ(r->info().format, Format::kEuroc);
  ASSERT_EQ(t.t.size(), csv.rows.size());
  ASSERT_EQ(r->info().channels.size(), 6u);
  for (std::size_t i = 0; i < csv.rows.size(); i += 1009) {
    EXPECT_NEAR(t.t[i] - t.t[0], csv.rows[i][0] - csv.rows[0][0], 2e-6);
    EXPECT_NEAR(t.ch[1][i], csv.rows[i][5], 1e-12);
    EXPECT_NEAR(t.ch[5][i], csv.rows[i][3] * kG, 1e-12);
  }
  // a damaged row names its line
  write_text(dir / "bad.csv", s.substr(0, s.find('\n', 2000) + 1) + "1403636579758555392,0.1,x,0.3,1,2,3\n");
  try {
    auto b = open_imu(dir / "bad.csv", {});
    read_all(*b);
    FAIL();
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.csv:"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("expected a number, got 'x'"), std::string::npos) << e.what();
  }
}

TEST(NpyImport, RealCountsAsDoublesAndAsInt16) {
  DRIFTLESS_NEED_REALDATA();
  // GIVEN the tomisuarez2 static recording (raw counts) as a .npy of doubles and of int16
  auto text = open_imu(tomisuarez_static(), {});
  const Table t = read_all(*text);
  std::vector<std::vector<double>> rows_dps, rows_counts;
  for (std::size_t i = 0; i < t.t.size(); ++i) {
    // the text reader's channels: gx, gy, gz (rates) first, then ax, ay, az
    rows_dps.push_back({0.01 * static_cast<double>(i), t.ch[0][i], t.ch[1][i], t.ch[2][i]});
    rows_counts.push_back({std::round(t.ch[0][i] * 131.0), std::round(t.ch[1][i] * 131.0), std::round(t.ch[2][i] * 131.0)});
  }
  const auto dir = scratch("npy");
  write_npy<double>(dir / "f8.npy", rows_dps, "<f8");
  write_npy<std::int16_t>(dir / "i2.npy", rows_counts, "<i2");
  // WHEN read with the time column and, for counts, the unit given
  ImportOptions o;
  o.time_column = "1";
  auto a = open_imu(dir / "f8.npy", o);
  const Table ta = read_all(*a);
  ImportOptions oc;
  oc.units = "lsb:131";
  auto b = open_imu(dir / "i2.npy", oc);
  const Table tb = read_all(*b);
  // THEN both give the text reader's deg/s, row by row
  EXPECT_EQ(a->info().format, Format::kNpy);
  ASSERT_EQ(ta.t.size(), t.t.size());
  ASSERT_EQ(tb.t.size(), t.t.size());
  EXPECT_DOUBLE_EQ(ta.t[7], 0.07);
  for (std::size_t i = 0; i < t.t.size(); i += 101) {
    EXPECT_DOUBLE_EQ(ta.ch[0][i], t.ch[0][i]);
    EXPECT_NEAR(tb.ch[2][i], t.ch[2][i], 1e-12);
  }
  EXPECT_EQ(tb.loc[4], 5u);
  // and a caller that wants only the values of the unstamped array gets them without stamps or
  // row numbers; the stamped one keeps its stamps
  auto bare = open_imu(dir / "i2.npy", oc);
  const Table tc = read_all(*bare, 1000, true);
  EXPECT_TRUE(tc.t.empty());
  EXPECT_TRUE(tc.loc.empty());
  EXPECT_EQ(tc.ch, tb.ch);
  auto stamped = open_imu(dir / "f8.npy", o);
  EXPECT_EQ(read_all(*stamped, 1000, true).t, ta.t);
}

TEST(NpyImport, DamagedArraysAreRefusedWithTheRow) {
  const auto dir = scratch("npy_bad");
  std::vector<std::vector<double>> rows(100, std::vector<double>{1.0, 2.0});
  write_npy<double>(dir / "ok.npy", rows, "<f8");
  // cut the file inside row 51
  const auto size = std::filesystem::file_size(dir / "ok.npy");
  std::filesystem::copy_file(dir / "ok.npy", dir / "cut.npy");
  std::filesystem::resize_file(dir / "cut.npy", size - 50 * 16 + 5);
  try {
    auto r = open_imu(dir / "cut.npy", {});
    read_all(*r, 1000);
    FAIL();
  } catch (const ImportError& e) {
    EXPECT_NE(std::string(e.what()).find("cut.npy: row 51: the file ends before the 100 rows"), std::string::npos) << e.what();
  }
  write_npy<double>(dir / "big.npy", rows, ">f8");
  EXPECT_THROW(open_imu(dir / "big.npy", {}), ImportError);  // big-endian refused with the dtype named
  write_text(dir / "fake.npy", "\x93NUMPX");
  EXPECT_THROW(open_imu(dir / "fake.npy", {}), ImportError);
  ImportOptions o;
  o.columns = {"gx"};  // no names in an array
  EXPECT_THROW(open_imu(dir / "ok.npy", o), ImportError);
  // a column given twice, or the time column given as a channel, is refused, naming it
  for (const auto& [cols, time] : {std::pair<std::vector<std::string>, std::string>{{"1", "1"}, ""},
                                   std::pair<std::vector<std::string>, std::string>{{"1", "2"}, "2"}}) {
    ImportOptions twice;
    twice.columns = cols;
    twice.time_column = time;
    try {
      open_imu(dir / "ok.npy", twice);
      ADD_FAILURE() << "a column read twice was accepted";
    } catch (const ImportError& e) {
      EXPECT_NE(std::string(e.what()).find("is already read as another channel"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace driftless::importers::test
