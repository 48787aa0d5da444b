// The sweep machinery: file parsing, grid expansion, seeds, the parallel runner and the table.
#include <cmath>
#include <fstream>
#include <random>
#include <sstream>

#include <unistd.h>

#include <gtest/gtest.h>

#include "estimator/input_error.hpp"
#include "studies/sweep.hpp"

namespace driftless::studies {
namespace {

const char* kSweep = R"(
name: demo
runner: fast
scenario: base.yaml
duration_s: 60
monte_carlo: 3
seed: 7
grid:
  flip_angle_deg: [10, 45, 90]
  noise:
    set: [model.sensor1.effects.white_noise.density_dps_rthz, model.sensor2.effects.white_noise.density_dps_rthz]
    vector3: true
    range: [0.005, 0.015, 0.005]
fixed:
  flip_schedule.standstill_s: 5
plots:
  - {x: flip_angle_deg, y: [err], series: noise, logy: true}
)";

std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// a real little job: the sample std of white noise drawn from the run's seed, scaled by the values
Metrics noise_job(const RunSpec& s) {
  std::mt19937_64 rng(s.seed);
  std::normal_distribution<double> g;
  double s2 = 0;
  for (int i = 0; i < 2000; ++i) {
    const double x = g(rng) * s.values[1];
    s2 += x * x;
  }
  return {{"err", std::sqrt(s2 / 2000) / std::sin(s.values[0] * 3.14159265358979 / 180)},
          {"noise_est", std::sqrt(s2 / 2000)}};
}

TEST(Sweep, ParsesTheFile) {
  const SweepConfig c = parse_sweep(kSweep, "demo.yaml", "/tmp/x");
  EXPECT_EQ(c.name, "demo");
  EXPECT_EQ(c.scenario, std::filesystem::path("/tmp/x/base.yaml"));
  ASSERT_EQ(c.grid.size(), 2u);
  EXPECT_EQ(c.grid[1].set.size(), 2u);
  EXPECT_TRUE(c.grid[1].vector3);
  ASSERT_EQ(c.grid[1].values.size(), 3u);
  EXPECT_NEAR(c.grid[1].values[2], 0.015, 1e-12);
  EXPECT_EQ(c.points(), 9u);
  EXPECT_EQ(c.runs(), 27u);
  ASSERT_EQ(c.fixed.size(), 1u);
  EXPECT_EQ(c.fixed[0].second, "5");
  ASSERT_EQ(c.plots.size(), 1u);
  EXPECT_EQ(c.plots[0].series, "noise");
}

TEST(Sweep, RejectsBadFilesWithFileAndKey) {
  EXPECT_THROW(parse_sweep("name: x\nbogus: 1\n", "a.yaml", "."), driftless::InputError);
  try {
    parse_sweep("grid:\n  a: [1, x]\n", "b.yaml", ".");
    FAIL();
  } catch (const driftless::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("b.yaml:2"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parse_sweep("runner: magic\n", "c.yaml", "."), driftless::InputError);
  EXPECT_THROW(parse_sweep("grid: {a: [1]}\nplots: [{x: b, y: [e]}]\n", "d.yaml", "."),
               driftless::InputError);
}

TEST(Sweep, OneTableReadsAndWritesTheFile) {
  // GIVEN the demo sweep read
  const SweepConfig c = parse_sweep(kSweep, "demo.yaml", "/tmp/x");
  // WHEN written through the same table and read again
  const std::string text = sweep_yaml(c);
  const SweepConfig back = parse_sweep(text, "back.yaml", "/elsewhere");
  // THEN every field comes back (the range as its values, the scenario path as written)
  EXPECT_EQ(back.name, c.name);
  EXPECT_EQ(back.runner, c.runner);
  EXPECT_EQ(back.scenario, c.scenario);
  EXPECT_EQ(back.duration_s, 60.0);
  EXPECT_EQ(back.monte_carlo, 3);
  EXPECT_EQ(back.seed, 7u);
  ASSERT_EQ(back.grid.size(), 2u);
  for (std::size_t a = 0; a < 2; ++a) {
    EXPECT_EQ(back.grid[a].name, c.grid[a].name);
    EXPECT_EQ(back.grid[a].set, c.grid[a].set);
    EXPECT_EQ(back.grid[a].values, c.grid[a].values);  // shortest exact numbers: bit for bit
    EXPECT_EQ(back.grid[a].vector3, c.grid[a].vector3);
  }
  EXPECT_EQ(back.fixed, c.fixed);
  ASSERT_EQ(back.plots.size(), 1u);
  EXPECT_EQ(back.plots[0].y, c.plots[0].y);
  EXPECT_TRUE(back.plots[0].logy);
  EXPECT_FALSE(back.plots[0].logx);
  // AND a key in another unit of the same quantity converts; one in another quantity is refused
  EXPECT_EQ(parse_sweep("duration_min: 2\n", "m.yaml", ".").duration_s, 120.0);
  try {
    parse_sweep("duration_deg: 2\n", "q.yaml", ".");
    FAIL() << "a duration in degrees passed";
  } catch (const driftless::InputError& e) {
    EXPECT_EQ(e.key(), "duration_deg");
  }
  // AND a plot without x names the key and the line
  try {
    parse_sweep("grid: {a: [1]}\nplots:\n  - {y: [e]}\n", "p.yaml", ".");
    FAIL() << "a plot without x passed";
  } catch (const driftless::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("p.yaml:3: plots[0].x: missing"), std::string::npos) << e.what();
  }
}

TEST(Sweep, ExpandsLastAxisFastestWithCommonSeeds) {
  const SweepConfig c = parse_sweep(kSweep, "demo.yaml", ".");
  const auto specs = expand(c);
  ASSERT_EQ(specs.size(), 27u);
  EXPECT_EQ(specs[0].values, (std::vector<double>{10, 0.005}));
  EXPECT_EQ(specs[3].values[1], 0.01);   // point 1: second noise value
  EXPECT_EQ(specs[9].values[0], 45.0);   // point 3: second angle
  for (const auto& s : specs) {
    EXPECT_EQ(s.index, s.point * 3 + s.mc);
    EXPECT_EQ(s.seed, specs[s.mc].seed);  // common random numbers across points
  }
  EXPECT_NE(specs[0].seed, specs[1].seed);
}

TEST(Sweep, ParallelTableIsIdenticalToSerialAndFailuresAreReported) {
  SweepConfig c = parse_sweep(kSweep, "demo.yaml", ".");
  const auto specs = expand(c);
  std::vector<std::size_t> all(specs.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  auto job = [](const RunSpec& s) {
    if (s.point == 4 && s.mc == 1) throw std::invalid_argument("bad value, for the test");
    return noise_job(s);
  };
  std::size_t calls = 0;
  const auto serial = run_parallel(specs, all, job, 1, [&](std::size_t d, std::size_t n) {
    ++calls;
    EXPECT_LE(d, n);
  });
  EXPECT_EQ(calls, specs.size());
  const auto parallel = run_parallel(specs, all, job, 4);
  const auto dir = std::filesystem::temp_directory_path() / ("test_sweep_out-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  EXPECT_EQ(write_outputs(c, specs, serial, dir / "serial", false), 1u);
  // results split over two "ranks" and gathered as text give the same table
  std::vector<RunResult> gathered;
  for (const auto& r : parallel) gathered.push_back(parse_result(serialize_result(r)));
  std::reverse(gathered.begin(), gathered.end());
  EXPECT_EQ(write_outputs(c, specs, gathered, dir / "gathered", false), 1u);
  EXPECT_EQ(slurp(dir / "serial/runs.csv"), slurp(dir / "gathered/runs.csv"));
  EXPECT_EQ(slurp(dir / "serial/summary.csv"), slurp(dir / "gathered/summary.csv"));
  const std::string runs = slurp(dir / "serial/runs.csv");
  EXPECT_NE(runs.find("failed: bad value; for the test"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir / "serial/plot_err_vs_flip_angle_deg.gp"));
  // the summary mean is the mean of the runs: noise_est at point 0 ~ 0.005
  const auto agg = summarize(c, serial);
  EXPECT_EQ(agg[0].at("noise_est").n, 3u);
  EXPECT_NEAR(agg[0].at("noise_est").mean, 0.005, 0.0005);
  EXPECT_EQ(agg[4].at("noise_est").n, 2u);  // one failed run left out
  // a missing result is refused: duplicated index
  auto dup = serial;
  dup.push_back(serial[0]);
  EXPECT_THROW(write_outputs(c, specs, dup, dir / "dup", false), std::runtime_error);
}

TEST(Sweep, SerializeRoundTripIsLossless) {
  RunResult r;
  r.index = 42;
  r.ok = true;
  r.metrics = {{"a", 0.1 + 0.2}, {"b", -1e-300}, {"c", std::nan("")}};
  const RunResult back = parse_result(serialize_result(r));
  EXPECT_EQ(back.index, 42u);
  EXPECT_TRUE(back.ok);
  ASSERT_EQ(back.metrics.size(), 3u);
  EXPECT_EQ(back.metrics[0].second, 0.1 + 0.2);
  EXPECT_EQ(back.metrics[1].second, -1e-300);
  EXPECT_TRUE(std::isnan(back.metrics[2].second));
}

}  // namespace
}  // namespace driftless::studies
