// Test logs for compare/diagnose, drawn from the twin's closed-form source (twin::FastBox: the
// scenario's motion, the flip schedule of paper Fig. 3 with the platforms pressed onto their end
// stops, the effects' SensorModel, the sensors' sampling offset) and written and read back through
// the log format, so the samples carry the log's fixed precision. The deliberately independent
// generator is tests/diagnose/independent_log.py.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "estimator/log.hpp"
#include "tests/temp_path.hpp"
#include "twin/fast_box.hpp"
#include "twin/scenario.hpp"
#include "twin/sensor/sensor_model.hpp"

namespace driftless::diagnose::testlog {

using namespace driftless::twin;  // the sensor model, scenario and simulator

struct TestLog {
  std::vector<Sample> samples;
  log::Metadata meta;
  std::uint32_t fields = kFieldRefQ | kFieldRefP | kFieldTemp;
};

/// Box-level errors planted in a test log (the log does not know them).
struct Planted {
  double stop_error_deg[2][2] = {{0, 0}, {0, 0}};  // [platform][0: + stop, 1: - stop], deg
  double time_offset_s = 0.0;                      // sensors sample this much before the log time, s
  bool with_ref_q = true;
};

/// The scenario of a test log: `amp_dps` = 0 a static box, else the pan/tilt unit moving at up to
/// amp_dps deg/s; 10 s standstills; sensors p1, p2; the planted stop errors and time offset.
inline Scenario test_scenario(const SensorParams& p1, const SensorParams& p2, double duration_s, std::uint64_t seed,
                              double amp_dps, double fs, double lat_deg, const Planted& pl) {
  Scenario sc;
  sc.name = "diagnose-test";
  sc.duration_s = duration_s;
  sc.seed = seed;
  sc.sample_rate_hz = fs;
  sc.latitude_deg = lat_deg;
  sc.model.sensor1 = p1;
  sc.model.sensor2 = p2;
  sc.model.time_offset_s = pl.time_offset_s;
  sc.model.box.stop1_error_deg = Eigen::Vector2d(pl.stop_error_deg[0][1], pl.stop_error_deg[0][0]);
  sc.model.box.stop2_error_deg = Eigen::Vector2d(pl.stop_error_deg[1][1], pl.stop_error_deg[1][0]);
  sc.flip_schedule.standstill_s = 10.0;
  if (amp_dps > 0) {
    sc.motion.type = MotionType::pan_tilt;
    sc.motion.pan_tilt.max_rate_dps = amp_dps;
    sc.motion.pan_tilt.min_rate_dps = std::min(sc.motion.pan_tilt.min_rate_dps, amp_dps);
  }
  return sc;
}

/// Simulates `duration_s` at `fs` Hz with sensors p1, p2 (seeded). amp_dps = 0: static box.
inline TestLog make_log(const SensorParams& p1, const SensorParams& p2, double duration_s, std::uint64_t seed,
                        double amp_dps = 30.0, double fs = 100.0, double lat_deg = 52.0, const Planted& pl = {}) {
  FastBox box(test_scenario(p1, p2, duration_s, seed, amp_dps, fs, lat_deg, pl));
  const std::uint32_t fields = pl.with_ref_q ? kFieldRefQ | kFieldRefP | kFieldTemp : kFieldTemp;
  const std::filesystem::path path = test::temp_path("diagnose-test-log.csv");
  {
    log::LogWriter writer(path, box.metadata(), fields);
    Sample s;
    while (box.next(s)) writer.write(s);
    writer.finish(true);
  }
  TestLog out;
  log::LogReader reader(path);
  Sample s;
  while (reader.next(s)) out.samples.push_back(s);
  out.meta = reader.metadata();
  out.fields = reader.fields();
  std::filesystem::remove(path);
  return out;
}

}  // namespace driftless::diagnose::testlog
