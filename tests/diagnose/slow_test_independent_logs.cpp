// The acceptance tests of diagnosis on logs this project did not make (independent_log.py),
// diagnosed with the embedded default model as `driftless diagnose` without --model:
//   - a planted physical effect is the first physical effect selected, on the right sensor and
//     axis, within 20 %, whatever the signal chain around it (>= 95 % of seeds);
//   - a planted signal-chain effect (another DLPF, a lagging sensor, a box time offset) is
//     found as itself;
//   - logs with nothing planted are consistent, or report only their signal-chain mismatch;
//   - two and three effects at once are all found in one run;
//   - after --apply, the next comparison is consistent_with_noise.
// Each test prints its rate; docs/compare.md quotes them (measured with DRIFTLESS_INDEP_SEEDS=24).
// The thresholds are the 95 % (the 24-seed sweep meets it on every row since the fifth
// stop; docs/compare.md "Measured" says where it stands).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <random>
#include <string>
#include <utility>

#include "tests/diagnose/independent_logs.hpp"

namespace driftless::diagnose {
namespace {

using indep::Source;

// seeds per sweep: lean by default (CI), DRIFTLESS_INDEP_SEEDS=N for the full sweep
int sweep_seeds(int lean) {
  const char* env = std::getenv("DRIFTLESS_INDEP_SEEDS");
  return env ? std::max(1, std::atoi(env)) : lean;
}

// DRIFTLESS_INDEP_ONLY=SEED runs that seed of each sweep only (to study one case by hand; the
// rates are then not the sweep's)
bool skipped(int seed) {
  const char* env = std::getenv("DRIFTLESS_INDEP_ONLY");
  return env && std::atoi(env) != seed;
}

// at least `fraction` of n (rounded down)
int at_least(double fraction, int n) { return static_cast<int>(std::floor(fraction * n)); }

// a planted effect: the generator argument and what diagnose must report
struct Plant {
  std::string arg;
  Effect effect;
  std::string param;
  double value;
  bool temperature = false;
};

// g-sensitivity needs the specific force along its column to vary while the platforms rest:
// sensor 2 rests at +-90 deg about x, so gravity is on its y axis (its sign swaps with each flip)
// and the pitch tilts it onto its x axis; its z axis sees none of it at rest (seeds 313 and 322
// planted s2 columns z, which change no sample the fits use: "not identified" was right, and
// they were counted as misses); sensor 1 rests at +-90 deg
// about z, so its x axis is the box's y axis, which only a roll tilts, and no motion of the
// generator rolls (its pan/tilt and sweep pitch): a planted x column changes no sample the fits
// use (seed 11 planted s1 x<-x and the log was rightly consistent). Its y axis is the box's x
// axis, which the pitch tilts (pan/tilt and sweep, not the small wobble)
Plant random_plant(std::mt19937& g, const std::string& motion) {
  auto uni = [&](int n) { return std::uniform_int_distribution<int>(0, n - 1)(g); };
  const int s = 1 + uni(2);
  const char* ax = "xyz";
  const double sign = uni(2) ? 1.0 : -1.0;
  switch (uni(6)) {
    case 0: {
      const char a = ax[uni(3)];
      return {fmt::format("scale:{}:{}:{}", s, a, 3 * sign), Effect::kScaleFactor, fmt::format("s{}.{}.value_pct", s, a), 3 * sign};
    }
    case 1: {
      const int r = uni(3), c = (r + 1 + uni(2)) % 3;
      return {fmt::format("misalign:{}:{}:{}:{}", s, ax[r], ax[c], 2 * sign), Effect::kMisalignment,
              fmt::format("s{}.matrix_pct[{}][{}]", s, ax[r], ax[c]), 2 * sign};
    }
    case 2: {
      const int sg = motion == "wobble" ? 2 : s;
      const int r = uni(3), pick = uni(2), c = sg == 2 ? pick : 1;
      return {fmt::format("gsens:{}:{}:{}:{}", sg, ax[r], ax[c], 0.1 * sign), Effect::kGSensitivity,
              fmt::format("s{}.matrix_dps_per_g[{}][{}]", sg, ax[r], ax[c]), 0.1 * sign};
    }
    case 3: {
      // not about the platform's hinge axis (z for sensor 1, x for sensor 2): that rotation reads
      // the same as equal end-stop errors
      const char a = s == 1 ? "xy"[uni(2)] : "yz"[uni(2)];
      return {fmt::format("mount:{}:{}:{}", s, a, 0.8 * sign), Effect::kMountingMisalignment,
              fmt::format("s{}.angles_deg[{}]", s, a), 0.8 * sign};
    }
    case 4: {
      const char* side = uni(2) ? "plus" : "minus";
      return {fmt::format("stop:{}:{}:{}", s, side, 0.4 * sign), Effect::kEndStopError, fmt::format("s{}.{}_stop_deg", s, side), 0.4 * sign};
    }
    default: {
      const char a = ax[uni(3)];
      return {fmt::format("tempco:{}:{}:{}", s, a, 0.1 * sign), Effect::kTemperature,
              fmt::format("s{}.{}.bias_tc_dps_per_degc", s, a), 0.1 * sign, true};
    }
  }
}

// the planted effect is selected, first among the non-signal-chain effects, within 20 %
bool found_first(const CompareResult& r, const Plant& p, std::string* why) {
  for (const auto& c : r.selected) {
    if (c.family() == Family::kSignalChain) continue;
    if (c.effect != p.effect) {
      *why = fmt::format("{} selected before {}", effect_id(c.effect), effect_id(p.effect));
      return false;
    }
    const FittedParam* fp = find_param(c, p.param);
    if (!fp) {
      *why = fmt::format("{} found without {}", effect_id(c.effect), p.param);
      return false;
    }
    if (std::abs(fp->new_value() - p.value) > 0.2 * std::abs(p.value)) {
      *why = fmt::format("{} = {:.4g}, planted {:.4g}", p.param, fp->new_value(), p.value);
      return false;
    }
    return true;
  }
  *why = "not selected";
  return false;
}

// every selected effect is a signal-chain one (the mismatch the source has built in)
bool only_signal_chain(const CompareResult& r) {
  for (const auto& c : r.selected)
    if (c.family() != Family::kSignalChain) return false;
  return true;
}

TEST(IndependentLogs, PlantedPhysicalEffectIsFoundFirst) {
  int ok = 0, first_overall = 0, applied_ok = 0, applied = 0;
  std::map<std::string, std::pair<int, int>> per_effect;  // effect id: (found first, planted)
  const int seeds = sweep_seeds(12);
  for (int seed = 1; seed <= seeds; ++seed) {
    if (skipped(seed)) continue;
    std::mt19937 g(static_cast<unsigned>(seed) * 104729u);
    Source src = indep::random_source(seed, true);
    const Plant p = random_plant(g, src.motion);
    src.plants = {p.arg};
    src.temperature = p.temperature;
    const auto log = indep::generate(src, "plant");
    const CompareResult r = indep::diagnose_log(log);
    std::string why;
    const bool found = found_first(r, p, &why);
    ok += found;
    auto& tally = per_effect[effect_id(p.effect)];
    tally.first += found, ++tally.second;
    if (!found) std::printf("MISS %s: %s\n  %s\n", indep::describe(src).c_str(), why.c_str(), r.statement.c_str());
    if (!r.selected.empty() && r.selected.front().effect == p.effect) ++first_overall;
    if (seed % 3 == 0) {  // the loop on every third seed: apply, compare again
      ++applied;
      const CompareResult again = indep::apply_and_compare(log, r, "plant");
      if (again.verdict == Verdict::kConsistent) ++applied_ok;
      else std::printf("APPLY %s: %s\n", indep::describe(src).c_str(), again.statement.c_str());
    }
    std::filesystem::remove(log);
  }
  std::printf("planted physical effect found first among physical effects within 20 %%: %d / %d (first overall: %d); "
              "after --apply consistent: %d / %d\n", ok, seeds, first_overall, applied_ok, applied);
  for (const auto& [id, t] : per_effect) std::printf("  %s: %d / %d\n", id.c_str(), t.first, t.second);
  EXPECT_GE(ok, at_least(0.95, seeds));
  EXPECT_GE(applied_ok, at_least(0.95, applied));
}

TEST(IndependentLogs, NothingPlantedIsConsistentOrItsSignalChain) {
  int ok = 0, consistent = 0;
  const int seeds = sweep_seeds(12);
  for (int seed = 101; seed < 101 + seeds; ++seed) {
    if (skipped(seed)) continue;
    const Source src = indep::random_source(seed, true);
    const auto log = indep::generate(src, "clean");
    const CompareResult r = indep::diagnose_log(log);
    std::filesystem::remove(log);
    if (r.verdict == Verdict::kConsistent) ++consistent;
    if (r.verdict == Verdict::kConsistent || (r.verdict == Verdict::kMissingEffect && only_signal_chain(r))) ++ok;
    else std::printf("CLEAN %s: %s\n", indep::describe(src).c_str(), r.statement.c_str());
  }
  std::printf("nothing planted: %d / %d consistent or only their signal-chain mismatch (%d consistent)\n", ok, seeds, consistent);
  EXPECT_GE(ok, at_least(0.95, seeds));
}

TEST(IndependentLogs, SignalChainEffectsAreFoundAsThemselves) {
  int ok = 0, n = 0;
  for (int seed = 201; seed < 201 + sweep_seeds(9); ++seed) {
    if (skipped(seed)) continue;
    Source src = indep::random_source(seed, false);
    // a lag or a time offset alone: the source has the model's filter (DLPF_CFG 3); another
    // filter besides is the multi-effect test's case (its split from a delay rests on the noise
    // colour)
    if (seed % 3 != 2) src.dlpf = "cfg:3";
    std::mt19937 g(static_cast<unsigned>(seed));
    const int kind = seed % 3;
    Effect want = Effect::kSampleDelay;
    std::string param;
    double value = 0.0;
    if (kind == 0) {  // a sensor sampled 12-25 ms late
      src.lag_sensor = 1 + static_cast<int>(g() % 2);
      src.lag_s = std::uniform_real_distribution<double>(0.012, 0.025)(g);
      param = fmt::format("s{}.delay_s", src.lag_sensor);
      value = src.lag_s;
    } else if (kind == 1) {  // the box's time stamps 15 ms late
      src.time_offset_s = 0.015;
      want = Effect::kTimeOffset;
      param = "offset_s";
      value = 0.015;
    } else {  // another DLPF than the model's DLPF_CFG 3 (4.8 ms), on both chips
      src.dlpf = g() % 2 ? "cfg:5" : "cfg:1";
      want = Effect::kLowpass;
      param = "delay_s";
      value = src.dlpf == "cfg:5" ? 13.4e-3 : 1.9e-3;
    }
    const auto log = indep::generate(src, "chain");
    const CompareResult r = indep::diagnose_log(log);
    std::filesystem::remove(log);
    ++n;
    const Candidate* c = indep::selected(r, want);
    const FittedParam* fp = c ? find_param(*c, param) : nullptr;
    if (c && !fp && want == Effect::kLowpass) fp = find_param(*c, "s1.delay_s");  // per-sensor form
    // a delay within 20 % or 1 ms (DLPF delays of 2 ms are read against a 4.8 ms model)
    const bool good = fp && std::abs(fp->new_value() - value) <= std::max(0.2 * value, 1e-3) && only_signal_chain(r);
    if (good) ++ok;
    else std::printf("CHAIN %s (want %s %s = %.4g): %s\n", indep::describe(src).c_str(), effect_id(want), param.c_str(), value,
                     r.statement.c_str());
  }
  std::printf("signal-chain effects found as themselves: %d / %d\n", ok, n);
  EXPECT_GE(ok, at_least(0.95, n));
}

TEST(IndependentLogs, TwoAndThreeEffectsInOneRun) {
  int ok = 0, applied_ok = 0, applied2_ok = 0;
  const int seeds = sweep_seeds(6);
  for (int seed = 301; seed < 301 + seeds; ++seed) {
    if (skipped(seed)) continue;
    std::mt19937 g(static_cast<unsigned>(seed) * 31u);
    Source src = indep::random_source(seed, false);
    src.dlpf = "none";  // the signal-chain mismatch: no DLPF against the model's DLPF_CFG 3
    // two effects: a physical one and the signal chain; three: another physical one (odd
    // seeds) or sensor 2 sampling 18 ms late (every third seed)
    std::vector<Plant> plants{random_plant(g, src.motion)};
    while (seed % 2 == 1 && plants.size() < 2) {
      const Plant q = random_plant(g, src.motion);
      if (q.effect != plants[0].effect) plants.push_back(q);
    }
    if (seed % 3 == 0) {
      src.lag_sensor = 2;
      src.lag_s = 0.018;
    }
    for (const auto& p : plants) {
      src.plants.push_back(p.arg);
      src.temperature = src.temperature || p.temperature;
    }
    const auto log = indep::generate(src, "multi");
    const CompareResult r = indep::diagnose_log(log);
    bool all = indep::selected(r, Effect::kLowpass) != nullptr || indep::selected(r, Effect::kTimeOffset) != nullptr;
    for (const auto& p : plants) {
      const Candidate* c = indep::selected(r, p.effect);
      const FittedParam* fp = c ? find_param(*c, p.param) : nullptr;
      all = all && fp && std::abs(fp->new_value() - p.value) <= 0.2 * std::abs(p.value);
    }
    if (src.lag_sensor) all = all && indep::selected(r, Effect::kSampleDelay) != nullptr;
    if (all) ++ok;
    else std::printf("MULTI %s: %s\n", indep::describe(src).c_str(), r.statement.c_str());
    // the claim: consistent after at most two applies (the second from the first's model)
    CompareModel m = default_compare_model();
    const CompareResult again = indep::apply_and_compare(log, r, "multi", &m);
    if (again.verdict == Verdict::kConsistent) {
      ++applied_ok, ++applied2_ok;
    } else {
      std::printf("MULTI APPLY %s: %s\n", indep::describe(src).c_str(), again.statement.c_str());
      const CompareResult third = indep::apply_and_compare(log, again, "multi", &m);
      if (third.verdict == Verdict::kConsistent) ++applied2_ok;
      else std::printf("MULTI APPLY 2 %s: %s\n", indep::describe(src).c_str(), third.statement.c_str());
    }
    std::filesystem::remove(log);
  }
  std::printf("two and three effects (one a signal-chain mismatch) all found in one run: %d / %d; consistent after "
              "one --apply: %d / %d, after at most two: %d / %d\n", ok, seeds, applied_ok, seeds, applied2_ok, seeds);
  EXPECT_GE(ok, at_least(0.95, seeds));
  EXPECT_GE(applied_ok, at_least(0.95, seeds));
  EXPECT_GE(applied2_ok, at_least(0.95, seeds));
}

}  // namespace
}  // namespace driftless::diagnose
