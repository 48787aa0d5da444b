// Stamps made by others: a regular step with gaps, stamps that go backwards or repeat, and bursty
// arrival stamps (the real sunsided recording).
#include <cmath>

#include <gtest/gtest.h>

#include "import_fixture.hpp"
#include "importers/stamp_ns.hpp"
#include "importers/stamps.hpp"

namespace driftless::importers::test {
namespace {

TEST(Stamps, GapsBackwardsAndRepeatsAreCountedWithTheirPlace) {
  // GIVEN 100 Hz stamps with 5 samples missing after row 50, one stamp going back, one repeated
  std::vector<double> t;
  for (int i = 0; i < 200; ++i) t.push_back(0.01 * (i < 50 ? i : i + 5));
  t[120] = t[119] - 0.003;
  t[150] = t[149];
  StampMonitor m;
  m.learn(t);
  for (std::size_t i = 0; i < t.size(); ++i) m.push(t[i], i + 1);
  const auto& r = m.report();
  // THEN the gap of five samples at row 51, one backwards at 121, one repeat at 151; the stamps
  // after those two jump 2.3 and 2 steps forward again (one sample each as the monitor counts)
  EXPECT_NEAR(r.step_s, 0.01, 1e-12);
  EXPECT_FALSE(r.bursty);
  EXPECT_EQ(r.gaps, 3u);
  EXPECT_EQ(r.first_gap_loc, 51u);
  EXPECT_EQ(r.missing, 7u);
  EXPECT_EQ(r.backwards, 1u);
  EXPECT_EQ(r.first_backwards_loc, 121u);
  EXPECT_EQ(r.repeated, 1u);
  EXPECT_EQ(r.first_repeated_loc, 151u);
  const auto text = r.describe("line");
  ASSERT_GE(text.size(), 3u);
  EXPECT_NE(text[0].find("the first at line 51"), std::string::npos) << text[0];
}

TEST(Stamps, JitteringWholeMillisecondStampsGiveTheMeanRateNotTheMedian) {
  // GIVEN a loop that takes 3.3 ms stamped in whole ms (Arduino millis()): steps of 3, 3, 4 ms, and one
  // gap of 50 ms
  std::vector<double> t;
  for (int i = 0; i < 3000; ++i) t.push_back(1e-3 * std::floor(3.3 * i + (i >= 1500 ? 50.0 : 0.0)));
  StampMonitor m;
  m.learn(std::span<const double>(t.data(), 1000));
  for (std::size_t i = 0; i < t.size(); ++i) m.push(t[i], i + 2);
  const auto& r = m.report();
  // THEN the median step is 3 ms (333 Hz) but the regular steps' rate is the loop's 303 Hz (the gap left
  // out: with it the mean over the record reads 0.5 % slower)
  EXPECT_NEAR(r.step_s, 3e-3, 1e-12);
  EXPECT_EQ(r.gaps, 1u);
  EXPECT_NEAR(r.regular_rate_hz(), 1.0 / 3.3e-3, 0.2);
  EXPECT_LT(r.mean_rate_hz(), 0.997 / 3.3e-3);
}

TEST(Stamps, RealBurstyArrivalStampsAreNotGaps) {
  DRIFTLESS_NEED_REALDATA();
  const Csv csv = plain_csv(sunsided_10min());
  std::vector<double> t;
  for (const auto& r : csv.rows) t.push_back(r[0]);
  StampMonitor m;
  m.learn(std::span<const double>(t.data(), 4096));
  for (std::size_t i = 0; i < t.size(); ++i) m.push(t[i], i + 2);
  const auto& r = m.report();
  // THEN bursty (median 2 ms against a mean of ~10 ms), no gaps, the mean rate ~99.3 Hz (README)
  EXPECT_TRUE(r.bursty);
  EXPECT_EQ(r.gaps, 0u);
  EXPECT_NEAR(r.mean_rate_hz(), 99.3, 0.3);
  EXPECT_GT(r.largest_step_s, 0.3);
}

TEST(StampNs, DecimalStampsBecomeWholeNanosecondsExactly) {
  auto ns_of = [](const std::string& s, std::int64_t per_unit) {
    std::int64_t ns = -1;
    return parse_stamp_ns(s.data(), s.data() + s.size(), per_unit, ns) ? ns : std::int64_t{-1};
  };
  // ns integers, seconds with 9 or 6 decimals, milliseconds with a fraction
  EXPECT_EQ(ns_of("1403636579758555392", 1), 1403636579758555392LL);
  EXPECT_EQ(ns_of("1403636579.758555392", 1'000'000'000), 1403636579758555392LL);
  EXPECT_EQ(ns_of("1403636579.758555", 1'000'000'000), 1403636579758555000LL);
  EXPECT_EQ(ns_of("12.5", 1'000'000), 12'500'000LL);
  EXPECT_EQ(ns_of("-0.25", 1'000'000'000), -250'000'000LL);
  // not plain decimals: refused, so the reader falls back to a double
  EXPECT_EQ(ns_of("1.4e9", 1'000'000'000), -1);
  EXPECT_EQ(ns_of("nan", 1), -1);
  EXPECT_EQ(ns_of("99999999999999999999", 1), -1);  // 20 digits: not 64-bit
  // the epoch floors (also below zero), and the difference is formed in integers
  EXPECT_EQ(epoch_s_of(1403636579758555392LL), 1403636579);
  EXPECT_EQ(epoch_s_of(-1), -1);
  EXPECT_NEAR(seconds_since(1403636579758555392LL + 5'000'000LL * 1000, 1403636579), 5.758555392, 1e-15);
  EXPECT_EQ(ns_per_unit_of(1e-3), 1'000'000);
  EXPECT_EQ(ns_per_unit_of(0.5), 0);
}

}  // namespace
}  // namespace driftless::importers::test

namespace driftless::importers::test {
namespace {

std::int64_t dt_ns(const std::string& s) {
  std::int64_t ns = -1;
  EXPECT_TRUE(parse_datetime_ns(s.data(), s.data() + s.size(), ns)) << s;
  return ns;
}

bool refused(const std::string& s) {
  std::int64_t ns = 0;
  return !parse_datetime_ns(s.data(), s.data() + s.size(), ns);
}

TEST(StampNs, DatesAndTimesBecomeWholeNanosecondsSince1970Utc) {
  // GIVEN the forms phone apps and Python loggers write; THEN ns since 1970-01-01 UTC, exactly
  EXPECT_EQ(dt_ns("1970-01-01 00:00:00"), 0);
  EXPECT_EQ(dt_ns("2024-05-01T12:00:00.125Z"), 1714564800125000000LL);  // 19844 days + 12 h
  EXPECT_EQ(dt_ns("2024-05-01 14:00:00.125+02:00"), 1714564800125000000LL);
  EXPECT_EQ(dt_ns("2000-02-29 23:59:59.999999999"), 951868799999999999LL);
  EXPECT_EQ(dt_ns("2024-05-01 12:00:00.1234567891"), 1714564800123456789LL);  // below 1 ns dropped
  // a date-time as a stamp in s (the unit the step gives), not in another unit
  const std::string t = "2024-05-01 12:00:00.010";
  std::int64_t ns = 0;
  EXPECT_TRUE(parse_stamp_ns(t.data(), t.data() + t.size(), 1'000'000'000, ns));
  EXPECT_EQ(ns, 1714564800010000000LL);
  EXPECT_FALSE(parse_stamp_ns(t.data(), t.data() + t.size(), 1'000'000, ns));
  // THEN what is not a date and time is refused
  for (const char* bad : {"2024-13-01 00:00:00", "2023-02-29 00:00:00", "2024-05-01 24:00:00", "2024-05-01",
                          "2024-05-01 12:00:00.", "2024-05-01 12:00:00 UTC", "2024/05/01 12:00:00"}) {
    EXPECT_TRUE(refused(bad)) << bad;
  }
}

TEST(TextImport, DateTimeColumnIsTheTimeReadExactly) {
  const auto dir = scratch("datetime");
  // GIVEN a logger that stamps rows with the date and time, 100 Hz
  std::string s = "time,gx,gy,gz\n";
  char b[120];
  for (int i = 0; i < 30; ++i) {
    const double sec = 59.8 + 0.01 * i;
    const int minute = static_cast<int>(std::floor(sec / 60.0));
    std::snprintf(b, sizeof b, "2024-05-01 12:%02d:%06.3f,0.5,-0.3,0.2\n", minute, sec - 60.0 * minute);
    s += b;
  }
  write_text(dir / "dt.csv", s);
  auto r = open_imu(dir / "dt.csv", {});
  const Table t = read_all(*r);
  // THEN the column is the time, said, and the steps are 10 ms across the minute's end
  EXPECT_TRUE(r->info().has_time);
  EXPECT_EQ(r->info().channels.size(), 3u);
  bool said = false;
  for (const auto& a : r->info().assumptions) said = said || a.find("holds dates and times") != std::string::npos;
  EXPECT_TRUE(said);
  ASSERT_EQ(t.t.size(), 30u);
  for (std::size_t i = 1; i < t.t.size(); ++i) EXPECT_NEAR(t.t[i] - t.t[i - 1], 0.01, 1e-9) << i;
}

}  // namespace
}  // namespace driftless::importers::test
