// Writing a comparison: DIR/diagnosis.json and a self-contained DIR/report.html (plots drawn by
// gnuplot to PNG and embedded as base64; no external scripts or fonts). docs/compare.md.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "diagnose/compare.hpp"

namespace driftless::diagnose {

/// What the report says besides the comparison: the command that made it, and optionally a
/// second comparison of the same log (with the model after --apply, or compare --model --before).
struct ReportExtras {
  std::string command = "compare";       // "compare" or "diagnose": the page title names it
  const CompareResult* after = nullptr;  // the same log against the updated model
  std::string after_model;               // its source
  std::vector<std::string> applied;      // what was written, one line each
  std::vector<std::string> skipped;      // what could not be written, and why
};

/// diagnosis.json text (deterministic: same input, same bytes).
std::string diagnosis_json(const CompareResult& r, const ReportExtras& extras = {});
/// Writes DIR/diagnosis.json and DIR/report.html (creates DIR). Plots need gnuplot on PATH;
/// without it the report says so and keeps the tables.
void write_report(const CompareResult& r, const std::filesystem::path& dir, const ReportExtras& extras = {});

}  // namespace driftless::diagnose
