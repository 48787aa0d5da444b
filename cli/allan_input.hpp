// `driftless allan` input: channels from a measurement log (raw, optionally DriftLess-corrected)
// or from any recording the importers read, with the rate, the gap breaks and every assumption.
// Either in memory (exact at every tau) or streamed into octave accumulators (bounded memory).
#pragma once

#include <array>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "estimator/allan.hpp"
#include "importers/imu_reader.hpp"
#include "importers/stamps.hpp"

namespace CLI {
class App;
}  // namespace CLI

namespace driftless::cli::allan {

/// The input options of `driftless allan` (and the reader options of `convert`).
struct InputArgs {
  std::string log, in, csv;     // exactly one; --csv is --in with --format text
  importers::ImportOptions import;
  std::string format = "auto";
  std::string columns, accel_columns;  // comma lists
  double rate_hz = 0.0;         // Hz, overrides the file's
  bool gaps_ignore = false;     // --gaps ignore: samples taken as contiguous across gaps
  bool corrected = false;       // log only: DriftLess-corrected channels too
  std::string config, mode;     // for --corrected
  // deg/s: the corrected channels start once every sigma of the correction is below this (the
  // filter has locked on, as in `estimate`'s Fig. 5); 0: from the first sample
  double corrected_lock_sigma_dps = 0.05;
  /// The importer options with the comma lists split and the format parsed.
  importers::ImportOptions import_options() const;
  const std::string& source() const { return !log.empty() ? log : !in.empty() ? in : csv; }
};

/// One analysed channel.
struct Channel {
  std::string name;
  importers::Quantity quantity = importers::Quantity::kRate;
  int axis = -1;
  std::vector<double> x;                  // deg/s or m/s^2
  std::vector<std::size_t> segment_starts;  // sample indices where a gap-free piece begins
};

/// What was read.
struct Loaded {
  std::vector<Channel> channels;
  double rate_hz = std::nan("");
  std::string format;                     // "log", "text", "euroc", "npy", "bag"
  std::vector<std::string> notes;         // assumptions, stamp findings, dropped rows, gap policy
  importers::StampReport stamps;
  // a DriftLess log: the range each platform's angle column spans (deg; NaN: no such column or no
  // value), which says whether the platforms flipped while the record ran
  std::array<double, 2> platform_span_deg{std::nan(""), std::nan("")};
};

/// Reads every channel into memory.
Loaded load(const InputArgs& a);

/// Means of consecutive blocks of about 1 s (round(rate) samples) of one channel, fed in pieces.
struct BlockMeans {
  explicit BlockMeans(double rate_hz);
  void push(std::span<const double> x);
  std::size_t per = 0;  // samples a block (0: no rate, nothing kept)
  std::vector<double> means;
  double sum = 0.0;
  std::size_t seen = 0, finite = 0;
};
/// True for the channels the motion check watches: raw rate channels (not accelerometers, not corrected).
bool watched_for_motion(const std::string& name, importers::Quantity q);
/// Warnings when the record is not at rest (a rate channel's 1 s means move by more than a gyro's bias
/// drift): its Allan deviation measures the motion. docs/allan.md.
std::vector<std::string> motion_warnings(const std::vector<std::string>& names, const std::vector<BlockMeans>& per_channel,
                                         double rate_hz);
/// The same for channels read into memory.
std::vector<std::string> motion_warnings(const Loaded& in);

/// The octave curves of a streamed input: curves[c][d] for channel c and deviation d.
struct Streamed {
  Loaded meta;                            // channels without samples, rate, notes, stamps
  std::vector<std::vector<est::AllanCurve>> curves;
  std::vector<std::string> warnings;      // the record is not at rest (motion_warnings)
};

/// Streams an imported input through octave accumulators (Allan and/or Hadamard) at bounded
/// memory: exact up to `exact_up_to_m` samples per cluster. Two threads share the channels.
Streamed stream_octaves(const InputArgs& a, const std::vector<est::Deviation>& devs, double confidence,
                        std::size_t exact_up_to_m);

/// The importer options shared by `allan --in` and `convert`: --format, --columns, --accel-columns,
/// --time-column, --units, --accel-units, --time-units, --separator, --no-header, --topic, --rate.
void add_import_options(CLI::App* cmd, InputArgs& in);

/// True when the input is read by the importers (not a driftless log).
bool is_imported(const InputArgs& a);

// ---- shared by the in-memory and the streaming readers ----

/// "a,b, c" -> {"a", "b", "c"}.
std::vector<std::string> split_list(const std::string& s);
/// The sample rate: --rate, else the file's own, else the stamps (regular: the step; bursty: the
/// mean); says which in `notes`. Throws std::invalid_argument when there is none.
double resolve_rate(double given, double nominal, const importers::StampReport& st, std::vector<std::string>& notes,
                    const std::string& source);
/// The stamp findings and the gap policy, as notes.
void add_stamp_notes(const importers::StampReport& st, const std::string& loc_word, bool ignore,
                     std::vector<std::string>& notes);
/// An imported input read into memory.
Loaded load_imported(const InputArgs& a);

}  // namespace driftless::cli::allan
