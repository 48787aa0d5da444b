// What `driftless allan` computed, and the writers of its outputs (tables, fit JSON, summary,
// Kalibr / OpenVINS / VINS-Mono noise files, plots, the round-trip check). Docs: docs/allan.md.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cli/allan_input.hpp"
#include "estimator/allan.hpp"
#include "estimator/allan_fit.hpp"

namespace driftless::cli::allan {

/// Datasheet values to draw beside the fit (`--datasheet N=..,B=..,K=..`), input units.
struct Datasheet {
  double N = 0.0, B = 0.0, K = 0.0;  // 0: not given
  bool any() const { return N > 0.0 || B > 0.0 || K > 0.0; }
};
/// Parses "N=0.005,B=0.01,K=0.0003" (deg/s family); throws std::invalid_argument on junk.
Datasheet parse_datasheet(const std::string& s);

/// The round trip of one channel: simulated records' 95 % band against the measured curve.
struct Validation {
  std::vector<double> tau_s, lo95, hi95;  // per octave tau of the measured curve
  std::size_t records = 0;
  double fails_at_tau_s = 0.0;            // s, the first tau outside the band (0: none)
  std::string verdict;                    // one sentence
  std::vector<std::string> notes;         // what the catalogue could not represent
};

/// One analysed channel.
struct ChannelResult {
  std::string name;
  importers::Quantity quantity = importers::Quantity::kRate;
  int axis = -1;
  std::vector<est::AllanCurve> curves;  // per requested deviation
  est::AllanCurve fit_curve;            // the octave overlapping ADEV the fit uses
  est::NoiseFit fit;
  std::optional<Validation> validation;
};

/// Everything `driftless allan` found.
struct Result {
  std::string source, format;
  double rate_hz = 0.0;
  std::size_t samples = 0;
  std::vector<est::Deviation> deviations;
  std::vector<std::string> notes;
  std::vector<std::string> warnings;    // what makes the figures wrong for the sensor (a record that moves)
  importers::StampReport stamps;
  std::vector<ChannelResult> channels;
  Datasheet datasheet;
};

/// allan.csv (overlapping ADEV, wide), <dev>.csv for the others, allan_points.csv (long form with
/// edf and noise type).
void write_tables(const std::filesystem::path& dir, const Result& r);
/// allan_fit.json: every parameter with sigma, bound, region and note, per channel.
void write_fit_json(const std::filesystem::path& dir, const Result& r);
/// The console summary.
void print_summary(const Result& r);

/// Export options: noise-density / random-walk inflation factor and the topic written.
struct ExportOptions {
  bool kalibr = false, openvins = false, vins_mono = false;
  double inflate = 1.0;
  std::string topic = "/imu0";
};
/// Writes the requested noise files; returns the paths written.
std::vector<std::filesystem::path> write_exports(const std::filesystem::path& dir, const Result& r, const ExportOptions& o);

/// Simulates `records` records of the same length from each channel's fit with the twin's sensor
/// model and attaches the 95 % band and the verdict.
void validate_round_trip(Result& r, std::size_t records, std::uint64_t seed);

/// allan.png/svg (every channel) and allan_<channel>.png/svg (bars, terms, model, datasheet, band).
/// Returns warnings (gnuplot missing or failing).
std::vector<std::string> write_plots(const std::filesystem::path& dir, const Result& r);

}  // namespace driftless::cli::allan
