// The live loop's log thread (hil_bridge/log_pump.hpp): GIVEN rows and event lines queued through
// the pump, WHEN it is closed, THEN the file holds the bytes a direct write gives, in the same
// order, also when the ring is far smaller than the stream (the loop then waits, and says so).
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "estimator/log.hpp"
#include "hil_bridge/log_pump.hpp"

namespace driftless::hil {
namespace {

namespace fs = std::filesystem;

fs::path temp_file(const std::string& name) {
  return fs::temp_directory_path() / ("driftless-pump-" + std::to_string(::getpid()) + "-" + name);
}

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

log::Metadata meta_1khz() {
  log::Metadata m;
  m.set("sample_rate_hz", "1000");
  m.set("latitude_deg", "52.0");
  return m;
}

Sample row(int i) {
  Sample s;
  s.t_s = i * 1e-3;
  s.gyro1_dps = Eigen::Vector3d(0.5 + 1e-4 * i, -0.3, std::sin(i * 0.01));
  s.gyro2_dps = Eigen::Vector3d(-0.6, 0.4 - 1e-4 * i, std::cos(i * 0.01));
  s.plat1_deg = (i / 500) % 2 ? 90.0 : -90.0;
  s.plat2_deg = 90.0;
  s.temp1_c = 25.0 + 1e-3 * i;
  s.temp2_c = 26.0;
  return s;
}

// the same stream (rows, an event every 97 rows) written directly and through a pump
template <class Sink>
void stream(Sink&& sink, int rows) {
  for (int i = 0; i < rows; ++i) {
    sink.write(row(i));
    if (i % 97 == 0) sink.event(i * 1e-3, "info: marker " + std::to_string(i));
  }
}

void expect_same_bytes_as_direct(std::size_t capacity, int rows, bool expect_waits) {
  const fs::path direct = temp_file("direct.csv"), pumped = temp_file("pumped.csv");
  {
    log::LogWriter w(direct, meta_1khz(), kFieldTemp);
    stream(w, rows);
    w.finish(true);
  }
  std::uint64_t waits = 0;
  {
    log::LogWriter w(pumped, meta_1khz(), kFieldTemp);
    LogPump pump(w, 0.01, capacity);
    stream(pump, rows);
    pump.close();
    waits = pump.waits();
    w.finish(true);
  }
  const std::string a = bytes_of(direct), b = bytes_of(pumped);
  EXPECT_GT(a.size(), static_cast<std::size_t>(rows) * 20);
  EXPECT_EQ(a, b) << "capacity " << capacity;
  if (expect_waits) {
    EXPECT_GT(waits, 0u) << "a 4-slot ring cannot hold 600 rows queued at once";
  }
  fs::remove(direct);
  fs::remove(pumped);
}

TEST(LogPump, RowsAndEventsReachTheFileAsWrittenDirectly) { expect_same_bytes_as_direct(8192, 20000, false); }

TEST(LogPump, ATinyRingMakesTheLoopWaitButLosesAndReordersNothing) { expect_same_bytes_as_direct(4, 600, true); }

TEST(LogPump, RejectsANonPositiveFlushIntervalAndAnEmptyRing) {
  const fs::path p = temp_file("bad.csv");
  log::LogWriter w(p, meta_1khz(), 0);
  EXPECT_THROW(LogPump(w, 0.0), std::invalid_argument);
  EXPECT_THROW(LogPump(w, 0.5, 0), std::invalid_argument);
  w.finish(true);
  fs::remove(p);
}

}  // namespace
}  // namespace driftless::hil
