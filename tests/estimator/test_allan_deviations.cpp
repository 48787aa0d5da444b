// Modified Allan and Hadamard deviations, the tau sets, gap-aware segments, the streaming pass and
// the noise identification, against closed forms and the exact in-memory pass.
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimator/allan.hpp"
#include "estimator/allan_stream.hpp"

namespace driftless::est {
namespace {

std::vector<double> white(std::size_t n, double sigma, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> g(0.0, sigma);
  std::vector<double> x(n);
  for (auto& v : x) v = g(rng);
  return x;
}

std::vector<double> random_walk(std::size_t n, double step, std::uint64_t seed) {
  auto x = white(n, step, seed);
  for (std::size_t i = 1; i < n; ++i) x[i] += x[i - 1];
  return x;
}

TEST(AllanDeviations, RampReadsRTauOverRootTwoAndHadamardIgnoresIt) {
  // GIVEN a pure rate ramp r(t) = R t, R = 0.01 deg/s^2, at 10 Hz
  const double R = 0.01, fs = 10.0;
  std::vector<double> x(20000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = R * static_cast<double>(i) / fs;
  AllanOptions o;
  o.sample_rate_hz = fs;
  const auto adev = allan_deviation(x, o);
  o.deviation = Deviation::kHadamard;
  const auto hdev = allan_deviation(x, o);
  // THEN sigma = R tau / sqrt(2) exactly at every tau, and the Hadamard deviation is zero
  for (const auto& p : adev.points) EXPECT_NEAR(p.adev, R * p.tau_s / std::sqrt(2.0), 1e-9 * R * p.tau_s) << p.tau_s;
  // (up to the rounding of the cumulative sum of a ramp: eight orders below the Allan deviation)
  for (std::size_t i = 0; i < hdev.points.size(); ++i) EXPECT_LT(hdev.points[i].adev, 1e-8 * adev.points[i].adev) << i;
}

TEST(AllanDeviations, ModifiedEqualsAllanAtOneSampleAndFallsFasterOnWhitePhase) {
  // GIVEN white phase noise (the rate is the difference of white noise): sigma ~ tau^-1,
  // Mod sigma ~ tau^-3/2
  const auto phase = white(200001, 1.0, 3);
  std::vector<double> x(200000);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = phase[i + 1] - phase[i];
  AllanOptions o;
  const auto a = allan_deviation(x, o);
  o.deviation = Deviation::kModifiedAllan;
  const auto m = allan_deviation(x, o);
  EXPECT_NEAR(m.points[0].adev, a.points[0].adev, 1e-12 * a.points[0].adev);
  const auto slope = [](const AllanCurve& c, std::size_t i, std::size_t j) {
    return std::log(c.points[j].adev / c.points[i].adev) / std::log(c.points[j].tau_s / c.points[i].tau_s);
  };
  EXPECT_NEAR(slope(a, 3, 9), -1.0, 0.05);
  EXPECT_NEAR(slope(m, 3, 9), -1.5, 0.05);
  // and the noise identification calls it white PM
  EXPECT_EQ(a.points[4].noise, NoiseType::kWhitePM);
}

TEST(AllanDeviations, HadamardAgreesWithAllanOnWhiteAndRandomWalkFrequencyNoise) {
  // white FM: H sigma = sigma; random-walk FM: H sigma^2 = K^2 tau / 6 against K^2 tau / 3
  const auto w = white(400000, 1.0, 5);
  const auto rw = random_walk(400000, 0.01, 6);
  AllanOptions o;
  o.sample_rate_hz = 100.0;
  AllanOptions h = o;
  h.deviation = Deviation::kHadamard;
  const auto aw = allan_deviation(w, o), hw = allan_deviation(w, h);
  const auto ar = allan_deviation(rw, o), hr = allan_deviation(rw, h);
  for (std::size_t i = 3; i < 9; ++i) {
    EXPECT_NEAR(hw.points[i].adev / aw.points[i].adev, 1.0, 3.0 / std::sqrt(hw.points[i].edf)) << i;
    EXPECT_NEAR(hr.points[i].adev / ar.points[i].adev, std::sqrt(0.5), 4.0 / std::sqrt(hr.points[i].edf)) << i;
  }
}

TEST(AllanDeviations, DecadeAndExplicitTauSets) {
  const auto x = white(100000, 1.0, 7);
  AllanOptions o;
  o.sample_rate_hz = 100.0;
  o.spacing = TauSpacing::kDecade;
  const auto d = allan_deviation(x, o);
  const std::vector<std::size_t> want = {1, 2, 4, 10, 20, 40, 100, 200, 400, 1000, 2000, 4000, 10000, 20000, 40000};
  ASSERT_EQ(d.points.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_EQ(d.points[i].m, want[i]);
  // the list: 1, 10, 100, 1000, 3000 s; the record (1000 s) allows up to 500 s
  o.spacing = TauSpacing::kExplicit;
  o.tau_s = {1.0, 10.0, 100.0, 1000.0, 3000.0, 0.015};
  const auto e = allan_deviation(x, o);
  ASSERT_EQ(e.points.size(), 4u);
  EXPECT_EQ(e.points[0].m, 2u);  // 0.015 s -> 1.5 samples -> 2
  EXPECT_DOUBLE_EQ(e.points[3].tau_s, 100.0);
  ASSERT_EQ(e.notes.size(), 3u);  // two dropped, one rounded
  // the explicit points equal the same m of every-m evaluation
  AllanOptions all = o;
  all.spacing = TauSpacing::kAll;
  all.max_tau_s = 10.0;
  const auto a = allan_deviation(x, all);
  EXPECT_DOUBLE_EQ(e.points[2].adev, a.points[999].adev);  // m = 1000
}

TEST(AllanDeviations, SegmentsAreGapAwareAndAddTheirDegreesOfFreedom) {
  // GIVEN a record made of two independent pieces with a step between them
  auto a = white(50000, 1.0, 8), b = white(30000, 1.0, 9);
  std::vector<double> x = a;
  for (double v : b) x.push_back(v + 100.0);  // a huge jump where the pieces meet
  AllanOptions o;
  const std::vector<std::size_t> starts = {0, a.size()};
  const auto seg = allan_deviation(x, o, starts);
  const auto joined = allan_deviation(x, o);
  const auto ca = allan_deviation(a, o), cb = allan_deviation(b, o);
  // THEN no difference spans the jump: the squared sums are the pieces' (terms and values add up)
  EXPECT_EQ(seg.segments, 2u);
  for (std::size_t i = 0; i < 8; ++i) {
    EXPECT_EQ(seg.points[i].terms, ca.points[i].terms + cb.points[i].terms);
    const double pooled = (ca.points[i].adev * ca.points[i].adev * ca.points[i].terms +
                           cb.points[i].adev * cb.points[i].adev * cb.points[i].terms) / seg.points[i].terms;
    EXPECT_NEAR(seg.points[i].adev, std::sqrt(pooled), 1e-9 * seg.points[i].adev);
    EXPECT_NEAR(seg.points[i].edf, ca.points[i].edf + cb.points[i].edf, 1e-6 * seg.points[i].edf);
  }
  EXPECT_GT(joined.points[10].adev, 3.0 * seg.points[10].adev);  // joining reads the jump as noise
}

TEST(AllanStreaming, ExactModeEqualsTheInMemoryPassAndStridedModeStaysClose) {
  auto x = random_walk(300000, 1e-3, 10);
  const auto w = white(300000, 0.1, 11);
  for (std::size_t i = 0; i < x.size(); ++i) x[i] += 5.0 + w[i];
  for (const Deviation dev : {Deviation::kAllan, Deviation::kHadamard}) {
    AllanOptions o;
    o.deviation = dev;
    const auto ref = allan_deviation(x, o);
    for (const std::size_t R : {std::size_t{1} << 20, std::size_t{256}}) {
      StreamingOptions so;
      so.deviation = dev;
      so.exact_up_to_m = R;
      StreamingOctaveDeviation s(so);
      for (std::size_t i = 0; i < x.size(); i += 7777) s.push(std::span<const double>(x.data() + i, std::min<std::size_t>(7777, x.size() - i)));
      const auto c = s.finish();
      ASSERT_EQ(c.points.size(), ref.points.size());
      for (std::size_t i = 0; i < c.points.size(); ++i) {
        const double tol = c.points[i].m <= R ? 1e-10 : 0.5 / std::sqrt(ref.points[i].edf);
        EXPECT_NEAR(c.points[i].adev / ref.points[i].adev, 1.0, tol) << to_string(dev) << " m " << c.points[i].m << " R " << R;
        EXPECT_EQ(c.points[i].noise, ref.points[i].noise);
      }
    }
  }
}

TEST(AllanStreaming, SegmentBreaksMatchTheInMemorySegments) {
  const auto x = white(60000, 1.0, 12);
  AllanOptions o;
  const std::vector<std::size_t> starts = {0, 20000, 45000};
  const auto ref = allan_deviation(x, o, starts);
  StreamingOptions so;
  StreamingOctaveDeviation s(so);
  s.push(std::span<const double>(x.data(), 20000));
  s.break_segment();
  s.push(std::span<const double>(x.data() + 20000, 25000));
  s.break_segment();
  s.push(std::span<const double>(x.data() + 45000, 15000));
  const auto c = s.finish();
  EXPECT_EQ(c.segments, 3u);
  for (std::size_t i = 0; i < c.points.size(); ++i) {
    EXPECT_EQ(c.points[i].terms, ref.points[i].terms);
    EXPECT_NEAR(c.points[i].adev / ref.points[i].adev, 1.0, 1e-10);
  }
  StreamingOptions bad;
  bad.deviation = Deviation::kModifiedAllan;
  EXPECT_THROW(StreamingOctaveDeviation{bad}, std::invalid_argument);
}

TEST(AllanNoiseId, LagOneAutocorrelationNamesThePowerLaws) {
  int alpha = 99;
  const auto w = white(5000, 1.0, 13);
  ASSERT_TRUE(lag1_noise_id(w, 2, &alpha));
  EXPECT_EQ(alpha, 0);  // white FM
  ASSERT_TRUE(lag1_noise_id(random_walk(5000, 1.0, 14), 2, &alpha));
  EXPECT_EQ(alpha, -2);  // random-walk FM
  std::vector<double> d(4999);
  for (std::size_t i = 0; i < d.size(); ++i) d[i] = w[i + 1] - w[i];
  ASSERT_TRUE(lag1_noise_id(d, 2, &alpha));
  EXPECT_EQ(alpha, 2);  // white PM
  EXPECT_FALSE(lag1_noise_id(std::vector<double>(29, 1.0), 2, &alpha));  // too few averages
}

}  // namespace
}  // namespace driftless::est
