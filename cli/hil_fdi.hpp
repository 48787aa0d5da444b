// driftless hil --fdi: the fault detection's outputs (docs/hil.md, "Fault detection"): DIR/fdi.json,
// the verdict lines on the terminal and what the verdict means for the exit status.
#pragma once

#include <filesystem>

#include "hil_bridge/fdi_watch.hpp"

namespace driftless::cli {

/// Writes `path` (format driftless-fdi 1): verdict, first alarm, the isolated fault, the learned
/// residual noise, the tested samples.
void write_fdi_json(const std::filesystem::path& path, const hil::FdiWatch& watch);

/// Prints the verdict with its cause and fix; returns 1 when a fault, an alarm, or no monitoring
/// at all (too little rest data) is the result, else 0.
int report_fdi(const hil::FdiWatch& watch, const std::filesystem::path& json_path);

}  // namespace driftless::cli
