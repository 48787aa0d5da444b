// Sensitivity sweeps (paper section 3): a grid of parameters x Monte-Carlo seeds, run in
// parallel over local threads (and over MPI ranks by the CLI), gathered into one table.
// File format and outputs: docs/sweep.md.
#pragma once

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace driftless::studies {

/// One swept parameter: a name (a table column) and the values it takes. Each value is written
/// into every scenario key path in `set` (e.g. model.sensor1.effects.white_noise.density_dps_rthz)
/// or, for paths starting with "estimator.", into the filter configuration.
struct GridAxis {
  std::string name;                 // column name; carries its unit (flip_angle_deg)
  std::vector<std::string> set;     // dotted key paths the value goes to (default: {name})
  std::vector<double> values;
  bool vector3 = false;             // write [v, v, v] (for per-axis 3-vector keys)
  bool boolean = false;             // write true (v != 0) or false (for enabled switches)
};

/// Which plot to draw from the summary table (gnuplot).
struct PlotSpec {
  std::string x;                    // grid axis on the x axis
  std::vector<std::string> y;       // metrics, one plot each
  std::string series;               // optional grid axis drawn as separate lines
  bool logx = false, logy = false;
};

/// A sweep file.
struct SweepConfig {
  std::string name;
  std::string description;
  std::string runner = "fast";      // fast | twin | fdi | fdi_twin  (docs/sweep.md)
  std::filesystem::path scenario;   // base scenario file (resolved), or a built-in name
  double duration_s = 0.0;          // s, overrides the scenario's duration when > 0
  int monte_carlo = 1;              // seeds per grid point
  std::uint64_t seed = 1;           // base seed; run seed = f(seed, mc index) (common random numbers)
  std::vector<GridAxis> grid;
  std::vector<std::pair<std::string, std::string>> fixed;  // key path -> YAML value text, all runs
  std::vector<PlotSpec> plots;
  std::filesystem::path file;       // where it was read from

  /// Throws std::invalid_argument naming the file and field.
  void validate() const;
  std::size_t points() const;       // product of the grid sizes (1 for an empty grid)
  std::size_t runs() const { return points() * static_cast<std::size_t>(monte_carlo); }
};

/// Reads a sweep file; errors name the file, line and key (std::runtime_error).
SweepConfig load_sweep(const std::filesystem::path& path);
/// Parses sweep YAML text (`file` names it in messages, `base_dir` resolves `scenario:`).
SweepConfig parse_sweep(const std::string& yaml_text, const std::string& file,
                        const std::filesystem::path& base_dir);
/// The sweep as YAML text (the same table as parse_sweep; `range:` axes written as their values).
std::string sweep_yaml(const SweepConfig& c);

/// One run of the sweep.
struct RunSpec {
  std::size_t index = 0;            // 0-based, point-major: index = point * monte_carlo + mc
  std::size_t point = 0;
  int mc = 0;
  std::uint64_t seed = 0;
  std::vector<double> values;       // one per grid axis
};

/// Every run, in index order (last grid axis varies fastest, then the Monte-Carlo index).
std::vector<RunSpec> expand(const SweepConfig& cfg);
/// The seed of Monte-Carlo run `mc` (31 bits of rnd::mix64 of the base seed and mc; same for every point).
std::uint64_t run_seed(std::uint64_t base_seed, int mc);

/// Named results of one run, in a fixed order.
using Metrics = std::vector<std::pair<std::string, double>>;

/// What a run gave: metrics, or the error that stopped it.
struct RunResult {
  std::size_t index = 0;
  bool ok = false;
  std::string error;                // one line, when !ok
  Metrics metrics;
  double wall_s = 0.0;              // s, not part of the table (not reproducible)
};

/// A run: pure function of the spec (its seed and values). May throw; the runner records it.
using SweepJob = std::function<Metrics(const RunSpec&)>;

/// Runs `indices` of `specs` on `threads` threads (0 = all hardware threads). `on_done(done,
/// total)` is called from the workers under a lock after each run. Stops early (remaining runs
/// marked failed "stopped") when `stop` becomes true. Results come back in `indices` order.
std::vector<RunResult> run_parallel(const std::vector<RunSpec>& specs,
                                    const std::vector<std::size_t>& indices, const SweepJob& job,
                                    int threads,
                                    const std::function<void(std::size_t, std::size_t)>& on_done = {},
                                    const std::atomic<bool>* stop = nullptr);

/// A result as one text line (lossless doubles), for gathering over MPI; parse_result inverts it.
std::string serialize_result(const RunResult& r);
RunResult parse_result(const std::string& line);

/// Writes DIR/runs.csv (one row per run), DIR/summary.csv (mean, std, min, max per grid point),
/// DIR/<plot>.gp gnuplot scripts and, with `run_gnuplot`, DIR/<plot>.png. `results` must hold
/// every index once. Returns the number of failed runs; a plot gnuplot could not draw adds its
/// reason to `plot_warnings` (nothing is printed).
std::size_t write_outputs(const SweepConfig& cfg, const std::vector<RunSpec>& specs,
                          const std::vector<RunResult>& results, const std::filesystem::path& dir,
                          bool run_gnuplot = true, std::vector<std::string>* plot_warnings = nullptr);

/// Aggregate of one metric at one grid point over its successful Monte-Carlo runs.
struct Aggregate {
  std::size_t n = 0;
  double mean = 0, std = 0, min = 0, max = 0, rms = 0;
};
/// Per grid point (index), per metric name.
std::vector<std::map<std::string, Aggregate>> summarize(const SweepConfig& cfg,
                                                        const std::vector<RunResult>& results);

}  // namespace driftless::studies
