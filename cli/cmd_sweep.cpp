// driftless sweep: a grid of parameters x Monte-Carlo seeds over local threads and, when started
// by mpirun in an MPI build, over ranks; one table gathered on rank 0. Format: docs/sweep.md.
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <fmt/core.h>

#ifdef DRIFTLESS_HAVE_MPI
#include <mpi.h>
#endif

#include "cli/command.hpp"
#include "estimator/output_file.hpp"
#include "studies/jobs.hpp"
#include "studies/sweep.hpp"

namespace driftless::cli {
namespace {

using namespace driftless::studies;

struct SweepOptions {
  std::string config;
  std::string out;
  int jobs = 0;
  bool no_plots = false;
  bool save_logs = false;
};

// a rank's share: what it ran, or why it could not run at all
struct RankReport {
  int rank = 0;
  std::string error;                 // set when the rank failed as a whole
  std::vector<RunResult> results;
};

#ifdef DRIFTLESS_HAVE_MPI
std::string pack(const RankReport& r) {
  std::string s = r.error.empty() ? "OK\n" : "ERROR\t" + r.error + "\n";
  for (const auto& x : r.results) s += serialize_result(x) + "\n";
  return s;
}

RankReport unpack(int rank, const std::string& text) {
  RankReport r;
  r.rank = rank;
  std::istringstream in(text);
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    if (first) {
      first = false;
      if (line.rfind("ERROR\t", 0) == 0) r.error = line.substr(6);
      continue;
    }
    if (!line.empty()) r.results.push_back(parse_result(line));
  }
  return r;
}
#endif

int default_threads(int local_ranks) {
  const int hw = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  return std::max(1, hw / std::max(1, local_ranks));
}

int env_int(const char* name, int fallback) {
  const char* v = std::getenv(name);
  return v ? std::atoi(v) : fallback;
}

#ifdef DRIFTLESS_HAVE_MPI
// MPI only when a launcher started us (mpirun sets these); a plain run stays single-process
bool launched_by_mpirun() {
  return std::getenv("OMPI_COMM_WORLD_SIZE") || std::getenv("PMI_SIZE") || std::getenv("PMIX_RANK");
}
#endif

int run_sweep(const SweepOptions& opt) {
  int rank = 0, size = 1;
#ifdef DRIFTLESS_HAVE_MPI
  const bool mpi = launched_by_mpirun();
  if (mpi) {
    MPI_Init(nullptr, nullptr);
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
  }
  struct Finalize {
    bool on;
    ~Finalize() {
      if (on) MPI_Finalize();
    }
  } finalize{mpi};
#endif
  const auto t0 = std::chrono::steady_clock::now();
  // every rank reads the file (cheap); a bad file fails every rank the same way
  const SweepConfig cfg = load_sweep(opt.config);
  const auto specs = expand(cfg);
  const int threads = opt.jobs > 0 ? opt.jobs
                                   : default_threads(env_int("OMPI_COMM_WORLD_LOCAL_SIZE", 1));
  RankReport mine;
  mine.rank = rank;
  std::vector<std::size_t> indices;
  for (std::size_t i = static_cast<std::size_t>(rank); i < specs.size(); i += static_cast<std::size_t>(size)) {
    indices.push_back(i);
  }
  if (rank == 0) {
    fmt::print("driftless sweep '{}': {} grid points x {} seeds = {} runs ({} runner), {} rank(s) "
               "x {} thread(s)\n",
               cfg.name, cfg.points(), cfg.monte_carlo, specs.size(), cfg.runner, size, threads);
    std::fflush(stdout);
  }
  try {
    const SweepJob job =
        make_job(cfg, opt.save_logs ? std::filesystem::path(opt.out) / "logs" : std::filesystem::path(),
                 &stop_requested());
    Progress progress(fmt::format("sweep {} (rank 0 share)", cfg.name));
    mine.results = run_parallel(
        specs, indices, job, threads,
        [&](std::size_t done, std::size_t total) {
          if (rank == 0) progress.update(static_cast<double>(done) / static_cast<double>(total),
                                         fmt::format("{}/{} runs", done, total));
        },
        &stop_requested());
    if (rank == 0) progress.done(fmt::format("{} runs", mine.results.size()));
  } catch (const std::exception& e) {
    mine.error = e.what();
  }

  // gather every rank's results on rank 0 as text
  std::vector<RankReport> reports;
#ifdef DRIFTLESS_HAVE_MPI
  if (mpi) {
    const std::string text = pack(mine);
    int len = static_cast<int>(text.size());
    std::vector<int> lens(static_cast<std::size_t>(size)), displs(static_cast<std::size_t>(size));
    MPI_Gather(&len, 1, MPI_INT, lens.data(), 1, MPI_INT, 0, MPI_COMM_WORLD);
    std::vector<char> all;
    if (rank == 0) {
      int total = 0;
      for (int r = 0; r < size; ++r) {
        displs[r] = total;
        total += lens[r];
      }
      all.resize(static_cast<std::size_t>(std::max(1, total)));
    }
    MPI_Gatherv(text.data(), len, MPI_CHAR, all.data(), lens.data(), displs.data(), MPI_CHAR, 0,
                MPI_COMM_WORLD);
    if (rank != 0) return mine.error.empty() ? 0 : 1;
    for (int r = 0; r < size; ++r) {
      reports.push_back(unpack(r, std::string(all.data() + displs[r], static_cast<std::size_t>(lens[r]))));
    }
  } else {
    reports.push_back(mine);
  }
#else
  reports.push_back(mine);
#endif

  std::vector<RunResult> results;
  int failed_ranks = 0;
  double serial_s = 0;
  for (const auto& rep : reports) {
    if (!rep.error.empty()) {
      ++failed_ranks;
      fmt::print(stderr, "driftless sweep: rank {} failed: {}\n", rep.rank, rep.error);
    }
    std::size_t bad = 0;
    for (const auto& r : rep.results) {
      serial_s += r.wall_s;
      if (!r.ok) {
        ++bad;
        fmt::print(stderr, "driftless sweep: rank {}: run {} failed: {}\n", rep.rank, r.index, r.error);
      }
      results.push_back(r);
    }
    if (bad) fmt::print(stderr, "driftless sweep: rank {}: {} of {} runs failed\n", rep.rank, bad, rep.results.size());
  }
  std::vector<std::string> plot_warnings;
  const std::size_t failed = write_outputs(cfg, specs, results, opt.out, !opt.no_plots, &plot_warnings);
  for (const auto& w : plot_warnings) fmt::print(stderr, "driftless sweep: warning: {}\n", w);
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  {
    std::ostringstream t;
    t << "# wall time is not part of the table (not reproducible)\n"
      << "ranks: " << size << "\nthreads_per_rank: " << threads << "\nwall_s: " << wall
      << "\nsum_of_run_times_s: " << serial_s << "\nspeedup: " << (wall > 0 ? serial_s / wall : 0)
      << "\n";
    io::write_file(std::filesystem::path(opt.out) / "timing.txt", t.str());
  }
  fmt::print("{} runs, {} failed; wall {:.1f} s, sum of run times {:.1f} s (speed-up {:.2f}x); "
             "table: {}/runs.csv, {}/summary.csv\n",
             specs.size(), failed, wall, serial_s, wall > 0 ? serial_s / wall : 0.0, opt.out, opt.out);
  if (stop_requested()) fmt::print(stderr, "driftless sweep: stopped; unfinished runs are marked failed\n");
  return failed == 0 && failed_ranks == 0 ? 0 : 1;
}

const bool registered_sweep = register_command(60, [](CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "sweep",
      "Run a parameter grid x Monte-Carlo seeds (docs/sweep.md) in parallel over the local cores "
      "(and over MPI ranks under mpirun); writes runs.csv, summary.csv and gnuplot plots");
  auto opt = std::make_shared<SweepOptions>();
  cmd->add_option("--config", opt->config, "Sweep file (YAML, models/sweeps/*.yaml)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", opt->out, "Output folder (created): runs.csv, summary.csv, plots")
      ->required();
  cmd->add_option("--jobs,-j", opt->jobs,
                  "Worker threads per process (count; 0 = all cores / ranks on this node)");
  cmd->add_flag("--no-plots", opt->no_plots, "Write the gnuplot scripts but do not run gnuplot");
  cmd->add_flag("--save-logs", opt->save_logs,
                "Also write every run's samples to OUT/logs/run_<index>.csv (driftless-log 1)");
  return [opt] { return run_sweep(*opt); };
}, Interrupt::kPolls);

}  // namespace
}  // namespace driftless::cli
