// Writing a comparison: DIR/diagnosis.json and a self-contained DIR/report.html (plots drawn by
// gnuplot to PNG and embedded as base64; no external scripts or fonts). docs/compare.md.
#pragma once

#include <filesystem>
#include <string>

#include "diagnose/compare.hpp"

namespace driftless::diagnose {

/// Optional second comparison of the same log (e.g. with the model after --apply).
struct ReportExtras {
  const CompareResult* after = nullptr;  // the same log against the updated model
  std::string after_model;               // its source
  std::string applied;                   // what was applied, one line
};

/// diagnosis.json text (deterministic: same input, same bytes).
std::string diagnosis_json(const CompareResult& r, const ReportExtras& extras = {});
/// Writes DIR/diagnosis.json and DIR/report.html (creates DIR). Plots need gnuplot on PATH;
/// without it the report says so and keeps the tables.
void write_report(const CompareResult& r, const std::filesystem::path& dir, const ReportExtras& extras = {});

}  // namespace driftless::diagnose
