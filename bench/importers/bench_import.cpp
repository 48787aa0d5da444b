// Reading recordings made by others: the delimited-text reader on a 14 h, 100 Hz single-gyro CSV
// (5.04 M rows, the file `driftless allan --in` reads in the README's benchmark) and the .npy reader
// on six channels. Files are written once into the system temp folder.
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>

#include "importers/imu_reader.hpp"

namespace {

namespace fs = std::filesystem;
using namespace driftless;

constexpr std::size_t k14hSamples = 5'040'000;

// 'Fs,100' then a header 'gx' and one value per row with the log's 7 decimals (deg/s)
fs::path csv_file() {
  const fs::path p = fs::temp_directory_path() / "driftless_bench_allan_5m.csv";
  if (fs::exists(p)) return p;
  std::FILE* f = std::fopen(p.c_str(), "wb");
  std::fputs("Fs,100\ngx\n", f);
  std::mt19937_64 rng(1);
  std::normal_distribution<double> g(0.0, 0.05);
  for (std::size_t i = 0; i < k14hSamples; ++i) std::fprintf(f, "%.7f\n", 1.0 + g(rng));
  std::fclose(f);
  return p;
}

void BM_TextImport14h(benchmark::State& state) {
  const fs::path p = csv_file();
  std::size_t rows = 0;
  for (auto _ : state) {
    auto r = importers::open_imu(p, {});
    importers::ImuBlock b;
    rows = 0;
    while (r->read(b, 1u << 20)) rows += b.rows();
    benchmark::DoNotOptimize(rows);
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * rows));
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations() * fs::file_size(p)));
}
BENCHMARK(BM_TextImport14h)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
