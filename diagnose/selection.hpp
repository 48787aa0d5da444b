// Model selection as a whole: forward stepwise. Each step evaluates every parameter of every
// physical, box, signal-chain and ADC effect given the effects already selected (joint MAP fit
// with the nuisance), adds the effect whose supported parameters add the most evidence, refits
// everything selected jointly, drops parameters no longer supported, refits the white noise
// level, and stops when no effect is supported. docs/compare.md section 3.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "diagnose/channel_fit.hpp"
#include "diagnose/compare.hpp"
#include "diagnose/signal_chain.hpp"

namespace driftless::diagnose {

/// What the selection works on.
struct SelectionInput {
  Channels& ch;                         // white densities are refitted as effects are taken out
  const Replay& r;
  const Residual& res;
  const CompareModel& model;
  std::array<NoiseColour, 2> colour;    // measured noise colour per sensor
  std::vector<Candidate> adc;           // ADC candidates, evaluated on the raw output
  double threshold = 10.0;
  int max_steps = 12;
};

/// The selected set and its joint fit.
struct Selection {
  FitSpec spec;                         // selected parameters (low-pass delays held at their fit)
  FitResult fit;
  std::vector<Candidate> selected;      // in selection order
  std::vector<Candidate> not_supported; // every other effect, evaluated given the selection
  std::vector<std::string> notes;
};

/// Runs the forward stepwise selection.
Selection select_effects(SelectionInput& in);

}  // namespace driftless::diagnose
