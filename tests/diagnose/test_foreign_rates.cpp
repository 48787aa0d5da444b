// Diagnose on logs of other rates and other sensors than the model's: made by the outsider's
// generator (tests/diagnose/probe_log.py: numpy only, its own rotations, flips and sensor
// presets, white noise as sigma = N sqrt(fs) per sample, no low-pass) and by
// tests/diagnose/independent_log.py, both written apart from twin/. Diagnosed with the embedded
// default model (the nominal MPU6050, DLPF_CFG 3: 42 Hz, 4.8 ms), as `driftless diagnose`.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>

#include <fmt/core.h>

#include "diagnose/summary.hpp"
#include "tests/diagnose/independent_logs.hpp"
#include "tests/temp_path.hpp"

namespace driftless::diagnose {
namespace {

// probe_log.py with `args` into the temp folder (GTest fails on a generator error)
std::filesystem::path probe_log(const std::string& args, const std::string& tag) {
  const auto path = test::temp_path(fmt::format("driftless_probe_{}.csv", tag));
  const std::string cmd = fmt::format("/usr/bin/python3 '{}/tests/diagnose/probe_log.py' --out '{}' {} > /dev/null",
                                      DRIFTLESS_SOURCE_DIR, path.string(), args);
  EXPECT_EQ(std::system(cmd.c_str()), 0) << "generator failed: " << cmd;
  return path;
}

const Candidate* find_in(const std::vector<Candidate>& cs, Effect e) {
  for (const auto& c : cs)
    if (c.effect == e) return &c;
  return nullptr;
}

// the mean new value of a candidate's parameters
double mean_value(const Candidate& c) {
  double sum = 0.0;
  for (const auto& p : c.params) sum += p.new_value();
  return c.params.empty() ? std::nan("") : sum / static_cast<double>(c.params.size());
}

constexpr double kMpuDensity = 0.005;  // deg/s/rtHz, probe_log.py's and independent_log.py's MPU6050
constexpr double kDlpf3BandwidthHz = 42.0;

TEST(ForeignRates, TenHzLogHasNoFlipOrTimingEffectsAndSaysItsNoiseAssumption) {
  // GIVEN a 10 Hz MPU6050-like log: white noise sigma = N sqrt(10 Hz) per sample, 65.5 LSB/(deg/s),
  // flips of 1 s (10 samples), nothing else
  const auto log = probe_log("--rate 10 --duration 300 --seed 1", "10hz");
  // WHEN it is diagnosed with the embedded model, whose 42 Hz DLPF lies above the 5 Hz Nyquist
  const CompareResult r = indep::diagnose_log(log);
  // THEN neither a flip transient nor a signal-chain or jitter effect is claimed (they came from
  // the flips' rates inside the 4-sample stencil of the samples after a flip)
  for (Effect e : {Effect::kFlipTransient, Effect::kLowpass, Effect::kSampleDelay, Effect::kTimeOffset})
    EXPECT_EQ(find_in(r.selected, e), nullptr) << effect_id(e) << ": " << r.statement;
  EXPECT_EQ(find_in(r.noise_model, Effect::kSampleJitter), nullptr) << r.statement;
  // AND the quantisation is the probe's 65.5 LSB/(deg/s)
  const Candidate* q = find_in(r.selected, Effect::kQuantization);
  ASSERT_NE(q, nullptr) << r.statement;
  EXPECT_NEAR(mean_value(*q), 65.5, 0.1);
  // AND the white density, referred as the model's chain says (its 42 Hz DLPF sampled without
  // averaging: sigma = N sqrt(2B)), is N sqrt(fs / 2B); the note gives the per-sample sigma and
  // the density if the filter follows the output rate. Tolerance 5 %: the estimate's own spread
  // is 1.3 % per channel (the 65.5 LSB steps' q^2/12, +4 % in sigma, is taken out)
  const Candidate* w = find_in(r.noise_model, Effect::kWhiteNoise);
  ASSERT_NE(w, nullptr) << r.statement;
  const double expected = kMpuDensity * std::sqrt(10.0 / (2.0 * kDlpf3BandwidthHz));
  EXPECT_NEAR(mean_value(*w), expected, 0.05 * expected) << w->note;
  EXPECT_NE(w->note.find("without averaging"), std::string::npos) << w->note;
  EXPECT_NE(w->note.find("follows the output rate"), std::string::npos) << w->note;
  std::filesystem::remove(log);
}

TEST(ForeignRates, TwentyHzLogWithoutLowpassIsJudgedOnItsOwnChain) {
  // GIVEN a 20 Hz pan/tilt log from the independent generator without any low-pass, at twice
  // the MPU6050's noise (0.01 deg/s/rtHz, sigma = N sqrt(20 Hz) per sample)
  indep::Source src;
  src.seed = 5;
  src.rate_hz = 20.0;
  src.duration_s = 120.0;
  src.noise_scale = 2.0;
  src.dlpf = "none";
  const auto log = indep::generate(src, "foreign_20hz");
  const CompareResult r = indep::diagnose_log(log);
  // THEN the model's low-pass is found absent (said as a removal, not as "0 +- 0")
  const Candidate* lp = find_in(r.selected, Effect::kLowpass);
  ASSERT_NE(lp, nullptr) << r.statement;
  ASSERT_FALSE(lp->params.empty());
  EXPECT_TRUE(removes_model_effect(lp->params.front())) << r.statement;
  EXPECT_NE(r.statement.find("is not in the data: remove it"), std::string::npos) << r.statement;
  // AND the white density is judged against that chain (no low-pass: sigma = N sqrt(fs)): 0.01
  // within 10 % (against the model's DLPF it read N sqrt(20 / 84) = 0.0049, F13)
  const Candidate* w = find_in(r.noise_model, Effect::kWhiteNoise);
  ASSERT_NE(w, nullptr) << r.statement;
  EXPECT_NEAR(mean_value(*w), 2.0 * kMpuDensity, 0.1 * 2.0 * kMpuDensity) << r.statement;
  // AND no phantom jitter
  EXPECT_EQ(find_in(r.noise_model, Effect::kSampleJitter), nullptr) << r.statement;
  std::filesystem::remove(log);
}

TEST(ForeignRates, ExactStampsOnANoisierSensorGiveNoJitter) {
  // GIVEN a 100 Hz BMI088-like log (0.014 deg/s/rtHz: 2.8x the model's noise), exact 10 ms stamps
  const auto log = probe_log("--sensor bmi088 --duration 600 --seed 1", "bmi088");
  const CompareResult r = indep::diagnose_log(log);
  // THEN no sample jitter is proposed (judged against the model's floor, the squared residual's
  // variance was 61x too small and a 3 s jitter was selected, P10)
  EXPECT_EQ(find_in(r.noise_model, Effect::kSampleJitter), nullptr) << r.statement;
  // AND the white density is the sensor's within 8 %
  const Candidate* w = find_in(r.noise_model, Effect::kWhiteNoise);
  ASSERT_NE(w, nullptr) << r.statement;
  EXPECT_NEAR(mean_value(*w), 0.014, 0.08 * 0.014) << r.statement;
  std::filesystem::remove(log);
}

TEST(ForeignRates, ALowpassWithinTwoSigmaOfNoneIsNone) {
  // GIVEN a 100 Hz BMI088-like log of a turning box, without any low-pass (this seed's fitted
  // delay is 0.10 +- 0.05 ms)
  const auto log = probe_log("--sensor bmi088 --motion turn --duration 300 --seed 2", "bmi088_turn");
  const CompareResult r = indep::diagnose_log(log);
  // THEN the low-pass is found absent ("no low-pass", the model's to remove), not a 0.1 ms filter
  const Candidate* lp = find_in(r.selected, Effect::kLowpass);
  ASSERT_NE(lp, nullptr) << r.statement;
  ASSERT_FALSE(lp->params.empty());
  EXPECT_TRUE(is_no_lowpass(lp->params.front())) << r.statement;
  EXPECT_TRUE(removes_model_effect(lp->params.front())) << r.statement;
  // AND the white density is the sensor's within 8 % (as a 0.1 ms filter it took a 731 Hz
  // bandwidth from the datasheet relation, and the noise referred to it read 0.0037)
  const Candidate* w = find_in(r.noise_model, Effect::kWhiteNoise);
  ASSERT_NE(w, nullptr) << r.statement;
  EXPECT_NEAR(mean_value(*w), 0.014, 0.08 * 0.014) << r.statement;
  std::filesystem::remove(log);
}

TEST(ForeignRates, HingeAxesKeepTheirLsbAndAJitterBeyondASamplePeriodIsImplausible) {
  // GIVEN an MPU6050-like log (65.5 LSB/(deg/s) on every axis) on an irregular flip schedule:
  // the hinge axes' outputs during the flips are few and spread over +-360 deg/s
  const auto log = probe_log("--schedule irregular --duration 300 --seed 9", "irregular");
  const CompareResult r = indep::diagnose_log(log);
  // THEN every axis, hinge axes included, has the 65.5 LSB/(deg/s) (it read 0.655 on s1.z and
  // 0.51 on s2.x from the flips' sparse values, P14), and nothing is implausible
  const Candidate* q = find_in(r.selected, Effect::kQuantization);
  ASSERT_NE(q, nullptr) << r.statement;
  ASSERT_EQ(q->params.size(), 6u);
  for (const auto& p : q->params) EXPECT_NEAR(p.new_value(), 65.5, 0.01) << p.name();
  EXPECT_FALSE(r.any_absurd()) << r.statement;
  // AND a sample jitter fitted beyond one sample period (10 ms) is flagged and never proposed
  for (const auto* list : {&r.noise_model, &r.not_supported}) {
    for (const auto& c : *list) {
      if (c.effect != Effect::kSampleJitter) continue;
      for (const auto& p : c.params) EXPECT_EQ(p.new_value() > 0.01, p.absurd) << p.name() << " " << p.new_value();
    }
  }
  EXPECT_EQ(find_in(r.noise_model, Effect::kSampleJitter), nullptr) << r.statement;
  std::filesystem::remove(log);
}

TEST(ForeignRates, AStepCoarserThanOneDegPerSecondIsImplausible) {
  // GIVEN a log whose outputs lie on a 2 deg/s grid with noise that spans many of its steps
  // (probe_log.py at 0.6 deg/s/rtHz, 6 deg/s per sample, re-quantised to 2 deg/s: 2 deg/s is
  // also 131 of the 65.5 LSB/(deg/s) steps, so the coarsest grid the outputs lie on is the one)
  const auto log = probe_log("--noise 0.6 --duration 60 --seed 3", "coarse");
  const std::string cmd = fmt::format(
      "/usr/bin/python3 -c \"import numpy as np, sys\n"
      "p = sys.argv[1]; lines = open(p).read().splitlines(); h = [l for l in lines if l.startswith('#')]\n"
      "cols = lines[len(h)].split(','); rows = np.array([[float(v) for v in l.split(',')] for l in lines[len(h) + 1:]])\n"
      "rows[:, 1:7] = np.round(rows[:, 1:7] / 2.0) * 2.0\n"
      "open(p, 'w').write('\\n'.join(h + [','.join(cols)] + [','.join('%.7f' % v for v in r) for r in rows]) + '\\n')\" '{}'",
      log.string());
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  const CompareResult r = indep::diagnose_log(log);
  // THEN the quantisation found is 0.5 LSB/(deg/s) and flagged implausible (a 16-bit ADC would
  // span +-65536 deg/s)
  const Candidate* q = find_in(r.selected, Effect::kQuantization);
  ASSERT_NE(q, nullptr) << r.statement;
  EXPECT_NEAR(mean_value(*q), 0.5, 1e-6);
  EXPECT_TRUE(q->absurd) << r.statement;
  std::filesystem::remove(log);
}

TEST(ForeignRates, AnEffectTheDataLackIsSaidAsTheModelsNotAsMissing) {
  // GIVEN a tactical-grade log without any ADC (the model quantises at 131 LSB/(deg/s))
  const auto log = probe_log("--sensor tactical --duration 60 --seed 2", "tactical");
  const CompareResult r = indep::diagnose_log(log);
  // THEN the quantisation is selected as an effect of the model the data lack, with its value,
  // and the sentence says so instead of "missing effect ... = 0 +- 0"
  const Candidate* q = find_in(r.selected, Effect::kQuantization);
  ASSERT_NE(q, nullptr) << r.statement;
  for (const auto& p : q->params) EXPECT_TRUE(removes_model_effect(p)) << p.name();
  EXPECT_NE(r.statement.find("the model's quantization (s1.x.sensitivity_lsb_per_dps = 131"), std::string::npos)
      << r.statement;
  EXPECT_NE(r.statement.find("effect of the model not in the data"), std::string::npos) << r.statement;
  EXPECT_EQ(r.statement.find("= 0 ± 0"), std::string::npos) << r.statement;
  EXPECT_EQ(r.statement.find("missing effect"), std::string::npos) << r.statement;
  // AND --apply removes it (it wrote 0 LSB/(deg/s), which the model's own check refused) and
  // the log is then consistent with the model
  const CompareResult again = indep::apply_and_compare(log, r, "tactical");
  EXPECT_EQ(again.verdict, Verdict::kConsistent) << again.statement;
  std::filesystem::remove(log);
}

}  // namespace
}  // namespace driftless::diagnose
